#include "bridge/robot_inputs.h"

#include <cmath>

#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

namespace sandbox::bridge {
namespace {

// Decodes `bytes` as Message; false when they are not exactly one.
template <typename Message>
bool Decode(const std::vector<std::uint8_t>& bytes, Message* message) {
  return message->decode(bytes.data(), 0, static_cast<int>(bytes.size())) ==
         static_cast<int>(bytes.size());
}

// The seq of an encoded input message: every input type starts with the
// 8-byte fingerprint, then utime and seq (big-endian int64); -1 when too short.
std::int64_t RawSeq(const std::vector<std::uint8_t>& bytes) {
  if (bytes.size() < 24) return -1;
  std::uint64_t seq = 0;
  for (int i = 16; i < 24; ++i) seq = (seq << 8) | bytes[std::size_t(i)];
  return static_cast<std::int64_t>(seq);
}

bool AllFinite(const double* values, std::size_t n) {
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(values[i])) return false;
  }
  return true;
}

}  // namespace

RobotInputs::RobotInputs(LcmLink& link, const scene::Level& level, int robot,
                         const RobotBridgeConfig& config)
    : level_(level),
      robot_(robot),
      translation_(config.pose),
      pose_(link, config.channel_prefix + "/POSE"),
      bones_(link, config.channel_prefix + "/BONES"),
      actors_(link, config.channel_prefix + "/ACTORS"),
      camera_(link, config.channel_prefix + "/CAMERA") {}

RobotInputs::RobotInputs(LcmLink& link, const scene::Level& level, int robot)
    : RobotInputs(link, level, robot,
                  RobotBridgeConfig::FromModel(level.robots.at(std::size_t(robot)))) {}

RobotInputs::Applied RobotInputs::Apply(scene::RobotState* state, scene::CollisionWorld* world) {
  Applied applied;
  if (const auto* bytes = pose_.TakeNewest()) ApplyPose(*bytes, state, &applied);
  if (const auto* bytes = bones_.TakeNewest()) ApplyBones(*bytes, state, &applied);
  if (const auto* bytes = actors_.TakeNewest()) ApplyActors(*bytes, world, &applied);
  if (const auto* bytes = camera_.TakeNewest()) ApplyCamera(*bytes, &applied);
  return applied;
}

void RobotInputs::set_lockstep(bool lockstep) {
  pose_.set_queue(lockstep), bones_.set_queue(lockstep), actors_.set_queue(lockstep);
}

RobotInputs::Applied RobotInputs::ApplyNext(scene::RobotState* state,
                                            scene::CollisionWorld* world) {
  Applied applied;
  const std::vector<std::uint8_t>* pose = pose_.Peek();
  if (pose == nullptr) return applied;
  const std::int64_t seq = RawSeq(*pose);
  // Bones and placements sent with (or before) this pose come first.
  for (const std::vector<std::uint8_t>* bytes = bones_.Peek();
       bytes != nullptr && RawSeq(*bytes) <= seq; bytes = bones_.Peek()) {
    ApplyBones(*bytes, state, &applied);
    bones_.Pop();
  }
  for (const std::vector<std::uint8_t>* bytes = actors_.Peek();
       bytes != nullptr && RawSeq(*bytes) <= seq; bytes = actors_.Peek()) {
    ApplyActors(*bytes, world, &applied);
    actors_.Pop();
  }
  ApplyPose(*pose, state, &applied);
  pose_.Pop();
  // Camera commands change no output: the newest wins, as in free running.
  if (const auto* bytes = camera_.TakeNewest()) ApplyCamera(*bytes, &applied);
  return applied;
}

void RobotInputs::ApplyPose(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                            Applied* applied) {
  sandbox_msgs::robot_pose_t message{};
  if (!Decode(bytes, &message)) return pose_.Reject("cannot decode as robot_pose_t");
  if (!AllFinite(message.position, 3) || !AllFinite(message.orientation, 4)) {
    return pose_.Reject("non-finite pose");
  }
  const Eigen::Quaterniond q(message.orientation[0], message.orientation[1], message.orientation[2],
                             message.orientation[3]);
  if (std::abs(q.norm() - 1.0) > 1e-3) return pose_.Reject("non-unit quaternion");
  if (!state->SetPose(translation_.ToWorld(
          Eigen::Vector3d(message.position[0], message.position[1], message.position[2]), q))) {
    return pose_.Reject(state->last_rejection());
  }
  pose_.Accept(pose_.last_receive_utime());
  applied->pose = true;
  applied->pose_seq = message.seq;
  applied->pose_utime = message.utime;
}

