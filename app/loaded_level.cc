#include "app/loaded_level.h"

#include <cctype>
#include <filesystem>

#include "app/isolated_load.h"

namespace sandbox::app {

bool IsManifest(const std::string& file) {
  std::string extension = std::filesystem::path(file).extension().string();
  for (char& c : extension) c = char(std::tolower(static_cast<unsigned char>(c)));
  return extension == ".toml";
}

LoadedLevel LoadCheckedLevel(const std::string& file, const scene::AssetConversion& conversion,
                             Isolation isolation) {
  if (isolation == Isolation::kAlways ||
      (isolation == Isolation::kSceneFiles && !IsManifest(file))) {
    CheckLoadsInIsolation(file, conversion);
  }
  scene::LoadOptions options;
  options.conversion = conversion;
  return LoadCheckedLevel(file, options);
}

LoadedLevel LoadCheckedLevel(const std::string& file, const scene::LoadOptions& options) {
  LoadedLevel loaded;
  loaded.level = scene::LoadLevel(file, options);
  loaded.sensors = sensors::MakeRobotSensors(loaded.level);
  loaded.cameras = render::MakeRobotCameras(loaded.level);
  loaded.bridges = bridge::RobotBridgeConfigs(loaded.level);
  return loaded;
}

}  // namespace sandbox::app
