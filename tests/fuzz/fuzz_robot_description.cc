// Fuzz target: robot descriptions through the level loader (urdfdom for
// URDF, sdformat for SDF, then the robot model: shapes, joints, limits). The
// first byte picks the format; the rest is written to a file in /dev/shm
// (else the temporary folder) with its extension. Every input loads or gives
// one LevelError. Mesh URIs in an input may name files; the loader reads only
// regular files, and the mesh formats assimp reads safely are the level
// formats' business (fuzz_level_file).

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

#include "scene/level.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const char* format = data[0] % 2 == 0 ? "urdf" : "sdf";
  static const std::string folder = std::filesystem::is_directory("/dev/shm")
                                        ? "/dev/shm"
                                        : std::filesystem::temp_directory_path().string();
  const std::string file = folder + "/sandbox-fuzz-" + std::to_string(getpid()) + "." + format;
  {
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    out.write(reinterpret_cast<const char*>(data + 1), std::streamsize(size - 1));
  }
  try {
    sandbox::scene::LoadLevel(file);
  } catch (const sandbox::scene::LevelError&) {
  }
  return 0;
}
