#include "sensors/render/lens.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <stdexcept>

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
    : width_(width), height_(height), source_width_(source.width) {
  const double f = (source.height / 2.0) / std::tan(source.fov_y_rad / 2.0);
  const double scx = (source.width - 1) / 2.0, scy = (source.height - 1) / 2.0;
  const std::size_t n = std::size_t(width) * std::size_t(height);
  corner_.resize(n), weight_.resize(2 * n), nearest_.resize(n);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const Eigen::Vector3d ray = lens.Ray({double(u), double(v)});
      const double su = std::clamp(f * ray.x() / ray.z() + scx, 0.0, source.width - 1.001);
      const double sv = std::clamp(f * ray.y() / ray.z() + scy, 0.0, source.height - 1.001);
      const std::size_t i = std::size_t(v) * std::size_t(width) + std::size_t(u);
      const int iu = int(su), iv = int(sv);
      corner_[i] = iv * source.width + iu;
      weight_[2 * i] = std::uint16_t(std::lround((su - iu) * 256.0));
      weight_[2 * i + 1] = std::uint16_t(std::lround((sv - iv) * 256.0));
      nearest_[i] = int(std::lround(sv)) * source.width + int(std::lround(su));
    }
  }
}

void LensRemap::Apply(const Frame& source, Frame* out) const {
  out->width = width_, out->height = height_, out->kinds = source.kinds;
  const std::size_t n = corner_.size();
  const std::size_t row = std::size_t(source_width_);
  if (!source.rgb.empty()) {
    out->rgb.resize(3 * n);
    const std::uint8_t* from = source.rgb.data();
    std::uint8_t* to = out->rgb.data();
    for (std::size_t i = 0; i < n; ++i) {
      const std::uint8_t* a = from + 3 * std::size_t(corner_[i]);
      const std::uint8_t* b = a + 3 * row;
      const std::uint32_t wx = weight_[2 * i], wy = weight_[2 * i + 1];  // 0..256
      for (int k = 0; k < 3; ++k) {
        const std::uint32_t top = a[k] * (256 - wx) + a[3 + k] * wx;
        const std::uint32_t bottom = b[k] * (256 - wx) + b[3 + k] * wx;
        to[3 * i + std::size_t(k)] = std::uint8_t((top * (256 - wy) + bottom * wy + 32768) >> 16);
      }
    }
  } else {
    out->rgb.clear();
  }
  const std::int32_t* nearest = nearest_.data();
  const auto gather = [&](const auto& from, auto* to) {
    if (from.empty()) return to->clear();
    to->resize(n);
    const auto* __restrict in = from.data();
    auto* __restrict into = to->data();
    for (std::size_t i = 0; i < n; ++i) into[i] = in[nearest[i]];
  };
  gather(source.depth_m, &out->depth_m);
  gather(source.segment, &out->segment);
  if (source.normal_C.empty()) {
    out->normal_C.clear();
  } else {
    out->normal_C.resize(3 * n);
    const float* __restrict in = source.normal_C.data();
    float* __restrict into = out->normal_C.data();
    for (std::size_t i = 0; i < n; ++i) {
      const float* p = in + 3 * std::size_t(nearest[i]);
      into[3 * i] = p[0], into[3 * i + 1] = p[1], into[3 * i + 2] = p[2];
    }
  }
}

}  // namespace sandbox::render
