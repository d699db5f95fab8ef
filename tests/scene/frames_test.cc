#include "scene/frames.h"

#include <gtest/gtest.h>

namespace sandbox::scene {
namespace {

using Eigen::Vector3d;

TEST(FramesTest, YUpAssetMapsAsBlenderDoes) {
  // DESIGN.md: asset (x, y, z) becomes world (x, -z, y).
  const Vector3d p = UpAxisToWorld(UpAxis::kPosY) * Vector3d(1, 2, 3);
  EXPECT_TRUE(p.isApprox(Vector3d(1, -3, 2), 1e-12)) << p.transpose();
}

TEST(FramesTest, EveryUpAxisBecomesWorldZ) {
  const std::pair<UpAxis, Vector3d> cases[] = {
      {UpAxis::kPosX, {1, 0, 0}},  {UpAxis::kNegX, {-1, 0, 0}}, {UpAxis::kPosY, {0, 1, 0}},
      {UpAxis::kNegY, {0, -1, 0}}, {UpAxis::kPosZ, {0, 0, 1}},  {UpAxis::kNegZ, {0, 0, -1}}};
  for (const auto& [axis, up] : cases) {
    const Eigen::Matrix3d R = UpAxisToWorld(axis);
    EXPECT_TRUE((R * up).isApprox(Vector3d::UnitZ(), 1e-12)) << ToString(axis);
    EXPECT_NEAR(R.determinant(), 1.0, 1e-12) << ToString(axis);
    EXPECT_EQ(ParseUpAxis(ToString(axis)), axis);
  }
  EXPECT_EQ(ParseUpAxis("+Y"), UpAxis::kPosY);
  EXPECT_FALSE(ParseUpAxis("up").has_value());
}

TEST(FramesTest, RollPitchYawComposeAsRzRyRx) {
  const double q = 90.0 * kDegToRad;
  // Yaw alone turns x into y; pitch alone turns x into -z; roll alone turns y into z.
  EXPECT_TRUE((RotationFromRollPitchYaw(0, 0, q) * Vector3d::UnitX()).isApprox(Vector3d::UnitY()));
  EXPECT_TRUE((RotationFromRollPitchYaw(0, q, 0) * Vector3d::UnitX()).isApprox(-Vector3d::UnitZ()));
  EXPECT_TRUE((RotationFromRollPitchYaw(q, 0, 0) * Vector3d::UnitY()).isApprox(Vector3d::UnitZ()));
  // Roll first, then yaw: y -> z (roll) -> z (yaw); x -> x (roll) -> y (yaw).
  const Eigen::Matrix3d R = RotationFromRollPitchYaw(q, 0, q);
  EXPECT_TRUE((R * Vector3d::UnitY()).isApprox(Vector3d::UnitZ()));
  EXPECT_TRUE((R * Vector3d::UnitX()).isApprox(Vector3d::UnitY()));
}

}  // namespace
}  // namespace sandbox::scene
