#pragma once
// The sensors a level's robots declare ([[robot.sensor]] tables), read into
// the sensors' own configs, and where each one is at a robot state.

#include <Eigen/Geometry>
#include <string>
#include <variant>
#include <vector>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "sensors/cameras.h"
#include "sensors/face_scanner.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/range_sensor.h"

namespace sandbox::sensors {

using SensorConfig =
    std::variant<FaceScannerConfig, GroundScannerConfig, LidarConfig, RangeSensorConfig>;

struct MountedSensor {
  scene::SensorSpec spec;  // name, type, mount, X_MS, rate
  int robot{-1};           // index into Level::robots
  SensorConfig config;

  // X_WS: the robot's pose, the mount node's pose and the mounting offset.
  Eigen::Isometry3d Pose(const scene::RobotState& state) const;
};

// A camera declared by a [[robot.camera]] table.
struct MountedCamera {
  scene::SensorSpec spec;  // name, type (chase, trailing, payload, fixed), mount, X_MS, rate
  int robot{-1};
  CameraView view;  // size, field of view, clipping; the pose is set per frame
  ChaseConfig chase;
  double trailing_distance_m{25.0};
  double trailing_height_m{8.0};
  bool depth{false};           // payload cameras: also a depth image
  bool overlay{false};         // the debug overlay (scanner samples, bone frames, actor bounds)
  double overlay_stub_m{0.0};  // scanner samples as points (0) or stubs this long

  // The camera pose for a robot state (fixed cameras: their own pose; chase
  // cameras keep their lag in `chase_state`, advanced by dt_s).
  Eigen::Isometry3d Pose(const scene::RobotState& state, ChaseCamera* chase_state,
                         const TrailingCommand& command, double dt_s) const;
};

// Every robot's cameras; throws scene::LevelError naming the manifest, line,
// camera and setting (zero or huge resolution, an unknown key, ...).
std::vector<MountedCamera> MakeRobotCameras(const scene::Level& level);

// Every robot's sensors. Throws scene::LevelError naming the manifest, the line,
// the sensor and the setting: an unknown key, a wrong type, a value its config
// rejects (zero or negative resolution, more than 10 million rays, ...).
std::vector<MountedSensor> MakeRobotSensors(const scene::Level& level);

}  // namespace sandbox::sensors
