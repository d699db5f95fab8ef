// A --record log's STATEs as a replay's inputs: which robots, in which
// convention, and what a STATE that does not decode does.
#include "bridge/recorded_states.h"

#include <gtest/gtest.h>

#include <cmath>

#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "tests/encoded.h"

namespace {

using namespace sandbox::bridge;
using sandbox::testing::Encoded;

template <typename Message>
Message Decode(const LogEvent& event) {
  Message message;
  EXPECT_EQ(message.decode(event.data.data(), 0, int(event.data.size())), int(event.data.size()));
  return message;
}

// A state in the world frame: 10 m east, 20 m north, 30 m up, heading north
// (the body's x along the world's y), with two bone values.
sandbox_msgs::robot_state_t NorthboundState() {
  sandbox_msgs::robot_state_t state{};
  state.utime = 5'000'000;
  state.seq = 7;
  state.position[0] = 10, state.position[1] = 20, state.position[2] = 30;
  state.orientation[0] = std::cos(M_PI / 4), state.orientation[3] = std::sin(M_PI / 4);
  state.num_values = 2;
  state.bone_values = {0.25, -0.5};
  return state;
}

TEST(StatesAsInputsTest, AStateBecomesBonesThenPoseInTheRobotsConvention) {
  Translation ned{Convention::kNed, {}};
  StatesAsInputs states({RecordedRobot{"WING", ned, Translation{}}});
  sandbox_msgs::robot_state_t state = NorthboundState();
  std::vector<LogEvent> feed;
  EXPECT_EQ(states.Translate("WING/STATE", Encoded(state), &feed), "");
  ASSERT_EQ(feed.size(), 2u);
  EXPECT_EQ(feed[0].channel, "WING/BONES");
  const auto bones = Decode<sandbox_msgs::bone_values_t>(feed[0]);
  EXPECT_EQ(bones.values, (std::vector<double>{0.25, -0.5}));
  EXPECT_EQ(bones.utime, 5'000'000);
  EXPECT_EQ(feed[1].channel, "WING/POSE");
  const auto pose = Decode<sandbox_msgs::robot_pose_t>(feed[1]);
  EXPECT_EQ(pose.utime, 5'000'000);
  EXPECT_EQ(pose.seq, 7);
  // NED: north, east, down; heading north is yaw 0, the identity attitude.
  EXPECT_NEAR(pose.position[0], 20, 1e-12);
  EXPECT_NEAR(pose.position[1], 10, 1e-12);
  EXPECT_NEAR(pose.position[2], -30, 1e-12);
  EXPECT_NEAR(std::abs(pose.orientation[0]), 1, 1e-12);
  EXPECT_EQ(states.states_replayed(), 1);
  EXPECT_EQ(states.robots_from_states(), std::vector<std::string>{"WING"});
}

TEST(StatesAsInputsTest, AStateAlreadyInThePoseConventionIsTakenAsItIs) {
  Translation ned{Convention::kNed, {}};
  StatesAsInputs states({RecordedRobot{"WING", ned, ned}});
  sandbox_msgs::robot_state_t state = NorthboundState();
  state.num_values = 0;
  state.bone_values.clear();
  std::vector<LogEvent> feed;
  EXPECT_EQ(states.Translate("WING/STATE", Encoded(state), &feed), "");
  ASSERT_EQ(feed.size(), 1u);  // no bone values: no BONES
  const auto pose = Decode<sandbox_msgs::robot_pose_t>(feed[0]);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(pose.position[k], state.position[k], 1e-12);
  for (int k = 0; k < 4; ++k) EXPECT_NEAR(pose.orientation[k], state.orientation[k], 1e-12);
}

// A log with a robot's POSE before its STATE (lcm-logger on a live network)
// replays that robot's own inputs; other events pass unchanged.
TEST(StatesAsInputsTest, ARobotWhosePoseComesFirstKeepsItsOwnInputs) {
  StatesAsInputs states({RecordedRobot{"A", {}, {}}, RecordedRobot{"B", {}, {}}});
  sandbox_msgs::robot_state_t state = NorthboundState();
  const std::vector<std::uint8_t> bytes = Encoded(state);
  std::vector<LogEvent> feed;
  states.Translate("A/POSE", {1, 2, 3}, &feed);
  states.Translate("A/STATE", bytes, &feed);
  states.Translate("B/STATE", bytes, &feed);
  states.Translate("B/POSE", {4, 5}, &feed);
  states.Translate("OTHER/STATE", bytes, &feed);
  ASSERT_EQ(feed.size(), 6u);
  EXPECT_EQ(feed[0].channel, "A/POSE");
  EXPECT_EQ(feed[0].data, (std::vector<std::uint8_t>{1, 2, 3}));
  EXPECT_EQ(feed[1].channel, "A/STATE");
  EXPECT_EQ(feed[1].data, bytes);
  EXPECT_EQ(feed[2].channel, "B/BONES");
  EXPECT_EQ(feed[3].channel, "B/POSE");
  EXPECT_EQ(feed[4].channel, "B/POSE");
  EXPECT_EQ(feed[4].data, (std::vector<std::uint8_t>{4, 5}));
  EXPECT_EQ(feed[5].channel, "OTHER/STATE");
  EXPECT_EQ(states.robots_from_states(), std::vector<std::string>{"B"});
  EXPECT_EQ(states.TakeNewRobotsFromStates(), std::vector<std::string>{"B"});
  EXPECT_TRUE(states.TakeNewRobotsFromStates().empty());  // said once
}

TEST(StatesAsInputsTest, AStateThatDoesNotDecodeIsSkippedWithItsReason) {
  StatesAsInputs states({RecordedRobot{"WING", {}, {}}});
  sandbox_msgs::robot_state_t state = NorthboundState();
  std::vector<std::uint8_t> bytes = Encoded(state);
  bytes.resize(bytes.size() - 3);
  std::vector<LogEvent> feed;
  EXPECT_NE(states.Translate("WING/STATE", bytes, &feed).find("robot_state_t"), std::string::npos);
  state.orientation[0] = std::nan("");
  EXPECT_EQ(states.Translate("WING/STATE", Encoded(state), &feed),
            "its orientation is not a unit quaternion");
  EXPECT_TRUE(feed.empty());
  EXPECT_EQ(states.states_refused(), 2);
  EXPECT_EQ(states.states_replayed(), 0);
}

}  // namespace
