#pragma once
// What the sandbox publishes for a robot: <ROBOT>/SCAN_FACE, /GROUND, /LIDAR, /RANGE,
// /STATE and /STATUS, each numbered on its own channel (seq 0, 1, 2, ...) and
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
#include "sensors/face_scanner.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/range_sensor.h"

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

// The channel (after "<ROBOT>/") a sensor publishes on: its `channel`, or
// SCAN_FACE, GROUND, LIDAR, RANGE by type.
std::string OutputChannel(const scene::SensorSpec& spec);

// Throws scene::LevelError when two sensors of one robot would publish on one
// channel (range sensors may share: their messages carry the sensor's name).
void CheckOutputChannels(const scene::Level& level);

class RobotOutputs {
 public:
  // Publishes on <channel_prefix>/...; STATE's pose in `state_translation`'s
  // convention (the world's own, ENU, by default).
  RobotOutputs(LcmLink& link, std::string channel_prefix,
               const Translation& state_translation = {});

  // Publishes the faces of `scan` scanned at `tick` (the ones this tick
  // refreshed). `channel`: after the prefix; empty: SCAN_FACE (GROUND, LIDAR).
  void PublishFaces(const sensors::FaceScan& scan, std::int64_t tick, const InputTag& input,
                    std::int64_t now_utime, const std::string& channel = "");
  void PublishGround(const sensors::HeightMap& map, const InputTag& input, std::int64_t now_utime,
                     const std::string& channel = "");
  void PublishLidar(const sensors::LidarScan& scan, const InputTag& input, std::int64_t now_utime,
                    const std::string& channel = "");
  // One single-ray sensor's reading; `sensor` tells several on one robot apart.
  void PublishRange(const std::string& sensor, const sensors::RangeReading& reading,
                    const InputTag& input, std::int64_t now_utime, const std::string& channel = "");
  // Face f's frame in the world: the scanner box it was last scanned in
  // (sensors::ScanFace::X_WB).
  using FaceFrames = std::array<Eigen::Isometry3d, 6>;
  // The robot pose and bones in use, and the face frames `X_WF` in the robot
  // frame at that pose (null: no face scanner; the robot frame itself).
  void PublishState(const scene::RobotState& state, const InputTag& input, std::int64_t now_utime,
                    const FaceFrames* X_WF = nullptr);
  void PublishStatus(double loop_rate_hz, std::int64_t ticks, std::int64_t overruns,
                     const std::vector<ChannelStatus>& channels, std::int64_t now_utime);

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
