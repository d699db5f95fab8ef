#pragma once
// What the browser view is sent each time it is sent anything: the tick, the
// loop's timing, each robot's pose and status, and the movable actors'
// placements. Taken by the loop between ticks (copies of a few poses), encoded
// as JSON (nlohmann-json) on the stream's thread. The fields are listed in
// docs/reference/web.md.

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

namespace sandbox::web {

struct StreamState {
  struct Body {
    std::string name;
    Eigen::Vector3d p_W{Eigen::Vector3d::Zero()};
    Eigen::Quaterniond q_W{Eigen::Quaterniond::Identity()};
  };
  struct Robot : Body {
    bool has_pose{false};            // a pose has arrived
    std::int64_t received{0};        // inputs received so far (all its channels)
    std::int64_t rejected{0};        // inputs refused so far
    std::vector<std::string> stale;  // its input channels gone quiet
    std::vector<double> bone_values;  // flat, in bone-map order (RobotState::bone_values)
    // Per skin joint k (RobotModel::joints): its node's pose in the body
    // frame, the 3 x 4 matrix row by row (12 values a joint; sent to 1e-5).
    std::vector<double> joints;
  };
  std::int64_t tick{0};
  double time_s{0.0};   // since the run started (lock-step: the inputs' time)
  double tick_ms{0.0};  // the last tick's duration
  double late_ms{0.0};  // how late it started
  std::vector<Robot> robots;
  std::vector<Body> actors;  // the movable actors
  // A recorded run (`sandbox view`): whether its playhead moves, and how fast.
  bool has_player{false};
  bool playing{false};
  double speed{1.0};

  // A sensor's latest samples, positions relative to `samples_origin`.
  struct Samples {
    std::string robot, sensor, type;  // type: the [[robot.sensor]] type ("face", "lidar", ...)
    std::vector<float> xyz;           // 3 a sample, world axes
    std::vector<std::uint8_t> hit;    // 1: it hit something (occupied); 0: the ray's free end
    std::vector<std::int32_t> surface;  // its surface id (0: nothing)
  };
  bool has_samples{false};  // samples are sent with this state (at most a few a second)
  std::int64_t samples_tick{0};  // the tick they were taken at
  Eigen::Vector3d samples_origin{Eigen::Vector3d::Zero()};
  std::vector<Samples> samples;
};

// The state's text message (JSON).
std::string EncodeState(const StreamState& state);
// Its samples' binary message ("" without samples): "SMPL", a little-endian
// uint32 header length, the JSON header (padded with spaces to 4 bytes:
// tick, origin, and per sensor robot, sensor, type and count n), then per
// sensor in the header's order n * 3 float32 positions, n int32 surface ids
// and n uint8 hits (padded with zeros to 4 bytes). docs/reference/web.md.
std::string EncodeSamples(const StreamState& state);

}  // namespace sandbox::web
