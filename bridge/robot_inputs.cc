#include "bridge/robot_inputs.h"

#include <cmath>

#include "bridge/checked_decode.h"
#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/joint_values_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"

namespace sandbox::bridge {
namespace {

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

// The budget of a bone_values_t message for `n` values: its size, with room
// for a wrong count to be rejected as one rather than as an oversized message.
std::size_t BonesBudget(int n) { return 8 + 8 + 8 + 4 + 8 * std::size_t(n) + 65536; }

}  // namespace

RobotInputs::RobotInputs(LcmLink& link, const scene::Level& level, int robot,
                         const RobotBridgeConfig& config)
    : level_(level),
      robot_(robot),
      translation_(config.pose),
      pose_(
          link, config.channel_prefix + "/POSE",
          [this](const std::uint8_t* data, std::size_t size) {
            Pose pose;
            return ParsePose(data, size, &pose);
          },
          sandbox_msgs::robot_pose_t{}.getEncodedSize()),
      bones_(
          link, config.channel_prefix + "/BONES",
          [this](const std::uint8_t* data, std::size_t size) {
            std::vector<double> values;
            return ParseBones(data, size, &values);
          },
          BonesBudget(level.robots.at(std::size_t(robot)).num_values)),
      joints_(
          link, config.channel_prefix + "/JOINTS",
          [this](const std::uint8_t* data, std::size_t size) {
            std::vector<std::pair<int, double>> values;
            return ParseJoints(data, size, &values);
          },
          kMaxJointsBytes),
      actors_(
          link, config.channel_prefix + "/ACTORS",
          [this](const std::uint8_t* data, std::size_t size) {
            Placements placements;
            return ParsePlacements(data, size, &placements);
          },
          kMaxActorsBytes),
      camera_(
          link, config.channel_prefix + "/CAMERA",
          [this](const std::uint8_t* data, std::size_t size) {
            Camera camera;
            return ParseCamera(data, size, &camera);
          },
          kMaxCameraBytes) {}

RobotInputs::RobotInputs(LcmLink& link, const scene::Level& level, int robot)
    : RobotInputs(link, level, robot,
                  RobotBridgeConfig::FromModel(level.robots.at(std::size_t(robot)))) {}

std::string RobotInputs::ParsePose(const std::uint8_t* data, std::size_t size, Pose* pose) const {
  sandbox_msgs::robot_pose_t message{};
  if (std::string problem = DecodeChecked(data, size, &message); !problem.empty()) return problem;
  if (!AllFinite(message.position, 3) || !AllFinite(message.orientation, 4)) {
    return "non-finite pose";
  }
  const Eigen::Quaterniond q(message.orientation[0], message.orientation[1], message.orientation[2],
                             message.orientation[3]);
  if (std::abs(q.norm() - 1.0) > 1e-3) return "non-unit quaternion";
  const Eigen::Vector3d position(message.position[0], message.position[1], message.position[2]);
  if (std::string problem = PositionProblem(translation_, position); !problem.empty())
    return problem;
  pose->X_WB = translation_.ToWorld(position, q);
  pose->seq = message.seq;
  pose->utime = message.utime;
  return scene::PoseProblem(pose->X_WB);
}

std::string RobotInputs::ParseBones(const std::uint8_t* data, std::size_t size,
                                    std::vector<double>* values) const {
  const scene::RobotModel& model = level_.robots[std::size_t(robot_)];
  sandbox_msgs::bone_values_t message{};
  if (std::string problem = DecodeChecked(data, size, &message); !problem.empty()) return problem;
  if (message.num_values != model.num_values) {
    return "expected " + std::to_string(model.num_values) + " bone values, got " +
           std::to_string(message.num_values);
  }
  for (const scene::Bone& bone : model.bones) {
    const std::string problem = scene::BoneValuesProblem(
        bone, &message.values[std::size_t(bone.first_value)], bone.num_values);
    if (!problem.empty()) return problem;
  }
  *values = std::move(message.values);
  return "";
}

std::string RobotInputs::ParseJoints(const std::uint8_t* data, std::size_t size,
                                     std::vector<std::pair<int, double>>* values) const {
  const scene::RobotModel& model = level_.robots[std::size_t(robot_)];
  sandbox_msgs::joint_values_t message{};
  if (std::string problem = DecodeChecked(data, size, &message); !problem.empty()) return problem;
  std::vector<int> bones;
  if (message.num_names > 0) {
    if (message.num_values != message.num_names) {
      return std::to_string(message.num_names) + " names but " +
             std::to_string(message.num_values) + " values";
    }
    for (const std::string& name : message.names) {
      const int bone = model.FindBone(name);
      if (bone < 0) return "unknown joint '" + Printable(name, 64) + "'";
      bones.push_back(bone);
    }
  } else {
    if (message.num_values != int(model.bones.size())) {
      return "expected " + std::to_string(model.bones.size()) + " joint values, got " +
             std::to_string(message.num_values);
    }
    for (std::size_t b = 0; b < model.bones.size(); ++b) bones.push_back(int(b));
  }
  for (std::size_t i = 0; i < bones.size(); ++i) {
    const scene::Bone& bone = model.bones[std::size_t(bones[i])];
    if (bone.num_values != 1) {
      return "'" + bone.name + "' takes " + std::to_string(bone.num_values) +
             " values: not a joint (use BONES)";
    }
    const std::string problem = scene::BoneValuesProblem(bone, &message.values[i], 1);
    if (!problem.empty()) return problem + " ('" + bone.name + "')";
    values->emplace_back(bones[i], message.values[i]);
  }
  return "";
}

std::string RobotInputs::ParsePlacements(const std::uint8_t* data, std::size_t size,
                                         Placements* placements) const {
  // All of a message or none.
  sandbox_msgs::actor_placements_t message{};
  if (std::string problem = DecodeChecked(data, size, &message); !problem.empty()) return problem;
  if (message.num_positions != 3 * std::int64_t(message.num_actors) ||
      message.num_orientations != 4 * std::int64_t(message.num_actors)) {
    return "positions and orientations must hold 3 and 4 values per actor";
  }
  for (int i = 0; i < message.num_actors; ++i) {
    const std::string& name = message.names[std::size_t(i)];
    const int actor = level_.FindActor(name);
    const double* p = &message.positions[std::size_t(3 * i)];
    const double* o = &message.orientations[std::size_t(4 * i)];
    if (actor < 0) return "unknown actor '" + Printable(name, 64) + "'";
    if (!level_.actors[std::size_t(actor)].movable) {
      return "actor '" + Printable(name, 64) + "' is not movable";
    }
    if (!AllFinite(p, 3) || !AllFinite(o, 4)) return "non-finite placement";
    const Eigen::Quaterniond q(o[0], o[1], o[2], o[3]);
    if (std::abs(q.norm() - 1.0) > 1e-3) return "non-unit quaternion";
    placements->X_WA.emplace_back(actor, Eigen::Translation3d(p[0], p[1], p[2]) * q.normalized());
  }
  return "";
}

std::string RobotInputs::ParseCamera(const std::uint8_t* data, std::size_t size,
                                     Camera* camera) const {
  sandbox_msgs::camera_command_t message{};
  if (std::string problem = DecodeChecked(data, size, &message); !problem.empty()) return problem;
  if (!std::isfinite(message.pan_rad) || !std::isfinite(message.tilt_rad)) {
    return "non-finite pan or tilt";
  }
  if (!(message.zoom > 0.0 && message.zoom <= 100.0)) return "zoom must be in (0, 100]";
  if (!message.active_camera.empty()) {
    bool known = false;
    for (const scene::SensorSpec& spec : level_.robots.at(std::size_t(robot_)).cameras) {
      known = known || spec.name == message.active_camera;
    }
    if (!known) return "unknown camera '" + Printable(message.active_camera, 64) + "'";
  }
  camera->trailing = {message.pan_rad, message.tilt_rad, message.zoom};
  camera->active = message.active_camera;
  return "";
}

RobotInputs::Applied RobotInputs::Apply(scene::RobotState* state, scene::CollisionWorld* world) {
  Applied applied;
  if (const auto* bytes = pose_.TakeNewest()) ApplyPose(*bytes, state, &applied);
  if (const auto* bytes = bones_.TakeNewest()) ApplyBones(*bytes, state, &applied);
  if (const auto* bytes = joints_.TakeNewest()) ApplyJoints(*bytes, state, &applied);
  if (const auto* bytes = actors_.TakeNewest()) ApplyActors(*bytes, world, &applied);
  if (const auto* bytes = camera_.TakeNewest()) ApplyCamera(*bytes, &applied);
  return applied;
}

void RobotInputs::set_lockstep(bool lockstep) {
  pose_.set_queue(lockstep), bones_.set_queue(lockstep), joints_.set_queue(lockstep);
  actors_.set_queue(lockstep);
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
  for (const std::vector<std::uint8_t>* bytes = joints_.Peek();
       bytes != nullptr && RawSeq(*bytes) <= seq; bytes = joints_.Peek()) {
    ApplyJoints(*bytes, state, &applied);
    joints_.Pop();
  }
  for (const std::vector<std::uint8_t>* bytes = actors_.Peek();
       bytes != nullptr && RawSeq(*bytes) <= seq; bytes = actors_.Peek()) {
    ApplyActors(*bytes, world, &applied);
    actors_.Pop();
  }
  ApplyPose(*pose_.Peek(), state, &applied);
  pose_.Pop();
  // Camera commands change no output: the newest wins, as in free running.
  if (const auto* bytes = camera_.TakeNewest()) ApplyCamera(*bytes, &applied);
  return applied;
}

void RobotInputs::ApplyPose(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                            Applied* applied) {
  Pose pose;
  if (std::string problem = ParsePose(bytes.data(), bytes.size(), &pose); !problem.empty()) {
    return pose_.Reject(problem);
  }
  if (!state->SetPose(pose.X_WB)) return pose_.Reject(state->last_rejection());
  pose_.Accept();
  applied->pose = true;
  applied->pose_seq = pose.seq;
  applied->pose_utime = pose.utime;
}

void RobotInputs::ApplyBones(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                             Applied* applied) {
  std::vector<double> values;
  if (std::string problem = ParseBones(bytes.data(), bytes.size(), &values); !problem.empty()) {
    return bones_.Reject(problem);
  }
  if (!state->SetBones(values)) return bones_.Reject(state->last_rejection());
  bones_.Accept();
  applied->bones = true;
}

void RobotInputs::ApplyJoints(const std::vector<std::uint8_t>& bytes, scene::RobotState* state,
                              Applied* applied) {
  std::vector<std::pair<int, double>> values;
  if (std::string problem = ParseJoints(bytes.data(), bytes.size(), &values); !problem.empty()) {
    return joints_.Reject(problem);
  }
  // Checked above: every SetBone succeeds, so the message applies whole.
  for (const auto& [bone, value] : values) state->SetBone(bone, &value, 1);
  joints_.Accept();
  applied->bones = true;
}

void RobotInputs::ApplyActors(const std::vector<std::uint8_t>& bytes, scene::CollisionWorld* world,
                              Applied* applied) {
  Placements placements;
  if (std::string problem = ParsePlacements(bytes.data(), bytes.size(), &placements);
      !problem.empty()) {
    return actors_.Reject(problem);
  }
  for (const auto& [actor, X_WA] : placements.X_WA) world->SetActorPose(actor, X_WA);
  actors_.Accept();
  applied->actors = true;
}

void RobotInputs::ApplyCamera(const std::vector<std::uint8_t>& bytes, Applied* applied) {
  Camera camera;
  if (std::string problem = ParseCamera(bytes.data(), bytes.size(), &camera); !problem.empty()) {
    return camera_.Reject(problem);
  }
  if (!camera.active.empty()) active_camera_ = camera.active;
  trailing_ = camera.trailing;
  camera_.Accept();
  applied->camera = true;
}

}  // namespace sandbox::bridge
