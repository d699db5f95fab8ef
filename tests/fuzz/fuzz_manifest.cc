// Fuzz target: the level manifest parser (TOML text to a LevelManifest).
// Every input is either a manifest or one LevelError; nothing else may escape.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "scene/manifest.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  try {
    sandbox::scene::ParseManifestText(text, "/fuzz/level.toml");
  } catch (const sandbox::scene::LevelError&) {
  }
  return 0;
}
