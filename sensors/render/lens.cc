#include "sensors/render/lens.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#ifdef __SSE2__
#include <emmintrin.h>
#endif

#include "sensors/render/projection.h"

namespace sandbox::render {
namespace {

// Distorted normalized coordinates of an undistorted (x, y) = (X / Z, Y / Z).
Eigen::Vector2d BrownConrady(const Lens& l, const Eigen::Vector2d& xy) {
  const double x = xy.x(), y = xy.y(), r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (l.k1 + r2 * (l.k2 + r2 * l.k3));
  return {x * radial + 2.0 * l.p1 * x * y + l.p2 * (r2 + 2.0 * x * x),
          y * radial + l.p1 * (r2 + 2.0 * y * y) + 2.0 * l.p2 * x * y};
}

// The fisheye's distorted angle theta_d of an angle theta off the axis.
double FisheyeAngle(const Lens& l, double theta) {
  const double t2 = theta * theta;
  return theta * (1.0 + t2 * (l.k1 + t2 * (l.k2 + t2 * (l.k3 + t2 * l.k4))));
}

// Calls pixel(m, i, u, v) for each pixel (u, v) in band `band` (rows
// band * kTileHeight on) of a width x height image, in tiles: m
// its place in that order (the bands in turn), i its index in the image. A
// tile's pixels gather from a small patch of the source, which stays in
// cache (row by row, a lens's curved rows would cross the source's).
constexpr int kTileWidth = 32, kTileHeight = 32;  // of 64 x 64 .. 640 x 16, the fastest
int Bands(int height) { return (height + kTileHeight - 1) / kTileHeight; }
template <typename Pixel>
void InTiles(int width, int height, int band, Pixel pixel) {
  const int ty = band * kTileHeight, v_end = std::min(ty + kTileHeight, height);
  std::size_t m = std::size_t(ty) * std::size_t(width);
  for (int tx = 0; tx < width; tx += kTileWidth) {
    const int u_end = std::min(tx + kTileWidth, width);
    for (int v = ty; v < v_end; ++v) {
      std::size_t i = std::size_t(v) * std::size_t(width) + std::size_t(tx);
      for (int u = tx; u < u_end; ++u, ++i, ++m) pixel(m, i, u, v);
    }
  }
}

// One colour pixel, RGB at `to`, from the RGBA cell whose upper row's left
// pixel is at `a` and lower row's at `b`, with `w` the weights (1/16384,
// summing to it) of a, b, a's right neighbour, b's right neighbour, in
// pairs: w[0] = a's | b's << 16, w[1] = their neighbours'. (SSE2: each
// pixel's two rows interleaved in 16 bits, multiplied by their weights and
// summed in 32.)
// `spill`: a fourth byte may be written at to[3] (the next pixel's, written
// after this one).
inline void Bilinear(const std::uint8_t* a, const std::uint8_t* b, const std::int32_t* w,
                     std::uint8_t* to, bool spill) {
#ifdef __SSE2__
  const __m128i rows = _mm_unpacklo_epi8(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(a)),
                                         _mm_loadl_epi64(reinterpret_cast<const __m128i*>(b)));
  const __m128i zero = _mm_setzero_si128();
  // Left pixel: a.r b.r a.g b.g a.b b.b a.a b.a in 16 bits; the right one.
  __m128i sum = _mm_add_epi32(_mm_madd_epi16(_mm_unpacklo_epi8(rows, zero), _mm_set1_epi32(w[0])),
                              _mm_madd_epi16(_mm_unpackhi_epi8(rows, zero), _mm_set1_epi32(w[1])));
  sum = _mm_srli_epi32(_mm_add_epi32(sum, _mm_set1_epi32(8192)), 14);
  const __m128i bytes = _mm_packus_epi16(_mm_packs_epi32(sum, sum), sum);
  const std::uint32_t rgb = std::uint32_t(_mm_cvtsi128_si32(bytes));
  if (spill) {
    std::memcpy(to, &rgb, 4);
  } else {
    to[0] = std::uint8_t(rgb), to[1] = std::uint8_t(rgb >> 8), to[2] = std::uint8_t(rgb >> 16);
  }
#else
  (void)spill;
  const std::int32_t wa = std::int16_t(w[0]), wb = w[0] >> 16;
  const std::int32_t wa1 = std::int16_t(w[1]), wb1 = w[1] >> 16;
  for (int k = 0; k < 3; ++k) {
    to[k] = std::uint8_t((a[k] * wa + b[k] * wb + a[4 + k] * wa1 + b[4 + k] * wb1 + 8192) >> 14);
  }
#endif
}

}  // namespace

bool Lens::operator==(const Lens& o) const {
  return model == o.model && fx == o.fx && fy == o.fy && cx == o.cx && cy == o.cy && k1 == o.k1 &&
         k2 == o.k2 && k3 == o.k3 && k4 == o.k4 && p1 == o.p1 && p2 == o.p2;
}

std::string Lens::ModelName() const {
  return model == Model::kFisheye ? "fisheye" : "brown_conrady";
}

