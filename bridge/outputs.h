#pragma once
// What the sandbox publishes for a robot: <ROBOT>/SCAN_FACE, /GROUND, /LIDAR, /RANGE,
// /STATE, /STATUS and /WORLD, each numbered on its own channel (seq 0, 1, 2, ...) and
// tagged with the sequence number and time of the pose input it was computed
// from. Threads: the loop thread.

#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/translation.h"
#include "scene/robot_state.h"
#include "scene/surface_ids.h"
#include "sensors/face_scanner.h"
#include "sensors/sensor.h"

namespace sandbox::bridge {

// The input an output was computed from.
struct InputTag {
  std::int64_t seq{-1};
  std::int64_t utime{-1};
};

// One input channel's counters, for the status heartbeat.
struct ChannelStatus {
  std::string channel;
  std::int64_t received{0}, superseded{0}, rejected{0};
  bool stale{false};
  std::string last_reject_reason;
};

// Throws scene::LevelError when two sensors of one robot would publish on one
// channel (sensors::OutputChannel; range sensors may share: their messages
// carry the sensor's name).
void CheckOutputChannels(const scene::Level& level);

class RobotOutputs {
 public:
  // Publishes on <channel_prefix>/...; STATE's pose in `state_translation`'s
  // convention (the world's own, ENU, by default).
  RobotOutputs(LcmLink& link, std::string channel_prefix,
               const Translation& state_translation = {});

  // Where an output goes: on <prefix>/<channel>, from sensor `sensor` (range
  // readings carry it). References: nothing is copied per tick.
  struct Address {
    const std::string& sensor;
    const std::string& channel;  // sensors::MountedSensor::channel
  };
  // Any sensor's output, each kind by its publish function in outputs.cc
  // (a face scan: the faces scanned at `tick`, one message each).
  void Publish(const sensors::SensorOutput& output, const Address& to, std::int64_t tick,
               const InputTag& input, std::int64_t now_utime);
  using FaceFrames = sensors::FaceFrames;
  // The robot pose and bones in use, and the face frames `X_WF` in the robot
  // frame at that pose (null: no face scanner; the robot frame itself).
  void PublishState(const scene::RobotState& state, const InputTag& input, std::int64_t now_utime,
                    const FaceFrames* X_WF = nullptr);
  void PublishStatus(double loop_rate_hz, std::int64_t ticks, std::int64_t overruns,
                     const std::vector<ChannelStatus>& channels, std::int64_t now_utime);
  // The world's surface table (scene::CollisionWorld::SurfaceTable()) on
  // <prefix>/WORLD: what the samples' surface ids name.
  void PublishSurfaces(const std::vector<scene::SurfaceEntry>& table, std::uint64_t revision,
                       std::int64_t now_utime);

  const std::string& prefix() const { return prefix_; }
  std::int64_t published() const { return published_; }

 private:
  // Numbers `message` on its channel and publishes it.
  template <typename Message>
  void Send(const std::string& topic, Message& message);

  LcmLink& link_;
  std::string prefix_;
  Translation state_translation_;
  std::map<std::string, std::int64_t> next_seq_;  // per channel
  std::int64_t published_{0};
  std::vector<std::uint8_t> buffer_;
};

}  // namespace sandbox::bridge
