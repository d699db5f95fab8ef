#pragma once
// A robot's inputs from external models: <ROBOT>/POSE (robot_pose_t),
// <ROBOT>/BONES (bone_values_t), <ROBOT>/JOINTS (joint_values_t: one-value
// bones by name), <ROBOT>/ACTORS (actor_placements_t) and <ROBOT>/CAMERA
// (camera_command_t), each the newest good message of its channel,
// translated and applied. Every message is decoded and checked when
// it arrives (its size against the channel's budget, its layout, finite
// values, unit quaternions, the bone count, known and movable actors): a bad
// one is rejected, counted by reason, and never displaces the last good one.

#include <cstdint>
#include <string>

#include "bridge/lcm_link.h"
#include "bridge/robot_bridge_config.h"
#include "bridge/translation.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/robot_state.h"

namespace sandbox::bridge {

// The trailing cameras' steering from <ROBOT>/CAMERA (render::TrailingCommand
// takes these values).
struct TrailingCommand {
  double pan_rad{0.0};   // about the robot's up axis, positive to the left
  double tilt_rad{0.0};  // positive: the camera rises and looks down more
  double zoom{1.0};      // > 0; 2 halves the field of view
};

class RobotInputs {
 public:
  // Byte budgets of the variable-size inputs (POSE and BONES have one exact size).
  static constexpr std::size_t kMaxActorsBytes = 1u << 20;
  static constexpr std::size_t kMaxCameraBytes = 4096;
  static constexpr std::size_t kMaxJointsBytes = 1u << 16;

  // Subscribes the robot's channels (<prefix>/POSE, /BONES, /JOINTS, /ACTORS, /CAMERA)
  // on `link`; the config also says the convention its pose publisher speaks.
  // `level` must outlive this.
  RobotInputs(LcmLink& link, const scene::Level& level, int robot, const RobotBridgeConfig& config);
  // With the robot's own [robot.bridge] settings.
  RobotInputs(LcmLink& link, const scene::Level& level, int robot);

  // What the last Apply() used.
  struct Applied {
    bool pose{false}, bones{false}, actors{false}, camera{false};  // bones: BONES or JOINTS
    std::int64_t pose_seq{-1}, pose_utime{-1};                     // of the pose message applied
  };
  // After LcmLink::Drain(): applies the newest good message of each channel to
  // the robot state and, for actor placements, to the world. The caller then
  // runs RobotState::Update() and CollisionWorld::UpdateRobot() when the pose
  // or bones changed.
  Applied Apply(scene::RobotState* state, scene::CollisionWorld* world);

  // Lock-step (for replays and deterministic runs): the inputs queue every
  // good message, and ApplyNext() consumes exactly the oldest pose message,
  // after the bone and placement messages whose seq is not above its seq.
  void set_lockstep(bool lockstep);
  bool HasPose() const { return pose_.queued() > 0; }
  Applied ApplyNext(scene::RobotState* state, scene::CollisionWorld* world);

  const LatestInput& pose() const { return pose_; }
  const LatestInput& bones() const { return bones_; }
  const LatestInput& joints() const { return joints_; }
  const LatestInput& actors() const { return actors_; }
  const LatestInput& camera() const { return camera_; }
  // The last good camera command: the trailing cameras' pan, tilt and zoom,
  // and the active camera (one of the robot's, by name; empty until chosen).
  const TrailingCommand& trailing() const { return trailing_; }
  const std::string& active_camera() const { return active_camera_; }
  // Logs rejections of every input to `log`.
  void set_log(RejectLog* log) {
    pose_.set_log(log), bones_.set_log(log), joints_.set_log(log), actors_.set_log(log);
    camera_.set_log(log);
  }

 private:
  // A message decoded and checked, ready to apply.
  struct Pose {
    Eigen::Isometry3d X_WB;
    std::int64_t seq{-1}, utime{-1};
  };
  struct Placements {
    std::vector<std::pair<int, Eigen::Isometry3d>> X_WA;  // actor index, pose
  };
  struct Camera {
    TrailingCommand trailing;
    std::string active;  // empty: keep the active camera
  };
  // Each returns "" with the value, or why the message is rejected.
  std::string ParsePose(const std::uint8_t* data, std::size_t size, Pose* pose) const;
  std::string ParseBones(const std::uint8_t* data, std::size_t size,
                         std::vector<double>* values) const;
  // The joints' bone indices and values.
  std::string ParseJoints(const std::uint8_t* data, std::size_t size,
                          std::vector<std::pair<int, double>>* values) const;
  std::string ParsePlacements(const std::uint8_t* data, std::size_t size,
                              Placements* placements) const;
  std::string ParseCamera(const std::uint8_t* data, std::size_t size, Camera* camera) const;

  void ApplyPose(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                 Applied* applied);
  void ApplyBones(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                  Applied* applied);
  void ApplyJoints(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                   Applied* applied);
  void ApplyActors(const std::vector<std::uint8_t>& bytes, scene::CollisionWorld* world,
                   Applied* applied);
  void ApplyCamera(const std::vector<std::uint8_t>& bytes, Applied* applied);

  const scene::Level& level_;
  int robot_;
  Translation translation_;
  LatestInput pose_, bones_, joints_, actors_, camera_;
  TrailingCommand trailing_;
  std::string active_camera_;
};

}  // namespace sandbox::bridge