Eigen::Vector2d Lens::Pixel(const Eigen::Vector3d& ray) const {
  Eigen::Vector2d d;
  if (model == Model::kBrownConrady) {
    d = BrownConrady(*this, ray.head<2>() / ray.z());
  } else {
    const double r = ray.head<2>().norm();
    const double theta = std::atan2(r, ray.z());
    d = r > 0.0 ? Eigen::Vector2d(ray.head<2>() * (FisheyeAngle(*this, theta) / r))
                : Eigen::Vector2d::Zero();
  }
  return {fx * d.x() + cx, fy * d.y() + cy};
}

Eigen::Vector3d Lens::Ray(const Eigen::Vector2d& pixel) const {
  const Eigen::Vector2d d((pixel.x() - cx) / fx, (pixel.y() - cy) / fy);
  if (model == Model::kFisheye) {
    const double theta_d = d.norm();
    if (theta_d == 0.0) return Eigen::Vector3d::UnitZ();
    double theta = theta_d;
    for (int i = 0; i < 50; ++i) {
      const double h = 1e-7;
      const double f = FisheyeAngle(*this, theta) - theta_d;
      const double slope =
          (FisheyeAngle(*this, theta + h) - FisheyeAngle(*this, theta - h)) / (2 * h);
      const double step = f / slope;
      theta -= step;
      if (std::abs(step) < 1e-15) break;
    }
    const Eigen::Vector2d across = d / theta_d * std::sin(theta);
    return {across.x(), across.y(), std::cos(theta)};
  }
  Eigen::Vector2d xy = d;  // Newton on BrownConrady(xy) = d
  for (int i = 0; i < 50; ++i) {
    const Eigen::Vector2d f = BrownConrady(*this, xy) - d;
    if (f.norm() < 1e-15) break;
    Eigen::Matrix2d J;
    const double h = 1e-7;
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector2d e = Eigen::Vector2d::Zero();
      e[k] = h;
      J.col(k) = (BrownConrady(*this, xy + e) - BrownConrady(*this, xy - e)) / (2 * h);
    }
    xy -= J.partialPivLu().solve(f);
  }
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0).normalized();
}

void Lens::ValidateOrThrow(int width, int height, double max_angle_deg) const {
  if (!(fx > 0.0 && fy > 0.0 && std::isfinite(fx) && std::isfinite(fy))) {
    throw std::invalid_argument("fx and fy must be positive");
  }
  for (const double c : {cx, cy, k1, k2, k3, k4, p1, p2}) {
    if (!std::isfinite(c))
      throw std::invalid_argument("k1 and the other coefficients must be finite");
  }
  // Along the ray to the farthest corner, the radius in the image must grow
  // with the angle off the axis until it passes that corner.
  double reach = 0.0;  // normalized distorted radius of the farthest corner
  for (const double u : {-0.5, width - 0.5}) {
    for (const double v : {-0.5, height - 0.5}) {
      reach = std::max(reach, std::hypot((u - cx) / fx, (v - cy) / fy));
    }
  }
  const double max_angle = max_angle_deg * M_PI / 180.0;
  double last = 0.0;
  for (int i = 1; i <= 4000; ++i) {
    const double theta = max_angle * i / 4000.0;
    const double radius =
        model == Model::kFisheye
            ? FisheyeAngle(*this, theta)
            : std::tan(theta) * (1.0 + std::pow(std::tan(theta), 2) *
                                           (k1 + std::pow(std::tan(theta), 2) *
                                                     (k2 + std::pow(std::tan(theta), 2) * k3)));
    if (!(radius > last)) {
      char at[32];
      std::snprintf(at, sizeof(at), "%.1f", theta * 180.0 / M_PI);
      throw std::invalid_argument(
          std::string("k1 and the other coefficients fold the projection back inside the image "
                      "(at ") +
          at + " degrees off the axis)");
    }
    if (radius >= reach) return;
    last = radius;
  }
  char beyond[32];
  std::snprintf(beyond, sizeof(beyond), "%g", max_angle_deg);
  throw std::invalid_argument(std::string("the lens sees rays beyond ") + beyond +
                              " degrees off the axis: too wide to draw through a pinhole view");
}

CameraView SourceView(const CameraView& view, const Lens& lens) {
  // The widest tangents any border pixel's ray reaches.
  double tx = 0.0, ty = 0.0;
  const auto reach = [&](double u, double v) {
    const Eigen::Vector3d ray = lens.Ray({u, v});
    tx = std::max(tx, std::abs(ray.x() / ray.z()));
    ty = std::max(ty, std::abs(ray.y() / ray.z()));
  };
  for (int u = 0; u < view.width; ++u) reach(u, -0.5), reach(u, view.height - 0.5);
  for (int v = 0; v < view.height; ++v) reach(-0.5, v), reach(view.width - 0.5, v);
  // Twice the lens's density at the centre: a lens pixel takes its data
  // images from the nearest source pixel, within a quarter of its own.
  const double f = 2.0 * std::max(lens.fx, lens.fy);
  CameraView source = view;
  source.lens.reset();
  source.width = int(std::ceil(2.0 * f * tx)) + 2;
  source.height = int(std::ceil(2.0 * f * ty)) + 2;
  source.fov_y_rad = 2.0 * std::atan(source.height / (2.0 * f));
  return source;
}

