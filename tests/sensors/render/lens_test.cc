// Lenses against OpenCV's own projections (cv::projectPoints and
// cv::fisheye::projectPoints with the same coefficients), their inverses,
// the checks on coefficients, and the remap against OpenCV's pinhole
// projection of the source view.

#include "sensors/render/lens.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>

#include "sensors/render/projection.h"

namespace sandbox::render {
namespace {

Lens Brown() {
  Lens lens;
  lens.fx = 520.0, lens.fy = 515.0, lens.cx = 321.5, lens.cy = 238.25;
  lens.k1 = -0.28, lens.k2 = 0.09, lens.k3 = -0.01, lens.p1 = 0.0012, lens.p2 = -0.0008;
  return lens;
}

Lens Fisheye() {
  Lens lens;
  lens.model = Lens::Model::kFisheye;
  lens.fx = 330.0, lens.fy = 330.0, lens.cx = 319.5, lens.cy = 239.5;
  lens.k1 = 0.02, lens.k2 = -0.004, lens.k3 = 0.001, lens.k4 = -0.0002;
  return lens;
}

// Rays whose pixels fall in a 640 x 480 image, OpenCV camera frame.
std::vector<cv::Point3d> Rays(const Lens& lens, int n) {
  std::mt19937 random(4);
  std::uniform_real_distribution<double> u(0.0, 639.0), v(0.0, 479.0);
  std::vector<cv::Point3d> rays;
  while (int(rays.size()) < n) {
    const Eigen::Vector3d ray = lens.Ray({u(random), v(random)}) * 3.0;
    rays.emplace_back(ray.x(), ray.y(), ray.z());
  }
  return rays;
}

TEST(LensTest, BrownConradyIsOpenCvsProjection) {
  const Lens lens = Brown();
  const std::vector<cv::Point3d> rays = Rays(lens, 2000);
  const cv::Matx33d K(lens.fx, 0, lens.cx, 0, lens.fy, lens.cy, 0, 0, 1);
  const std::vector<double> dist = {lens.k1, lens.k2, lens.p1, lens.p2, lens.k3};
  std::vector<cv::Point2d> pixels;
  cv::projectPoints(rays, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist, pixels);
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Eigen::Vector3d ray(rays[i].x, rays[i].y, rays[i].z);
    const Eigen::Vector2d ours = lens.Pixel(ray);
    EXPECT_NEAR(ours.x(), pixels[i].x, 1e-9) << i;
    EXPECT_NEAR(ours.y(), pixels[i].y, 1e-9) << i;
    EXPECT_LT((lens.Ray(ours) - ray.normalized()).norm(), 1e-10) << i;  // and back
  }
}

TEST(LensTest, FisheyeIsOpenCvsFisheyeProjection) {
  const Lens lens = Fisheye();
  const std::vector<cv::Point3d> rays = Rays(lens, 2000);
  const cv::Matx33d K(lens.fx, 0, lens.cx, 0, lens.fy, lens.cy, 0, 0, 1);
  const cv::Vec4d dist(lens.k1, lens.k2, lens.k3, lens.k4);
  std::vector<cv::Point2d> pixels;
  cv::fisheye::projectPoints(rays, pixels, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0), K, dist);
  double widest = 0.0;
  for (std::size_t i = 0; i < rays.size(); ++i) {
    const Eigen::Vector3d ray(rays[i].x, rays[i].y, rays[i].z);
    const Eigen::Vector2d ours = lens.Pixel(ray);
    EXPECT_NEAR(ours.x(), pixels[i].x, 1e-9) << i;
    EXPECT_NEAR(ours.y(), pixels[i].y, 1e-9) << i;
    EXPECT_LT((lens.Ray(ours) - ray.normalized()).norm(), 1e-10) << i;
    widest = std::max(widest, std::acos(ray.normalized().z()));
  }
  EXPECT_GT(widest * 180.0 / M_PI, 60.0);  // a wide lens: its corners far off the axis
}

