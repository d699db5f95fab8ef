#pragma once
// A level as every command loads it, checked as `sandbox run` needs it: its
// robots' sensors, cameras and bridge settings (ports, channel prefixes,
// output channels). A level that `info` accepts is one that `run` accepts.

#include <string>
#include <vector>

#include "bridge/robot_bridge_config.h"
#include "scene/level.h"
#include "sensors/render/mounted_camera.h"
#include "sensors/sensor.h"

namespace sandbox::app {

struct LoadedLevel {
  scene::Level level;
  std::vector<sensors::MountedSensor> sensors;
  std::vector<render::MountedCamera> cameras;
  std::vector<bridge::RobotBridgeConfig> bridges;  // one per robot, in Level::robots order
};

// Which levels are first loaded in a child process (isolated_load.h), where
// a crash inside assimp is an error rather than the end of the program.
enum class Isolation {
  kSceneFiles,  // a scene file given as the level (someone else's file), not a manifest
  kAlways,      // --isolate: a manifest's assets too
  kNever,       // already done by the caller
};

// True for a level manifest (.toml), false for a scene file.
bool IsManifest(const std::string& file);

// Loads `file` (a scene file read with `conversion`, or a manifest) and makes
// every check above, loading it apart first as `isolation` says. Throws
// scene::LevelError naming the file, the line and what is wrong.
LoadedLevel LoadCheckedLevel(const std::string& file, const scene::AssetConversion& conversion = {},
                             Isolation isolation = Isolation::kSceneFiles);
// In this process, with every load option (the isolated child's call).
LoadedLevel LoadCheckedLevel(const std::string& file, const scene::LoadOptions& options);

}  // namespace sandbox::app
