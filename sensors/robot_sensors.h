#pragma once
// The sensors a level's robots declare ([[robot.sensor]] tables), read into
// the sensors' own configs, and where each one is at a robot state.

#include <Eigen/Geometry>
#include <string>
#include <variant>
#include <vector>

#include "scene/level.h"
#include "scene/robot_state.h"
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

// Every robot's sensors. Throws scene::LevelError naming the manifest, the line,
// the sensor and the setting: an unknown key, a wrong type, a value its config
// rejects (zero or negative resolution, more than 10 million rays, ...).
std::vector<MountedSensor> MakeRobotSensors(const scene::Level& level);

}  // namespace sandbox::sensors
