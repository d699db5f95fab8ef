// Lenses against OpenCV's own projections (cv::projectPoints and
// cv::fisheye::projectPoints with the same coefficients), their inverses,
// the checks on coefficients, and the remap against a pinhole projection.

#include "sensors/render/lens.h"

#include <gtest/gtest.h>

#include <opencv2/calib3d.hpp>
#include <random>

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
TEST(LensTest, TheRemapGathersFromWhereThePinholeSeesTheRay) {
  for (const Lens& lens : {Brown(), Fisheye()}) {
    CameraView view;
    view.width = 640, view.height = 480;
    const CameraView source = SourceView(view, lens);
    const LensRemap remap(lens, 640, 480, source);
    Frame frame;
    frame.width = source.width, frame.height = source.height;
    frame.segment.resize(std::size_t(source.width) * std::size_t(source.height));
    for (std::size_t i = 0; i < frame.segment.size(); ++i) frame.segment[i] = std::uint32_t(i);
    Frame out;
    remap.Apply(frame, &out);
    ASSERT_EQ(out.segment.size(), 640u * 480u);
    const double f = (source.height / 2.0) / std::tan(source.fov_y_rad / 2.0);
    const cv::Matx33d K(f, 0, (source.width - 1) / 2.0, 0, f, (source.height - 1) / 2.0, 0, 0, 1);
    int checked = 0;
    for (int v = 0; v < 480; v += 7) {
      for (int u = 0; u < 640; u += 7) {
        const Eigen::Vector3d ray = lens.Ray({double(u), double(v)});
        std::vector<cv::Point2d> at;
        cv::projectPoints(std::vector<cv::Point3d>{{ray.x(), ray.y(), ray.z()}}, cv::Vec3d(0, 0, 0),
                          cv::Vec3d(0, 0, 0), K, cv::noArray(), at);
        const std::uint32_t expected =
            std::uint32_t(std::lround(at[0].y) * source.width + std::lround(at[0].x));
        EXPECT_EQ(out.segment[std::size_t(v) * 640 + std::size_t(u)], expected) << u << "," << v;
        ++checked;
      }
    }
    EXPECT_GT(checked, 6000);
  }
}

}  // namespace
}  // namespace sandbox::render
