// The camera's projection checked against geometry worked out by hand: a
// point on the optical axis at the near and far planes lands at depth 1 and
// 0, a point at the edge of the field of view at the image's edge, the near
// plane's corner at the distance its triangle gives, and a depth read back
// becomes the distance it came from.

#include "sensors/render/projection.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "sensors/render/read_back.h"

namespace sandbox::render {
namespace {

CameraView View() {
  CameraView view;
  view.width = 640;
  view.height = 480;
  view.fov_y_rad = 1.0;
  view.near_m = 0.5;
  view.far_m = 2000.0;
  // At (10, 20, 30), looking along world +y (yawed 90 degrees), level.
  view.X_WC =
      Eigen::Translation3d(10, 20, 30) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  return view;
}

// Clip coordinates over w of a camera-centred world point.
Eigen::Vector3d Ndc(const CameraView& view, const Eigen::Vector3d& p_W) {
  const Eigen::Matrix4d M = ReversedDepthProjection(view) * ViewRotation(view.X_WC);
  const Eigen::Vector4d clip = M * (p_W - view.X_WC.translation()).homogeneous();
  return clip.head<3>() / clip.w();
}

TEST(ProjectionTest, NearAndFarOnTheAxisAreDepthOneAndZero) {
  const CameraView view = View();
  const Eigen::Vector3d eye = view.X_WC.translation(), forward(0, 1, 0);
  EXPECT_NEAR(Ndc(view, eye + view.near_m * forward).z(), 1.0, 1e-12);
  EXPECT_NEAR(Ndc(view, eye + view.far_m * forward).z(), 0.0, 1e-12);
  const Eigen::Vector3d centre = Ndc(view, eye + 100.0 * forward);
  EXPECT_NEAR(centre.x(), 0.0, 1e-12);
  EXPECT_NEAR(centre.y(), 0.0, 1e-12);
}

TEST(ProjectionTest, TheFieldOfViewsEdgesAreTheImagesEdges) {
  const CameraView view = View();
  const Eigen::Vector3d eye = view.X_WC.translation();
  const double d = 50.0, half_height = d * std::tan(0.5 * view.fov_y_rad);
  const double half_width = half_height * 640.0 / 480.0;
  // Up (world z) is the top of the image; the camera's left (world -x) its left.
  EXPECT_NEAR(Ndc(view, eye + Eigen::Vector3d(0, d, half_height)).y(), 1.0, 1e-12);
  EXPECT_NEAR(Ndc(view, eye + Eigen::Vector3d(-half_width, d, 0)).x(), -1.0, 1e-12);
  EXPECT_NEAR(Ndc(view, eye + Eigen::Vector3d(half_width, d, 0)).x(), 1.0, 1e-12);
}

TEST(ProjectionTest, NearReachIsTheDistanceToTheNearPlanesCorner) {
  const CameraView view = View();
  const double h = view.near_m * std::tan(0.5 * view.fov_y_rad), w = h * 640.0 / 480.0;
  EXPECT_NEAR(NearReach(view), std::sqrt(view.near_m * view.near_m + h * h + w * w), 1e-12);
  EXPECT_NEAR(PixelAngle(view), 2.0 * std::tan(0.5) / 480.0, 1e-9);
}

TEST(ProjectionTest, ADepthReadBackIsTheDistanceItCameFrom) {
  const CameraView view = View();
  for (const double d : {0.5, 1.0, 37.5, 1999.0}) {
    const double depth = Ndc(view, view.X_WC.translation() + Eigen::Vector3d(0, d, 0)).z();
    EXPECT_NEAR(ReversedDepth(view.near_m, view.far_m).Metres(float(depth)), d, d * 1e-5) << d;
  }
  EXPECT_EQ(ReversedDepth(view.near_m, view.far_m).Metres(0.f),
            std::numeric_limits<float>::infinity());
}

TEST(ProjectionTest, ABoxOutsideOnePlaneIsOutsideTheFrustum) {
  const CameraView view = View();
  const Eigen::Matrix4f M = (ReversedDepthProjection(view) * ViewRotation(view.X_WC)).cast<float>();
  auto box = [](float x, float y, float z) {
    return Eigen::AlignedBox3f(Eigen::Vector3f(x - 1, y - 1, z - 1),
                               Eigen::Vector3f(x + 1, y + 1, z + 1));
  };
  EXPECT_TRUE(InFrustum(M, box(0, 100, 0)));      // ahead
  EXPECT_FALSE(InFrustum(M, box(0, -100, 0)));    // behind
  EXPECT_FALSE(InFrustum(M, box(0, 100, -500)));  // far below
  // (Beyond the far plane it keeps the box: its depth planes are GL's -w..w,
  // wider than the zero-to-one depth drawn; the depth range clips it.)
  EXPECT_TRUE(InFrustum(M, box(0, 3000, 0)));
  EXPECT_FALSE(InFrustum(M, box(500, 100, 0)));  // far to the right
  EXPECT_TRUE(InFrustum(M, box(60, 100, 0)));  // inside the right edge (tan 0.5 * 4/3 * 100 = 72.8)
}

TEST(ReadBackTest, RowsComeOutTopFirst) {
  // 3 x 2, rows bottom first as GL reads them: values tell the row.
  const std::vector<std::uint32_t> ids = {10, 11, 12, 20, 21, 22};
  std::vector<std::uint32_t> flipped;
  FlippedImage(ids, 3, 2, &flipped);
  EXPECT_EQ(flipped, (std::vector<std::uint32_t>{20, 21, 22, 10, 11, 12}));
  const std::vector<float> normals = {1, 2, 3, 4, 5, 6};  // 1 x 2, three channels
  std::vector<float> normals_out;
  FlippedImage(normals, 1, 2, 3, &normals_out);
  EXPECT_EQ(normals_out, (std::vector<float>{4, 5, 6, 1, 2, 3}));
}

TEST(ReadBackTest, ColourDropsAlphaAndTakesTheMarks) {
  // 2 x 2 RGBA, bottom row first; a mark (alpha set) on the bottom row's right pixel.
  const std::vector<std::uint8_t> rgba = {1, 2, 3, 255, 4,  5,  6,  255,
                                          7, 8, 9, 255, 10, 11, 12, 255};
  const std::vector<std::uint32_t> marks = {0, 0xff332211u, 0, 0};
  std::vector<std::uint8_t> rgb;
  RgbImage(rgba.data(), 2, 2, nullptr, &rgb);
  EXPECT_EQ(rgb, (std::vector<std::uint8_t>{7, 8, 9, 10, 11, 12, 1, 2, 3, 4, 5, 6}));
  RgbImage(rgba.data(), 2, 2, &marks, &rgb);
  EXPECT_EQ(rgb, (std::vector<std::uint8_t>{7, 8, 9, 10, 11, 12, 1, 2, 3, 0x11, 0x22, 0x33}));
}

}  // namespace
}  // namespace sandbox::render
