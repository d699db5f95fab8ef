// Prints the keys each kind of manifest table accepts, as the parsers ask
// for them (scene::SetKeyListener) while the given levels load and their
// robots' sensors, cameras and bridges are read: "TABLE<TAB>key" lines,
// sorted. manifest_doc_test.sh compares them with docs/reference/manifest.md.
//
//   manifest_keys LEVEL.toml ...

#include <cstdio>
#include <map>
#include <set>
#include <string>

#include "bridge/robot_bridge_config.h"
#include "scene/level.h"
#include "scene/settings.h"
#include "sensors/render/mounted_camera.h"
#include "sensors/sensor.h"

int main(int argc, char** argv) {
  using namespace sandbox;
  std::map<std::string, std::set<std::string>> keys;
  scene::SetKeyListener([&](const std::string& table, const std::set<std::string>& asked) {
    keys[table].insert(asked.begin(), asked.end());
  });
  try {
    for (int i = 1; i < argc; ++i) {
      const scene::Level level = scene::LoadLevel(argv[i]);
      sensors::MakeRobotSensors(level);
      render::MakeRobotCameras(level);
      bridge::RobotBridgeConfigs(level);
    }
  } catch (const std::exception& e) {
    std::fprintf(stderr, "manifest_keys: %s\n", e.what());
    return 1;
  }
  for (const auto& [table, names] : keys) {
    for (const std::string& key : names) std::printf("%s\t%s\n", table.c_str(), key.c_str());
  }
  return 0;
}