void RobotInputs::ApplyBones(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                             Applied* applied) {
  sandbox_msgs::bone_values_t message{};
  const int expected = state->model().num_values;
  if (!Decode(bytes, &message)) return bones_.Reject("cannot decode as bone_values_t");
  if (message.num_values != expected) {
    return bones_.Reject("expected " + std::to_string(expected) + " bone values, got " +
                         std::to_string(message.num_values));
  }
  if (!state->SetBones(message.values)) return bones_.Reject(state->last_rejection());
  bones_.Accept(bones_.last_receive_utime());
  applied->bones = true;
}

void RobotInputs::ApplyActors(const std::vector<std::uint8_t>& bytes, scene::CollisionWorld* world,
                              Applied* applied) {
  // All of a message or none.
  sandbox_msgs::actor_placements_t message{};
  std::string reason;
  std::vector<std::pair<int, Eigen::Isometry3d>> placements;
  if (!Decode(bytes, &message)) {
    reason = "cannot decode as actor_placements_t";
  } else if (message.num_positions != 3 * message.num_actors ||
             message.num_orientations != 4 * message.num_actors) {
    reason = "positions and orientations must hold 3 and 4 values per actor";
  }
  for (int i = 0; reason.empty() && i < message.num_actors; ++i) {
    const int actor = level_.FindActor(message.names[std::size_t(i)]);
    const double* p = &message.positions[std::size_t(3 * i)];
    const double* o = &message.orientations[std::size_t(4 * i)];
    if (actor < 0) {
      reason = "unknown actor '" + message.names[std::size_t(i)] + "'";
    } else if (!level_.actors[std::size_t(actor)].movable) {
      reason = "actor '" + message.names[std::size_t(i)] + "' is not movable";
    } else if (!AllFinite(p, 3) || !AllFinite(o, 4)) {
      reason = "non-finite placement";
    } else if (std::abs(Eigen::Quaterniond(o[0], o[1], o[2], o[3]).norm() - 1.0) > 1e-3) {
      reason = "non-unit quaternion";
    } else {
      placements.emplace_back(actor, Eigen::Translation3d(p[0], p[1], p[2]) *
                                         Eigen::Quaterniond(o[0], o[1], o[2], o[3]).normalized());
    }
  }
  if (!reason.empty()) return actors_.Reject(reason);
  for (const auto& [actor, X_WA] : placements) world->SetActorPose(actor, X_WA);
  actors_.Accept(actors_.last_receive_utime());
  applied->actors = true;
}

void RobotInputs::ApplyCamera(const std::vector<std::uint8_t>& bytes, Applied* applied) {
  sandbox_msgs::camera_command_t message{};
  if (!Decode(bytes, &message)) return camera_.Reject("cannot decode as camera_command_t");
  if (!std::isfinite(message.pan_rad) || !std::isfinite(message.tilt_rad)) {
    return camera_.Reject("non-finite pan or tilt");
  }
  if (!(message.zoom > 0.0 && message.zoom <= 100.0)) {
    return camera_.Reject("zoom must be in (0, 100], got " + std::to_string(message.zoom));
  }
  if (!message.active_camera.empty()) {
    bool known = false;
    for (const scene::SensorSpec& camera : level_.robots.at(std::size_t(robot_)).cameras) {
      known = known || camera.name == message.active_camera;
    }
    if (!known) return camera_.Reject("unknown camera '" + message.active_camera + "'");
    active_camera_ = message.active_camera;
  }
  trailing_ = {message.pan_rad, message.tilt_rad, message.zoom};
  camera_.Accept(camera_.last_receive_utime());
  applied->camera = true;
}

}  // namespace sandbox::bridge
