// Robots: bone maps, forward kinematics, skinning, run-time rejects and the
// robot's collision body, against chains of transforms built by hand.

#include <gtest/gtest.h>

#include <cmath>

#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"
#include "tests/test_util.h"

namespace sandbox::scene {
namespace {

using Eigen::AngleAxisd;
using Eigen::Isometry3d;
using Eigen::Vector3d;

constexpr double kDeg = 3.14159265358979323846 / 180.0;

std::filesystem::path RobotsLevel() {
  return std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/robots/robots.toml";
}

class RobotTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { level_ = new Level(LoadLevel(RobotsLevel())); }
  static void TearDownTestSuite() { delete level_; }
  static const RobotModel& Robot(const char* name) {
    const int index = level_->FindRobot(name);
    EXPECT_GE(index, 0) << name;
    return level_->robots.at(static_cast<std::size_t>(index));
  }
  // The posed vertex of mesh 0 nearest `p_B` at rest.
  static std::size_t NearestRestVertex(const RobotState& rest, const Vector3d& p_B) {
    const auto& positions = rest.positions_B(0);
    std::size_t best = 0;
    for (std::size_t v = 0; v < positions.size(); ++v) {
      if ((positions[v].cast<double>() - p_B).norm() <
          (positions[best].cast<double>() - p_B).norm()) {
        best = v;
      }
    }
    return best;
  }
  static Level* level_;
};
Level* RobotTest::level_ = nullptr;

// The flying wing's bone layout (robot_shapes.h, restated): joint 1 of a side
// 0.6 m out from the centre, the next nine 1.2 m apart; the tip 12.6 m out.
Isometry3d WingChain(int side, double roll_rad, const Isometry3d& X_BR = Isometry3d::Identity()) {
  Isometry3d X = X_BR;
  for (int k = 1; k <= 10; ++k) {
    X = X * Eigen::Translation3d(0, side * (k == 1 ? 0.6 : 1.2), 0) *
        AngleAxisd(roll_rad, Vector3d::UnitX());
  }
  return X;  // frame of bone 10 of that side
}

TEST_F(RobotTest, WingBendsNinetyDegreesTipToTipAsTheAnalyticChain) {
  const RobotModel& wing = Robot("ELAHA");
  ASSERT_EQ(wing.bones.size(), 24u);
  EXPECT_EQ(wing.bones[1].name, "R1");
  EXPECT_EQ(wing.bones[20].name, "L10");
  const RobotState rest(wing);
  RobotState state(wing);
  // Right bones 1-10 roll +4.5 degrees, left bones 11-20 roll -4.5 degrees.
  for (int b = 1; b <= 20; ++b) {
    const double values[2] = {(b <= 10 ? 4.5 : -4.5) * kDeg, 0.0};
    ASSERT_TRUE(state.SetBone(b, values, 2));
  }
  state.Update();
  for (const int side : {-1, 1}) {
    // The tip's centre vertex (the cap) sits 1.2 m beyond joint 10 at rest.
    const Vector3d tip_rest(-0.15, side * 12.6, 0.0);
    const std::size_t v = NearestRestVertex(rest, tip_rest);
    ASSERT_LT((rest.positions_B(0)[v].cast<double>() - tip_rest).norm(), 1e-4);
    const Isometry3d X_B10 = WingChain(side, side * -4.5 * kDeg);
    const Vector3d expected = X_B10 * Vector3d(-0.15, side * 1.2, 0.0);
    EXPECT_LT((state.positions_B(0)[v].cast<double>() - expected).norm(), 1e-3)
        << "side " << side << ": " << state.positions_B(0)[v].transpose() << " expected "
        << expected.transpose();
    // Bone 10's frame agrees with the chain too.
    const int node = wing.bones[static_cast<std::size_t>(side < 0 ? 10 : 20)].node;
    EXPECT_TRUE(state.node_poses_B()[static_cast<std::size_t>(node)].matrix().isApprox(
        X_B10.matrix(), 1e-6));
  }
  // 45 degrees down on each side: the tip frames differ by 90 degrees.
  const Eigen::Matrix3d R_right =
      state.node_poses_B()[static_cast<std::size_t>(wing.bones[10].node)].linear();
  const Eigen::Matrix3d R_left =
      state.node_poses_B()[static_cast<std::size_t>(wing.bones[20].node)].linear();
  EXPECT_NEAR(AngleAxisd(R_right.transpose() * R_left).angle(), 90.0 * kDeg, 1e-5);
}

// The loop moves node poses every tick and skins only when a camera draws:
// UpdateKinematics leaves the posed mesh alone, Skin catches it up to exactly
// what Update makes.
TEST_F(RobotTest, SkinningWaitsForSkinAndThenMatchesUpdate) {
  const RobotModel& wing = Robot("ELAHA");
  const RobotState rest(wing);
  RobotState lazy(wing), eager(wing);
  EXPECT_TRUE(lazy.skinned());
  for (int b = 1; b <= 20; ++b) {
    const double values[2] = {(b <= 10 ? 4.5 : -4.5) * kDeg, 0.0};
    ASSERT_TRUE(lazy.SetBone(b, values, 2));
    ASSERT_TRUE(eager.SetBone(b, values, 2));
  }
  lazy.UpdateKinematics();
  eager.Update();
  EXPECT_FALSE(lazy.skinned());
  EXPECT_TRUE(lazy.node_poses_B()[std::size_t(wing.bones[10].node)].isApprox(
      eager.node_poses_B()[std::size_t(wing.bones[10].node)]));
  EXPECT_EQ(lazy.positions_B(0), rest.positions_B(0));  // still the old pose
  lazy.Skin();
  EXPECT_TRUE(lazy.skinned());
  EXPECT_EQ(lazy.positions_B(0), eager.positions_B(0));
  EXPECT_EQ(lazy.normals_B(0), eager.normals_B(0));
  EXPECT_NE(lazy.positions_B(0), rest.positions_B(0));
}
TEST_F(RobotTest, BentWingSkinHasNoCracks) {
  const RobotModel& wing = Robot("ELAHA");
  const RobotState rest(wing);
  RobotState state(wing);
  for (int b = 1; b <= 20; ++b) {
    const double values[2] = {(b <= 10 ? 4.5 : -4.5) * kDeg, 2.0 * kDeg};
    ASSERT_TRUE(state.SetBone(b, values, 2));
  }
  state.Update();
  // Every triangle keeps its shape to within the bend: no edge stretches or
  // shrinks by more than 10% (a crack would tear an edge open).
  const std::vector<std::uint32_t>& indices = wing.meshes[0].bind.indices;
  double worst = 0.0;
  for (std::size_t t = 0; t < indices.size(); t += 3) {
    for (int e = 0; e < 3; ++e) {
      const std::uint32_t a = indices[t + std::size_t(e)],
                          b = indices[t + std::size_t((e + 1) % 3)];
      const double before = (rest.positions_B(0)[a] - rest.positions_B(0)[b]).norm();
      const double after = (state.positions_B(0)[a] - state.positions_B(0)[b]).norm();
      if (before > 1e-4) worst = std::max(worst, std::abs(after / before - 1.0));
    }
  }
  EXPECT_LT(worst, 0.1);
  for (const auto& p : state.positions_B(0)) ASSERT_TRUE(p.allFinite());
}

TEST_F(RobotTest, ParentRotationCarriesTheTips) {
  const RobotModel& wing = Robot("ELAHA");
  const RobotState rest(wing);
  RobotState state(wing);
  const double root[2] = {0.0, 10.0 * kDeg};  // pitch the root 10 degrees
  ASSERT_TRUE(state.SetBone(0, root, 2));
  state.Update();
  const Eigen::Matrix3d R = AngleAxisd(10.0 * kDeg, Vector3d::UnitY()).toRotationMatrix();
  for (const double y : {-12.6, 12.6}) {
    const std::size_t v = NearestRestVertex(rest, Vector3d(0.35, y, 0.0));
    const Vector3d expected = R * rest.positions_B(0)[v].cast<double>();
    EXPECT_LT((state.positions_B(0)[v].cast<double>() - expected).norm(), 1e-4);
  }
  // The world pose moves everything with it.
  Isometry3d X_WB = Eigen::Translation3d(100, 200, 300) * AngleAxisd(0.5, Vector3d::UnitZ());
  ASSERT_TRUE(state.SetPose(X_WB));
  const int tip = wing.bones[10].node;
  EXPECT_TRUE(state.node_pose_W(tip).matrix().isApprox(
      (X_WB * state.node_poses_B()[static_cast<std::size_t>(tip)]).matrix()));
}

TEST_F(RobotTest, ArmEndEffectorIsTheProductOfJointTransforms) {
  const RobotModel& arm = Robot("ARM");
  RobotState state(arm);
  const double q[6] = {0.3, -0.7, 1.1, 0.4, -0.9, 1.7};
  for (int j = 0; j < 6; ++j) ASSERT_TRUE(state.SetBone(j + 1, &q[j], 1));
  state.Update();
  // Hand-written chain: base at the spawn pose (20, 0, 0); joint offsets up z
  // 0.25, 0.2, 0.6, 0.5, 0.15, 0.1; axes z, y, y, z, y, z; tool 0.08 above joint 6.
  const double offsets[6] = {0.25, 0.2, 0.6, 0.5, 0.15, 0.1};
  const Vector3d axes[6] = {Vector3d::UnitZ(), Vector3d::UnitY(), Vector3d::UnitY(),
                            Vector3d::UnitZ(), Vector3d::UnitY(), Vector3d::UnitZ()};
  Isometry3d X = Isometry3d(Eigen::Translation3d(20, 0, 0));
  for (int j = 0; j < 6; ++j) {
    X = X * Eigen::Translation3d(0, 0, offsets[j]) * AngleAxisd(q[j], axes[j]);
  }
  X = X * Eigen::Translation3d(0, 0, 0.08);
  const Eigen::Affine3d X_WT = state.node_pose_W(arm.FindNode("tool"));
  // The glTF file stores floats: agreement to float precision.
  EXPECT_LT((X_WT.translation() - X.translation()).norm(), 1e-5) << X_WT.translation().transpose();
  EXPECT_TRUE(X_WT.linear().isApprox(X.linear(), 1e-6));
}

TEST_F(RobotTest, BadRunTimeUpdatesAreRejectedCountedAndChangeNothing) {
  const RobotModel& arm = Robot("ARM");
  RobotState state(arm);
  const double good = 0.5;
  ASSERT_TRUE(state.SetBone(2, &good, 1));
  state.Update();
  const Eigen::Affine3d before = state.node_pose_W(arm.FindNode("tool"));
  const double nan = std::nan("");
  const double two[2] = {0.1, 0.2};
  EXPECT_FALSE(state.SetBone(2, &nan, 1));
  EXPECT_FALSE(state.SetBone(7, &good, 1));
  EXPECT_FALSE(state.SetBone(-1, &good, 1));
  EXPECT_FALSE(state.SetBone(2, two, 2));
  EXPECT_FALSE(state.SetBones({0.1, 0.2}));
  std::vector<double> all(7, 0.2);
  all[6] = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(state.SetBones(all));  // one bad value rejects the whole update
  Isometry3d bad = Isometry3d::Identity();
  bad.translation().x() = nan;
  EXPECT_FALSE(state.SetPose(bad));
  Isometry3d sheared = Isometry3d::Identity();
  sheared.linear()(0, 1) = 0.5;
  EXPECT_FALSE(state.SetPose(sheared));
  state.Update();
  EXPECT_TRUE(state.node_pose_W(arm.FindNode("tool")).isApprox(before));
  // The values in use are the last good ones: bone 2 (one angle, like every arm bone) at 0.5.
  std::vector<double> in_use(7, 0.0);
  in_use[2] = 0.5;
  EXPECT_EQ(state.bone_values(), in_use);
  const auto& rejected = state.rejected();
  EXPECT_EQ(rejected.at("non-finite bone value"), 2);
  EXPECT_EQ(rejected.at("bone index out of range"), 2);
  EXPECT_EQ(rejected.at("wrong number of bone values"), 2);
  EXPECT_EQ(rejected.at("non-finite pose"), 1);
  EXPECT_EQ(rejected.at("pose rotation is not a rotation"), 1);
}

TEST_F(RobotTest, QuaternionBonesRejectNonUnitQuaternions) {
  testing::TempDir dir;
  const Level level = LoadLevel(
      dir.Write("q.toml", "[[robot]]\nname = \"q\"\nfile = \"" +
                              (RobotsLevel().parent_path() / "generated/arm.gltf").string() +
                              "\"\nbones = [\"base\", \"link1\"]\n"));
  RobotState state(level.robots[0]);
  EXPECT_EQ(state.bone_values(), std::vector<double>({1, 0, 0, 0, 1, 0, 0, 0}));  // at rest
  const double half_turn[4] = {0.0, 0.0, 0.0, 1.0};
  const double long_q[4] = {1.0, 1.0, 0.0, 0.0};
  EXPECT_TRUE(state.SetBone(1, half_turn, 4));
  EXPECT_FALSE(state.SetBone(1, long_q, 4));
  EXPECT_EQ(state.bone_values(), std::vector<double>({1, 0, 0, 0, 0, 0, 0, 1}));
  EXPECT_EQ(state.rejected().at("non-unit bone quaternion"), 1);
  EXPECT_EQ(state.last_rejection(), "non-unit bone quaternion");
  state.Update();
  // link1 turned 180 degrees about z (in its rest frame = the robot's axes).
  EXPECT_TRUE(
      state.node_poses_B()[static_cast<std::size_t>(level.robots[0].FindNode("link1"))]
          .linear()
          .isApprox(AngleAxisd(3.14159265358979323846, Vector3d::UnitZ()).toRotationMatrix(),
                    1e-6));
}

TEST_F(RobotTest, RobotCollisionFollowsTheBentWingAndIgnoresItself) {
  const RobotModel& wing = Robot("ELAHA");
  const int robot = level_->FindRobot("ELAHA");
  CollisionWorld world(*level_);
  RobotState state(wing);
  // At rest, a ray down at the right tip hits the wing's upper surface (z 10 + 0.06).
  const Vector3d above_tip(-0.15, -12.3, 20);
  auto hit = world.CastRay(above_tip, above_tip - Vector3d(0, 0, 30));
  ASSERT_TRUE(hit.has_value());
  EXPECT_EQ(hit->robot, robot);
  EXPECT_EQ(hit->actor, -1);
  EXPECT_NEAR(hit->point_W.z(), 10.06, 2e-3);
  // The robot's own sensors do not see it.
  EXPECT_FALSE(
      world.CastRay(above_tip, above_tip - Vector3d(0, 0, 30), kAllGroups, -1, robot).has_value());
  // Bent 90 degrees tip to tip, the tip has gone down and inwards: the old ray
  // misses and a ray at the new tip hits it.
  for (int b = 1; b <= 20; ++b) {
    const double values[2] = {(b <= 10 ? 4.5 : -4.5) * kDeg, 0.0};
    ASSERT_TRUE(state.SetBone(b, values, 2));
  }
  state.Update();
  world.UpdateRobot(robot, state);
  const Vector3d tip_W = state.pose() * (WingChain(-1, 4.5 * kDeg) * Vector3d(-0.15, -0.9, 0.0));
  EXPECT_FALSE(world.CastRay(above_tip, above_tip - Vector3d(0, 0, 30), kRobot).has_value());
  hit = world.CastRay(tip_W + Vector3d(0, -5, 0), tip_W + Vector3d(0, 5, 0), kRobot);
  ASSERT_TRUE(hit.has_value());
  EXPECT_LT((hit->point_W - tip_W).norm(), 0.1);
  // Moving the robot moves its body.
  Isometry3d X_WB = state.pose();
  X_WB.translation() += Vector3d(0, 0, 50);
  ASSERT_TRUE(state.SetPose(X_WB));
  world.UpdateRobot(robot, state);
  EXPECT_FALSE(
      world.CastRay(tip_W + Vector3d(0, -5, 0), tip_W + Vector3d(0, 5, 0), kRobot).has_value());
}

std::string LoadError(const std::string& toml) {
  testing::TempDir dir;
  const auto file = dir.Write("level.toml", toml);
  try {
    LoadLevel(file);
  } catch (const LevelError& error) {
    return error.what();
  }
  return "no error";
}

TEST(RobotLoadTest, BadBoneMapsAreClearErrors) {
  const std::string arm = (RobotsLevel().parent_path() / "generated/arm.gltf").string();
  const std::string box = (RobotsLevel().parent_path() / "generated/box.gltf").string();
  const std::string head = "[[robot]]\nname = \"r\"\nfile = \"" + arm + "\"\n";
  EXPECT_NE(LoadError(head + "bones = [\"base\", \"elbow\"]\n")
                .find(":1: robot 'r': bone 'elbow' is not a node of arm.gltf (nodes: base, link1"),
            std::string::npos)
      << LoadError(head + "bones = [\"base\", \"elbow\"]\n");
  EXPECT_NE(
      LoadError(head + "bones = [\"b0\",\"b1\",\"b2\",\"b3\",\"b4\",\"b5\",\"b6\",\"b7\",\"b8\"]\n")
          .find("the bone map lists 9 bones, the skeleton of arm.gltf has 8 nodes"),
      std::string::npos);
  EXPECT_NE(
      LoadError(head + "bones = [\"link3\", \"link1\"]\n")
          .find("bone 0 'link3' must be the root of the bone map, but 'link1' is not below it"),
      std::string::npos);
  EXPECT_NE(
      LoadError("[[robot]]\nname = \"r\"\nfile = \"" + box + "\"\nbones = [\"box\"]\n")
          .find("box.gltf has no skeleton (no bones and a single node), but 'bones' declares 1"),
      std::string::npos);
  EXPECT_NE(LoadError(head + "bones = [\"base\", \"base\"]\n")
                .find(":4: robot 'r': bone 'base' is listed twice"),
            std::string::npos);
  EXPECT_NE(LoadError(head + "bones = [\"base\"]\nrotation = \"euler\"\n")
                .find("'rotation' must be \"quaternion\" or \"angles\", got 'euler'"),
            std::string::npos);
  EXPECT_NE(
      LoadError(head + "bones = [\"base\"]\nrotation = \"angles\"\n").find("needs 'angle_axes'"),
      std::string::npos);
  EXPECT_NE(LoadError(head + "bones = [\"base\"]\nrotation = \"angles\"\nangle_axes = [\"w\"]\n")
                .find(":6: robot 'r': 'angle_axes' takes axis names"),
            std::string::npos);
  EXPECT_NE(LoadError(head + "bones = [\"base\"]\nrotation = \"angles\"\nangle_axes = [\"z\"]\n"
                             "[robot.bone_axes]\nlink9 = [\"y\"]\n")
                .find("'bone_axes' names 'link9', which is not in 'bones'"),
            std::string::npos);
  EXPECT_NE(LoadError("[[robot]]\nname = \"r\"\nfile = \"missing.glb\"\n").find(":1: robot 'r': "),
            std::string::npos);
}

}  // namespace
}  // namespace sandbox::scene
