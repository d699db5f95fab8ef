// Latest-value inputs over LCM (memq://, one process): newest wins, bad
// messages are rejected with a reason and the last good value stays.

#include "bridge/robot_inputs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <sstream>

#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/joint_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "tests/test_util.h"

namespace sandbox::bridge {
namespace {

using Eigen::Vector3d;

template <typename Message>
void Publish(LcmLink& link, const std::string& channel, const Message& message) {
  std::vector<std::uint8_t> bytes(std::size_t(message.getEncodedSize()));
  message.encode(bytes.data(), 0, int(bytes.size()));
  ASSERT_TRUE(link.Publish(channel, bytes.data(), unsigned(bytes.size())));
}

sandbox_msgs::robot_pose_t Pose(std::int64_t seq, double x, double y, double z) {
  sandbox_msgs::robot_pose_t pose{};
  pose.utime = 1000 * seq;
  pose.seq = seq;
  pose.position[0] = x, pose.position[1] = y, pose.position[2] = z;
  pose.orientation[0] = 1.0;
  return pose;
}

class RobotInputsTest : public ::testing::Test {
 protected:
  RobotInputsTest()
      : level_(scene::LoadLevel(testing::SampleLevel())),
        world_(level_),
        state_(level_.robots.at(0)),
        link_("memq://"),
        inputs_(link_, level_, 0) {}
  // Every message published so far: one drain has a time budget (16
  // messages at least), and a busy machine may need several.
  int DrainAll() {
    int handled = 0;
    for (int n = link_.Drain(); n > 0; n = link_.Drain()) handled += n;
    return handled;
  }
  scene::Level level_;
  scene::CollisionWorld world_;
  scene::RobotState state_;
  LcmLink link_;
  RobotInputs inputs_;
};

TEST_F(RobotInputsTest, NewestPoseWinsAndOlderOnesAreCountedAsSuperseded) {
  for (int seq = 1; seq <= 5; ++seq) Publish(link_, "ELAHA/POSE", Pose(seq, seq, 0, 50));
  EXPECT_EQ(DrainAll(), 5);
  const RobotInputs::Applied applied = inputs_.Apply(&state_, &world_);
  EXPECT_TRUE(applied.pose) << inputs_.pose().last_reject_reason();
  EXPECT_EQ(applied.pose_seq, 5);
  EXPECT_TRUE(state_.pose().translation().isApprox(Vector3d(5, 0, 50)));
  EXPECT_EQ(inputs_.pose().received(), 5);
  EXPECT_EQ(inputs_.pose().superseded(), 4);
  // Nothing new: nothing applied.
  DrainAll();
  EXPECT_FALSE(inputs_.Apply(&state_, &world_).pose);
}

TEST_F(RobotInputsTest, BadMessagesAreRejectedAndTheLastGoodValueStays) {
  Publish(link_, "ELAHA/POSE", Pose(1, 10, 20, 30));
  DrainAll();
  inputs_.Apply(&state_, &world_);
  // Random bytes on every channel.
  std::mt19937 random(3);
  for (const char* channel : {"ELAHA/POSE", "ELAHA/BONES", "ELAHA/ACTORS"}) {
    std::vector<std::uint8_t> junk(64);
    for (auto& b : junk) b = std::uint8_t(random());
    link_.Publish(channel, junk.data(), unsigned(junk.size()));
    DrainAll();
    inputs_.Apply(&state_, &world_);
  }
  const std::string other_type = ": wrong fingerprint (another type?)";
  EXPECT_EQ(inputs_.pose().last_reject_reason(), "cannot decode as robot_pose_t" + other_type);
  EXPECT_EQ(inputs_.bones().last_reject_reason(), "cannot decode as bone_values_t" + other_type);
  EXPECT_EQ(inputs_.actors().last_reject_reason(),
            "cannot decode as actor_placements_t" + other_type);
  // NaN, a long quaternion.
  Publish(link_, "ELAHA/POSE", Pose(2, std::nan(""), 0, 0));
  DrainAll();
  inputs_.Apply(&state_, &world_);
  EXPECT_EQ(inputs_.pose().last_reject_reason(), "non-finite pose");
  sandbox_msgs::robot_pose_t long_q = Pose(3, 1, 2, 3);
  long_q.orientation[1] = 1.0;
  Publish(link_, "ELAHA/POSE", long_q);
  DrainAll();
  inputs_.Apply(&state_, &world_);
  EXPECT_EQ(inputs_.pose().last_reject_reason(), "non-unit quaternion");
  EXPECT_TRUE(state_.pose().translation().isApprox(Vector3d(10, 20, 30)));
  EXPECT_EQ(inputs_.pose().rejected(), 3);
  // A bone message of the wrong length.
  sandbox_msgs::bone_values_t bones{};
  bones.num_values = 10;
  bones.values.assign(10, 0.0);
  Publish(link_, "ELAHA/BONES", bones);
  DrainAll();
  inputs_.Apply(&state_, &world_);
  EXPECT_EQ(inputs_.bones().last_reject_reason(), "expected 45 bone values, got 10");
  // An unknown actor and a static one.
  sandbox_msgs::actor_placements_t actors{};
  actors.num_actors = 1;
  actors.names = {"drawbridge"};
  actors.num_positions = 3;
  actors.positions = {0, 0, 0};
  actors.num_orientations = 4;
  actors.orientations = {1, 0, 0, 0};
  Publish(link_, "ELAHA/ACTORS", actors);
  DrainAll();
  inputs_.Apply(&state_, &world_);
  EXPECT_EQ(inputs_.actors().last_reject_reason(), "unknown actor 'drawbridge'");
  actors.names = {"wall"};
  Publish(link_, "ELAHA/ACTORS", actors);
  DrainAll();
  inputs_.Apply(&state_, &world_);
  EXPECT_EQ(inputs_.actors().last_reject_reason(), "actor 'wall' is not movable");
}

TEST_F(RobotInputsTest, BonesAndActorPlacementsApply) {
  sandbox_msgs::bone_values_t bones{};
  bones.num_values = 45;
  bones.values.assign(45, 0.0);
  const double roll = 4.5 * M_PI / 180.0;
  for (int b = 1; b <= 10; ++b) bones.values[std::size_t(2 * b)] = roll;  // bone b: values 2b, 2b+1
  Publish(link_, "ELAHA/BONES", bones);
  sandbox_msgs::actor_placements_t actors{};
  actors.num_actors = 1;
  actors.names = {"gate"};
  actors.num_positions = 3;
  actors.positions = {-100, 100, 60};
  actors.num_orientations = 4;
  actors.orientations = {1, 0, 0, 0};
  Publish(link_, "ELAHA/ACTORS", actors);
  DrainAll();
  const RobotInputs::Applied applied = inputs_.Apply(&state_, &world_);
  EXPECT_TRUE(applied.bones);
  EXPECT_TRUE(applied.actors);
  state_.Update();
  const int r10 = level_.robots[0].bones[10].node;
  EXPECT_NEAR(Eigen::AngleAxisd(state_.node_poses_B()[std::size_t(r10)].linear()).angle(),
              10 * roll, 1e-5);
  EXPECT_EQ(world_.CastRay({-100, 100, 80}, {-100, 100, 0})->actor, level_.FindActor("gate"));
  EXPECT_FALSE(inputs_.bones().Stale(inputs_.bones().last_receive_utime(), 0.5));
  EXPECT_TRUE(inputs_.pose().Stale(inputs_.bones().last_receive_utime(), 0.5));  // never came
}

TEST_F(RobotInputsTest, CameraCommandsSteerTheTrailingCameraAndSwitchTheActiveOne) {
  sandbox_msgs::camera_command_t command{};
  command.active_camera = "belly";
  command.pan_rad = 0.3, command.tilt_rad = -0.1, command.zoom = 2.0;
  Publish(link_, "ELAHA/CAMERA", command);
  DrainAll();
  EXPECT_TRUE(inputs_.Apply(&state_, &world_).camera) << inputs_.camera().last_reject_reason();
  EXPECT_EQ(inputs_.active_camera(), "belly");
  EXPECT_EQ(inputs_.trailing().pan_rad, 0.3);
  EXPECT_EQ(inputs_.trailing().tilt_rad, -0.1);
  EXPECT_EQ(inputs_.trailing().zoom, 2.0);
  // Bad commands are rejected whole; the last good one stays.
  command.zoom = 0.0;
  Publish(link_, "ELAHA/CAMERA", command);
  DrainAll();
  EXPECT_FALSE(inputs_.Apply(&state_, &world_).camera);
  EXPECT_EQ(inputs_.camera().last_reject_reason(), "zoom must be in (0, 100]");
  command.zoom = 1.5;
  command.active_camera = "periscope";
  Publish(link_, "ELAHA/CAMERA", command);
  DrainAll();
  EXPECT_FALSE(inputs_.Apply(&state_, &world_).camera);
  EXPECT_EQ(inputs_.camera().last_reject_reason(), "unknown camera 'periscope'");
  EXPECT_EQ(inputs_.camera().rejected(), 2);
  EXPECT_EQ(inputs_.active_camera(), "belly");
  EXPECT_EQ(inputs_.trailing().zoom, 2.0);
  // An empty name keeps the active camera and still steers.
  command.active_camera = "";
  Publish(link_, "ELAHA/CAMERA", command);
  DrainAll();
  EXPECT_TRUE(inputs_.Apply(&state_, &world_).camera);
  EXPECT_EQ(inputs_.active_camera(), "belly");
  EXPECT_EQ(inputs_.trailing().zoom, 1.5);
}

TEST_F(RobotInputsTest, HostileMessagesNeverDisplaceTheGoodOneWaiting) {
  Publish(link_, "ELAHA/POSE", Pose(1, 10, 20, 30));
  sandbox_msgs::bone_values_t bones{};
  bones.num_values = 45;
  bones.values.assign(45, 0.0);
  bones.values[2] = 0.1;
  Publish(link_, "ELAHA/BONES", bones);
  // After the good messages: a negative count, a count of two billion, a
  // message far over the channel's budget, a NaN pose and another type.
  std::vector<std::uint8_t> negative(std::size_t(bones.getEncodedSize()));
  bones.encode(negative.data(), 0, int(negative.size()));
  negative[24] = 0xff, negative[25] = 0xff, negative[26] = 0xff, negative[27] = 0xfb;
  link_.Publish("ELAHA/BONES", negative.data(), unsigned(negative.size()));
  std::vector<std::uint8_t> huge = negative;
  huge[24] = 0x7f;
  link_.Publish("ELAHA/BONES", huge.data(), unsigned(huge.size()));
  const std::vector<std::uint8_t> oversized(8u << 20, 0x41);
  link_.Publish("ELAHA/BONES", oversized.data(), unsigned(oversized.size()));
  link_.Publish("ELAHA/ACTORS", oversized.data(), unsigned(oversized.size()));
  Publish(link_, "ELAHA/POSE", Pose(2, std::nan(""), 0, 0));
  Publish(link_, "ELAHA/POSE", bones);
  DrainAll();
  const RobotInputs::Applied applied = inputs_.Apply(&state_, &world_);
  ASSERT_TRUE(applied.pose);
  EXPECT_EQ(applied.pose_seq, 1);
  EXPECT_TRUE(applied.bones);
  EXPECT_EQ(state_.bone_values()[2], 0.1);
  EXPECT_EQ(inputs_.pose().rejected(), 2);
  EXPECT_EQ(inputs_.pose().superseded(), 0);
  EXPECT_EQ(inputs_.bones().rejected(), 3);
  const std::map<std::string, std::int64_t>& reasons = inputs_.bones().rejected_by_reason();
  EXPECT_EQ(reasons.at("cannot decode as bone_values_t: num_values is negative"), 1);
  EXPECT_EQ(reasons.at("cannot decode as bone_values_t: values runs past the end"), 1);
  EXPECT_EQ(reasons.at("over the channel's budget of 65924 bytes"), 1);
  EXPECT_EQ(inputs_.actors().last_reject_reason(), "over the channel's budget of 1048576 bytes");
}

TEST_F(RobotInputsTest, TheNewestOfAThousandPosesBetweenTwoTicksWins) {
  // 1000 poses within one tick: 100 kHz at 100 ticks a second. LCM's own
  // queue (30 messages by default) would keep the oldest and drop the rest.
  for (int seq = 1; seq <= 1000; ++seq) Publish(link_, "ELAHA/POSE", Pose(seq, seq, 0, 50));
  DrainAll();
  const RobotInputs::Applied applied = inputs_.Apply(&state_, &world_);
  EXPECT_EQ(applied.pose_seq, 1000);
  EXPECT_EQ(inputs_.pose().received(), 1000);
  EXPECT_EQ(inputs_.pose().superseded(), 999);
}

TEST_F(RobotInputsTest, ReasonsQuotingTheSenderAreBoundedAndPrintable) {
  sandbox_msgs::actor_placements_t actors{};
  actors.num_actors = 1;
  actors.num_positions = 3;
  actors.positions = {0, 0, 0};
  actors.num_orientations = 4;
  actors.orientations = {1, 0, 0, 0};
  for (int i = 0; i < 200; ++i) {
    actors.names = {"\x1b[2Jactor " + std::to_string(i) + std::string(500, 'x')};
    Publish(link_, "ELAHA/ACTORS", actors);
  }
  DrainAll();
  EXPECT_EQ(inputs_.actors().rejected(), 200);
  EXPECT_LE(inputs_.actors().rejected_by_reason().size(), LatestInput::kMaxReasons + 1);
  EXPECT_EQ(inputs_.actors().rejected_by_reason().at("other"), 200 - 32);
  const std::string& last = inputs_.actors().last_reject_reason();
  EXPECT_EQ(last.rfind("unknown actor '?[2Jactor 199xxx", 0), 0u) << last;
  EXPECT_LE(last.size(), 160u);
  EXPECT_EQ(last.find('\x1b'), std::string::npos);
}

TEST(LcmLinkTest, MulticastUrlsGetABigReceiveBuffer) {
  EXPECT_EQ(WithReceiveBuffer(""), "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=4194304");
  EXPECT_EQ(WithReceiveBuffer("udpm://239.255.76.67:7667"),
            "udpm://239.255.76.67:7667?recv_buf_size=4194304");
  EXPECT_EQ(WithReceiveBuffer("udpm://239.255.76.67:7667?recv_buf_size=1000"),
            "udpm://239.255.76.67:7667?recv_buf_size=1000");
  EXPECT_EQ(WithReceiveBuffer("memq://"), "memq://");
  EXPECT_THROW(LcmLink("nonsense://"), std::runtime_error);
}

}  // namespace
}  // namespace sandbox::bridge

