#pragma once
// A level as every command loads it, checked as `sandbox run` needs it: its
// robots' sensors, cameras and bridge settings (ports, channel prefixes,
// output channels). A level that `info` accepts is one that `run` accepts.

#include <string>
#include <vector>

#include "bridge/robot_bridge_config.h"
#include "scene/level.h"
#include "sensors/robot_sensors.h"

namespace sandbox::app {

struct LoadedLevel {
  scene::Level level;
  std::vector<sensors::MountedSensor> sensors;
  std::vector<sensors::MountedCamera> cameras;
  std::vector<bridge::RobotBridgeConfig> bridges;  // one per robot, in Level::robots order
};

// Loads `file` (a scene file read with `conversion`, or a manifest) and makes
// every check above. With `isolate`, first loads it in a child process
// (isolated_load.h): a crash inside assimp is then an error, not the end.
// Throws scene::LevelError naming the file, the line and what is wrong.
LoadedLevel LoadCheckedLevel(const std::string& file, const scene::AssetConversion& conversion = {},
                             bool isolate = false);
// In this process, with every load option (the isolated child's call).
LoadedLevel LoadCheckedLevel(const std::string& file, const scene::LoadOptions& options);

}  // namespace sandbox::app
