#include "bridge/recorded_states.h"

#include "bridge/checked_decode.h"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"

namespace sandbox::bridge {
namespace {

template <typename Message>
LogEvent Encoded(const std::string& channel, Message& message) {
  LogEvent event{channel, std::vector<std::uint8_t>(std::size_t(message.getEncodedSize()))};
  message.encode(event.data.data(), 0, int(event.data.size()));
  return event;
}

}  // namespace

std::vector<RecordedRobot> RecordedRobots(const std::vector<RobotBridgeConfig>& bridges) {
  std::vector<RecordedRobot> robots;
  for (const RobotBridgeConfig& config : bridges) {
    robots.push_back({config.channel_prefix, config.pose,
                      config.state_in_pose_convention ? config.pose : Translation{}});
  }
  return robots;
}

StatesAsInputs::StatesAsInputs(std::vector<RecordedRobot> robots) {
  for (RecordedRobot& robot : robots) {
    by_pose_[robot.channel_prefix + "/POSE"] = robots_.size();
    by_state_[robot.channel_prefix + "/STATE"] = robots_.size();
    robots_.push_back(Robot{std::move(robot)});
  }
}

std::string StatesAsInputs::Translate(const std::string& channel,
                                      const std::vector<std::uint8_t>& data,
                                      std::vector<LogEvent>* feed) {
  if (const auto pose = by_pose_.find(channel); pose != by_pose_.end()) {
    Robot& robot = robots_[pose->second];
    if (robot.source == Source::kUnknown) robot.source = Source::kInputs;
  }
  const auto state = by_state_.find(channel);
  if (state == by_state_.end()) {
    feed->push_back(LogEvent{channel, data});
    return "";
  }
  Robot& robot = robots_[state->second];
  if (robot.source == Source::kUnknown) {
    robot.source = Source::kStates;
    newly_.push_back(robot.config.channel_prefix);
  }
  if (robot.source == Source::kInputs) {
    feed->push_back(LogEvent{channel, data});
    return "";
  }
  sandbox_msgs::robot_state_t message;
  if (std::string why = DecodeChecked(data.data(), data.size(), &message); !why.empty()) {
    ++refused_;
    return why;
  }
  const Eigen::Quaterniond q_state(message.orientation[0], message.orientation[1],
                                   message.orientation[2], message.orientation[3]);
  if (!(q_state.norm() > 0.5 && q_state.norm() < 2.0)) {  // also NaN
    ++refused_;
    return "its orientation is not a unit quaternion";
  }
  const Eigen::Isometry3d X_WB = robot.config.state.ToWorld(
      Eigen::Vector3d(message.position[0], message.position[1], message.position[2]),
      q_state.normalized());
  Eigen::Vector3d p;
  Eigen::Quaterniond q;
  robot.config.pose.FromWorld(X_WB, &p, &q);
  if (message.num_values > 0) {
    sandbox_msgs::bone_values_t bones{};
    bones.utime = message.utime;
    bones.seq = message.seq;
    bones.num_values = message.num_values;
    bones.values = message.bone_values;
    feed->push_back(Encoded(robot.config.channel_prefix + "/BONES", bones));
  }
  sandbox_msgs::robot_pose_t pose{};
  pose.utime = message.utime;
  pose.seq = message.seq;
  for (int k = 0; k < 3; ++k) pose.position[k] = p[k];
  pose.orientation[0] = q.w(), pose.orientation[1] = q.x();
  pose.orientation[2] = q.y(), pose.orientation[3] = q.z();
  feed->push_back(Encoded(robot.config.channel_prefix + "/POSE", pose));
  ++replayed_;
  return "";
}

std::vector<std::string> StatesAsInputs::robots_from_states() const {
  std::vector<std::string> prefixes;
  for (const Robot& robot : robots_) {
    if (robot.source == Source::kStates) prefixes.push_back(robot.config.channel_prefix);
  }
  return prefixes;
}

}  // namespace sandbox::bridge