LensRemap::LensRemap(const Lens& lens, int width, int height, const CameraView& source)
    : width_(width), height_(height), source_width_(source.width), source_height_(source.height) {
  const double f = (source.height / 2.0) / std::tan(source.fov_y_rad / 2.0);
  const double scx = (source.width - 1) / 2.0, scy = (source.height - 1) / 2.0;
  const std::size_t n = std::size_t(width) * std::size_t(height);
  corner_.resize(n), weight_.resize(2 * n), nearest_.resize(n);
  for (int band = 0; band < Bands(height); ++band) {
    InTiles(width, height, band, [&](std::size_t m, std::size_t, int u, int v) {
      const Eigen::Vector3d ray = lens.Ray({double(u), double(v)});
      const double su = std::clamp(f * ray.x() / ray.z() + scx, 0.0, source.width - 1.001);
      const double sv = std::clamp(f * ray.y() / ray.z() + scy, 0.0, source.height - 1.001);
      const int iu = int(su), iv = int(sv);
      corner_[m] = (source.height - 1 - iv) * source.width + iu;  // GL's rows: the upper is higher
      const int x = int(std::lround((su - iu) * 128.0)), y = int(std::lround((sv - iv) * 128.0));
      weight_[2 * m] = (128 - x) * (128 - y) | ((128 - x) * y) << 16;  // upper left, lower left
      weight_[2 * m + 1] = x * (128 - y) | (x * y) << 16;              // their right neighbours
      nearest_[m] =
          (source.height - 1 - int(std::lround(sv))) * source.width + int(std::lround(su));
    });
  }
}

void LensRemap::Apply(const RawImages& source, Frame* out, sensors::WorkerPool* pool) const {
  if (source.width != source_width_ || source.height != source_height_) {
    throw std::invalid_argument("LensRemap::Apply(): a source of " + std::to_string(source.width) +
                                " x " + std::to_string(source.height) + " for a map from " +
                                std::to_string(source_width_) + " x " +
                                std::to_string(source_height_));
  }
  out->width = width_, out->height = height_;
  out->kinds = ImageKinds(source.rgba ? kColorImage : 0u) | (source.depth ? kDepthImage : 0u) |
               (source.segment ? kSegmentationImage : 0u) | (source.normal ? kNormalsImage : 0u);
  const std::size_t n = corner_.size();
  const auto size = [n](auto* image, const void* wanted, std::size_t channels) {
    if (wanted != nullptr) {
      image->resize(channels * n);
    } else {
      image->clear();
    }
  };
  size(&out->rgb, source.rgba, 3);
  size(&out->depth_m, source.depth, 1);
  size(&out->segment, source.segment, 1);
  size(&out->normal_C, source.normal, 3);
  const std::int32_t* __restrict corner = corner_.data();
  const std::int32_t* __restrict weight = weight_.data();
  const std::int32_t* __restrict nearest = nearest_.data();
  const std::size_t below = 4 * std::size_t(source_width_);  // bytes down one row: GL's row lower
  const ReversedDepth depth_to_m(source.near_m, source.far_m);
  // A band of rows, every image.
  const auto band = [&](int b) {
    if (source.rgba != nullptr) {
      std::uint8_t* __restrict to = out->rgb.data();
      InTiles(width_, height_, b, [&](std::size_t m, std::size_t i, int u, int) {
        const std::uint8_t* a = source.rgba + 4 * std::size_t(corner[m]);
        Bilinear(a, a - below, &weight[2 * m], to + 3 * i, u + 1 < width_);
      });
    }
    if (source.depth != nullptr) {
      float* __restrict to = out->depth_m.data();
      InTiles(width_, height_, b, [&](std::size_t m, std::size_t i, int, int) {
        to[i] = depth_to_m.Metres(source.depth[nearest[m]]);
      });
    }
    if (source.segment != nullptr) {
      std::uint32_t* __restrict to = out->segment.data();
      InTiles(width_, height_, b,
              [&](std::size_t m, std::size_t i, int, int) { to[i] = source.segment[nearest[m]]; });
    }
    if (source.normal != nullptr) {
      float* __restrict to = out->normal_C.data();
      InTiles(width_, height_, b, [&](std::size_t m, std::size_t i, int, int) {
        const float* p = source.normal + 3 * std::size_t(nearest[m]);
        to[3 * i] = p[0], to[3 * i + 1] = p[1], to[3 * i + 2] = p[2];
      });
    }
  };
  if (pool != nullptr) {
    pool->RunParallel(Bands(height_), band);
  } else {
    for (int b = 0; b < Bands(height_); ++b) band(b);
  }
}

}  // namespace sandbox::render
