#pragma once
// Everything that drives one robot from outside, applied in one call: its LCM
// inputs (<ROBOT>/POSE, /BONES, /JOINTS, /ACTORS, /CAMERA) and its UDP adapters (net_fdm,
// doubles). Apply() reports what changed and keeps the tag of the input the
// robot's outputs are computed from. Threads: the loop thread.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/outputs.h"
#include "bridge/reject_log.h"
#include "bridge/robot_bridge_config.h"
#include "bridge/robot_inputs.h"
#include "bridge/udp_inputs.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"

namespace sandbox::bridge {

class RobotFeed {
 public:
  // Subscribes robot `robot`'s channels on `link` and opens its UDP sockets;
  // rejections go to `log`. `level` and `log` must outlive this.
  RobotFeed(LcmLink& link, const scene::Level& level, int robot, const RobotBridgeConfig& config,
            bool lockstep, RejectLog* log);
  RobotFeed(const RobotFeed&) = delete;  // its subscriptions point at it
  RobotFeed& operator=(const RobotFeed&) = delete;

  // What one Apply() changed.
  struct Changes {
    int messages{0};    // inputs applied (LCM messages and UDP packets)
    bool moved{false};  // the pose or bones changed: the state and the world were updated
    bool pose{false};   // an LCM pose message was applied
    std::int64_t pose_utime{-1};
    // Input times that went back (a model restarting its clock), one line
    // each naming the channel and the jump; the first few per channel.
    std::vector<std::string> time_jumps;
  };
  // After LcmLink::Drain(): applies the newest good input of each kind (lock-step:
  // the next pose message and what belongs to it, then the UDP inputs) to
  // `state`, and actor placements and the robot's new shape to `world`.
  // `now_utime` tags UDP inputs that carry no time of their own.
  Changes Apply(std::int64_t now_utime, scene::RobotState* state, scene::CollisionWorld* world);

  // The input the robot's outputs are tagged with: the latest applied.
  const InputTag& input() const { return input_; }
  // Lock-step: a pose message is waiting.
  bool HasPose() const { return inputs_.HasPose(); }
  // The camera steering and choice from <ROBOT>/CAMERA.
  const TrailingCommand& trailing() const { return inputs_.trailing(); }
  const std::string& active_camera() const { return inputs_.active_camera(); }
  // Every input's counters: the LCM channels, then the UDP sockets.
  std::vector<ChannelStatus> Channels(std::int64_t now_utime) const;
  // Appends whether pose, joint values (BONES or JOINTS) and actors (in that
  // order) are stale at `now_utime`.
  void AppendStale(std::int64_t now_utime, std::vector<bool>* stale) const;
  const RobotBridgeConfig& config() const { return config_; }

 private:
  bool JointValuesStale(std::int64_t now_utime) const;

  RobotBridgeConfig config_;
  int robot_;
  bool lockstep_;
  RobotInputs inputs_;
  std::unique_ptr<NetFdmInput> net_fdm_;
  std::unique_ptr<DoublesInput> doubles_;
  InputTag input_;
  // The newest input time per channel (pose, net_fdm, doubles), and the jumps said.
  struct TimeWatch {
    bool seen{false};
    std::int64_t utime{0};
    int jumps{0};
  };
  TimeWatch pose_time_, net_fdm_time_, doubles_time_;
};

}  // namespace sandbox::bridge
