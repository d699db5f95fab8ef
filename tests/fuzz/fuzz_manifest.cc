// Fuzz target: the level manifest parser (TOML text to a LevelManifest), and
// the same text as a command line's sensor settings (ParseSettingsText, one
// line of "key = value, ..."). Every input is either a manifest or one
// LevelError, and settings or one LevelError; nothing else may escape.

#include <cstddef>
#include <cstdint>
#include <string>
#include <string_view>

#include "scene/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    sandbox::scene::ParseManifestText(text, "/fuzz/level.toml");
  } catch (const sandbox::scene::LevelError&) {
  }
  try {
    sandbox::scene::ParseSettingsText(std::string(text), "--lidar", "lidar");
  } catch (const sandbox::scene::LevelError&) {
  }
  return 0;
}