TEST(LensTest, CoefficientsThatFoldTheImageAreRefused) {
  EXPECT_NO_THROW(Brown().ValidateOrThrow(640, 480));
  EXPECT_NO_THROW(Fisheye().ValidateOrThrow(640, 480));
  Lens fold = Fisheye();
  fold.k1 = -0.6;  // theta (1 - 0.6 theta^2) peaks at 42.7 degrees, inside the image
  try {
    fold.ValidateOrThrow(640, 480);
    ADD_FAILURE() << "a folding fisheye was accepted";
  } catch (const std::invalid_argument& error) {
    EXPECT_NE(std::string(error.what()).find("fold the projection back inside the image"),
              std::string::npos)
        << error.what();
  }
  Lens barrel = Brown();
  barrel.k1 = -0.9, barrel.k2 = 0.0, barrel.k3 = 0.0;
  EXPECT_THROW(barrel.ValidateOrThrow(640, 480), std::invalid_argument);
  Lens wide = Fisheye();
  wide.fx = wide.fy = 120.0;  // corners beyond 80 degrees
  EXPECT_THROW(wide.ValidateOrThrow(640, 480), std::invalid_argument);
  Lens zero = Brown();
  zero.fx = 0.0;
  EXPECT_THROW(zero.ValidateOrThrow(640, 480), std::invalid_argument);
}

// The remap takes each lens pixel's segment from the source pixel nearest
// to where OpenCV projects its ray through the source's pinhole.
// Where OpenCV's pinhole projection of the source view puts the lens pixel
// (u, v)'s ray, in the source image (row 0 at the top).
cv::Point2d SourcePoint(const Lens& lens, const CameraView& source, int u, int v) {
  const double f = (source.height / 2.0) / std::tan(source.fov_y_rad / 2.0);
  const cv::Matx33d K(f, 0, (source.width - 1) / 2.0, 0, f, (source.height - 1) / 2.0, 0, 0, 1);
  const Eigen::Vector3d ray = lens.Ray({double(u), double(v)});
  std::vector<cv::Point2d> at;
  cv::projectPoints(std::vector<cv::Point3d>{{ray.x(), ray.y(), ray.z()}}, cv::Vec3d(0, 0, 0),
                    cv::Vec3d(0, 0, 0), K, cv::noArray(), at);
  return at[0];
}

// Each source image in GL's row order (bottom first), as the renderer reads
// it back: segment = the pixel's index in a top-first image; depth the
// reversed-depth value of a known distance; colour R, G linear in x and y
// (mod 256), B constant; normal (x, y, 1) of the top-first pixel.
struct Source {
  std::vector<std::uint32_t> segment;
  std::vector<float> depth, normal;
  std::vector<std::uint8_t> rgba;
  RawImages raw;
};

float RawDepth(double metres, double near_m, double far_m) {  // projection.h's inverse
  return float((near_m * far_m / metres - near_m) / (far_m - near_m));
}

Source MakeSource(const CameraView& source) {
  Source s;
  const std::size_t w = std::size_t(source.width), h = std::size_t(source.height);
  s.segment.resize(w * h), s.depth.resize(w * h), s.normal.resize(3 * w * h),
      s.rgba.resize(4 * w * h);
  for (std::size_t gl_row = 0; gl_row < h; ++gl_row) {
    const std::size_t y = h - 1 - gl_row;
    for (std::size_t x = 0; x < w; ++x) {
      const std::size_t i = gl_row * w + x;
      s.segment[i] = std::uint32_t(y * w + x);
      s.depth[i] = RawDepth(1.0 + double(y * w + x) * 1e-4, 0.2, 5000.0);
      s.normal[3 * i] = float(x), s.normal[3 * i + 1] = float(y), s.normal[3 * i + 2] = 1.f;
      s.rgba[4 * i] = std::uint8_t(x), s.rgba[4 * i + 1] = std::uint8_t(y);
      s.rgba[4 * i + 2] = 200, s.rgba[4 * i + 3] = 7;
    }
  }
  s.raw.width = source.width, s.raw.height = source.height;
  s.raw.rgba = s.rgba.data(), s.raw.segment = s.segment.data(), s.raw.normal = s.normal.data();
  s.raw.depth = s.depth.data(), s.raw.near_m = 0.2, s.raw.far_m = 5000.0;
  return s;
}

