// Fuzz target: robot descriptions through the level loader (urdfdom for
// URDF, sdformat for SDF, then the robot model: shapes, joints, limits). The
// first byte picks the format; the rest is written to a file with its
// extension (fuzz_file.h). Every input loads or gives one LevelError. Mesh
// URIs in an input may name files; the loader reads only regular files, and
// the mesh formats assimp reads safely are the level formats' business
// (fuzz_level_file).

#include <cstdint>
#include <string>

#include "scene/level.h"
#include "tests/fuzz/fuzz_file.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const char* format = data[0] % 2 == 0 ? "urdf" : "sdf";
  const std::string file = sandbox::fuzz::WriteInputFile(data + 1, size - 1, format);
  try {
    sandbox::scene::LoadLevel(file);
  } catch (const sandbox::scene::LevelError&) {
  }
  return 0;
}
