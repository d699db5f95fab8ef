// Fuzz target: level files through the level loader (assimp for scene files;
// our own readers for heightmap images and Terragen terrains). The bytes are
// written to a file in memory-backed /dev/shm (else the temporary folder)
// with the extension of one format, chosen by the first byte among
// SANDBOX_FUZZ_FORMATS (a comma list, e.g. "obj,ply"; default: all of kFormats). Every input loads
// or gives one LevelError. A crash inside assimp stops this process: such formats are listed in
// docs/explanation/reliability.md, and `sandbox --isolate` contains them.

#include <unistd.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "scene/asset_import.h"
#include "scene/heightmap.h"
#include "tests/fuzz/fuzz_file.h"

namespace {

const char* kFormats[] = {"obj", "ply", "stl", "off", "gltf", "glb", "dae", "fbx",
                          "3ds", "x",   "3mf", "pk3", "ter",  "png", "pgm"};

std::vector<std::string>& Formats() {
  static std::vector<std::string> formats;
  return formats;
}

}  // namespace

extern "C" int LLVMFuzzerInitialize(int*, char***) {
  const char* chosen = std::getenv("SANDBOX_FUZZ_FORMATS");
  std::stringstream list(chosen != nullptr ? chosen : "");
  for (std::string format; std::getline(list, format, ',');) {
    if (!format.empty()) Formats().push_back(format);
  }
  if (Formats().empty()) Formats().assign(std::begin(kFormats), std::end(kFormats));
  return 0;
}

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string& format = Formats()[data[0] % Formats().size()];
  const std::string file = sandbox::fuzz::WriteInputFile(data + 1, size - 1, format);
  sandbox::scene::LoadLimits limits;
  limits.max_heightmap_samples = 1u << 20;  // fuzzing needs fast executions, not big grids
  limits.max_texture_pixels = 1u << 20;
  limits.max_triangles = 1u << 20;
  try {
    if (format == "png" || format == "pgm") {
      sandbox::scene::ImportHeightmapImage(file, {100, 100, 10}, limits);
    } else {
      sandbox::scene::ImportAsset(file, {}, limits);
    }
  } catch (const sandbox::scene::LevelError&) {
  }
  unlink(file.c_str());
  return 0;
}
