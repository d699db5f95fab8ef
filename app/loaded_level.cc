#include "app/loaded_level.h"

#include "app/isolated_load.h"

namespace sandbox::app {

LoadedLevel LoadCheckedLevel(const std::string& file, const scene::AssetConversion& conversion,
                             bool isolate) {
  if (isolate) CheckLoadsInIsolation(file, conversion);
  scene::LoadOptions options;
  options.conversion = conversion;
  return LoadCheckedLevel(file, options);
}

LoadedLevel LoadCheckedLevel(const std::string& file, const scene::LoadOptions& options) {
  LoadedLevel loaded;
  loaded.level = scene::LoadLevel(file, options);
  loaded.sensors = sensors::MakeRobotSensors(loaded.level);
  loaded.cameras = sensors::MakeRobotCameras(loaded.level);
  loaded.bridges = bridge::RobotBridgeConfigs(loaded.level);
  return loaded;
}

}  // namespace sandbox::app