namespace sandbox::bridge {
namespace {

TEST(RejectLogTest, OncePerCausePerSecond) {
  std::ostringstream out;
  RejectLog log(&out);
  for (int i = 0; i < 5; ++i) log.Note("ELAHA/POSE", "non-finite pose");
  log.Note("ELAHA/POSE", "non-unit quaternion");
  log.Note("ELAHA/BONES", "non-finite pose");
  EXPECT_EQ(out.str(),
            "sandbox: ELAHA/POSE: rejected (non-finite pose)\n"
            "sandbox: ELAHA/POSE: rejected (non-unit quaternion)\n"
            "sandbox: ELAHA/BONES: rejected (non-finite pose)\n");
}

// JOINTS on the bundled URDF arm: by name, in the joint order, and refused
// whole for an unknown name, a value beyond a limit or NaN.
TEST(JointsInputTest, JointValuesByNameOrInOrderAllOrNothing) {
  const scene::Level level =
      scene::LoadLevel(std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/arm/arm.urdf");
  const scene::RobotModel& arm = level.robots.at(0);
  scene::CollisionWorld world(level);
  scene::RobotState state(arm);
  LcmLink link("memq://");
  RobotInputs inputs(link, level, 0);
  auto joints = [](std::int64_t seq, std::vector<std::string> names, std::vector<double> values) {
    sandbox_msgs::joint_values_t message{};
    message.seq = seq;
    message.num_names = int(names.size());
    message.names = std::move(names);
    message.num_values = int(values.size());
    message.values = std::move(values);
    return message;
  };
  auto value_of = [&](const char* joint) {
    return state
        .bone_values()[std::size_t(arm.bones[std::size_t(arm.FindBone(joint))].first_value)];
  };
  auto send = [&](const sandbox_msgs::joint_values_t& message) {
    Publish(link, "arm/JOINTS", message);
    while (link.Drain() > 0) {
    }
    return inputs.Apply(&state, &world).bones;
  };
  EXPECT_TRUE(send(joints(1, {"elbow", "extend"}, {0.5, 0.1})));
  EXPECT_EQ(value_of("elbow"), 0.5);
  EXPECT_EQ(value_of("extend"), 0.1);
  EXPECT_EQ(value_of("shoulder"), 0.0);  // not named: kept
  // Every joint in order (sandbox info's: base_yaw, shoulder, elbow, extend, wrist_roll).
  EXPECT_TRUE(send(joints(2, {}, {3.5, -0.2, -1.0, 0.05, 2.0})));
  EXPECT_EQ(value_of("base_yaw"), 3.5);
  EXPECT_EQ(value_of("wrist_roll"), 2.0);
  // Refused whole, the last good values kept, each counted by reason.
  EXPECT_FALSE(send(joints(3, {"shoulder", "nose"}, {0.1, 0.2})));
  EXPECT_FALSE(send(joints(4, {"shoulder", "extend"}, {0.1, 0.2})));  // extend: 0 .. 0.15 m
  EXPECT_FALSE(send(joints(5, {"elbow"}, {std::nan("")})));
  EXPECT_FALSE(send(joints(6, {}, {0.0, 0.0})));
  EXPECT_FALSE(send(joints(7, {"elbow", "shoulder"}, {0.1})));
  EXPECT_EQ(value_of("shoulder"), -0.2);
  EXPECT_EQ(value_of("extend"), 0.05);
  const std::map<std::string, std::int64_t>& reasons = inputs.joints().rejected_by_reason();
  EXPECT_EQ(reasons.at("unknown joint 'nose'"), 1);
  EXPECT_EQ(reasons.at("joint value beyond its limits ('extend')"), 1);
  EXPECT_EQ(reasons.at("non-finite bone value ('elbow')"), 1);
  EXPECT_EQ(reasons.at("expected 5 joint values, got 2"), 1);
  EXPECT_EQ(reasons.at("2 names but 1 values"), 1);
  EXPECT_EQ(inputs.joints().rejected(), 5);
}

}  // namespace
}  // namespace sandbox::bridge