TEST(LensTest, TheRemapGathersFromWhereThePinholeSeesTheRay) {
  sensors::WorkerPool pool(2);
  for (const Lens& lens : {Brown(), Fisheye()}) {
    SCOPED_TRACE(lens.ModelName());
    CameraView view;
    view.width = 640, view.height = 480;
    const CameraView source = SourceView(view, lens);
    const LensRemap remap(lens, 640, 480, source);
    const Source from = MakeSource(source);
    Frame out, pooled;
    remap.Apply(from.raw, &out);
    remap.Apply(from.raw, &pooled, &pool);
    ASSERT_EQ(out.kinds, kColorImage | kDepthImage | kSegmentationImage | kNormalsImage);
    ASSERT_EQ(out.segment.size(), 640u * 480u);
    ASSERT_EQ(out.rgb.size(), 3u * 640u * 480u);
    EXPECT_TRUE(out.rgb == pooled.rgb && out.depth_m == pooled.depth_m &&
                out.segment == pooled.segment && out.normal_C == pooled.normal_C);
    int checked = 0, bilinear = 0;
    // Every 7th pixel and the last row and column.
    std::vector<int> columns, rows;
    for (int u = 0; u < 640; u += 7) columns.push_back(u);
    for (int v = 0; v < 480; v += 7) rows.push_back(v);
    columns.push_back(639), rows.push_back(479);
    for (const int v : rows) {
      for (const int u : columns) {
        const cv::Point2d at = SourcePoint(lens, source, u, v);
        const long x = std::lround(at.x), y = std::lround(at.y);
        const std::size_t i = std::size_t(v) * 640 + std::size_t(u);
        const std::uint32_t expected = std::uint32_t(y * source.width + x);
        ASSERT_EQ(out.segment[i], expected) << u << "," << v;
        // The source pixel's depth, in metres by projection.h's conversion (and about the
        // distance).
        const std::size_t gl_pixel =
            std::size_t(source.height - 1 - y) * std::size_t(source.width) + std::size_t(x);
        EXPECT_EQ(out.depth_m[i], ReversedDepth(0.2, 5000.0).Metres(from.depth[gl_pixel]));
        EXPECT_NEAR(out.depth_m[i], 1.0 + double(expected) * 1e-4, 1e-3 * out.depth_m[i]);
        EXPECT_EQ(out.normal_C[3 * i], float(x));
        EXPECT_EQ(out.normal_C[3 * i + 1], float(y));
        // Bilinear colour: R and G are linear in x and y inside a cell that
        // does not wrap at 256; B the same everywhere (the weights sum to 1).
        EXPECT_EQ(out.rgb[3 * i + 2], 200) << u << "," << v;
        if (std::fmod(at.x, 256.0) < 254.0 && std::fmod(at.y, 256.0) < 254.0) {
          EXPECT_NEAR(out.rgb[3 * i], std::fmod(at.x, 256.0), 0.51) << u << "," << v;
          EXPECT_NEAR(out.rgb[3 * i + 1], std::fmod(at.y, 256.0), 0.51) << u << "," << v;
          ++bilinear;
        }
        ++checked;
      }
    }
    EXPECT_GT(checked, 6000);
    EXPECT_GT(bilinear, 5800);
  }
}

TEST(LensTest, TheRemapGathersOnlyTheImagesGivenAndRefusesAnotherSize) {
  CameraView view;
  view.width = 64, view.height = 48;
  Lens lens = Brown();
  lens.fx /= 10, lens.fy /= 10, lens.cx = 31.5, lens.cy = 23.5;
  const CameraView source = SourceView(view, lens);
  const LensRemap remap(lens, 64, 48, source);
  Source from = MakeSource(source);
  from.raw.rgba = nullptr, from.raw.normal = nullptr;
  Frame out;
  out.rgb.assign(5, 1);  // left over from a former frame
  remap.Apply(from.raw, &out);
  EXPECT_EQ(out.kinds, kDepthImage | kSegmentationImage);
  EXPECT_TRUE(out.rgb.empty());
  EXPECT_TRUE(out.normal_C.empty());
  EXPECT_EQ(out.depth_m.size(), 64u * 48u);
  from.raw.height += 1;
  EXPECT_THROW(remap.Apply(from.raw, &out), std::invalid_argument);
}

}  // namespace
}  // namespace sandbox::render
