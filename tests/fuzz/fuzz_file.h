#pragma once
// For fuzz targets that feed a reader a file: the input's bytes written to
// this process's file of that extension in memory-backed /dev/shm (else the
// temporary folder), replaced on every call.

#include <unistd.h>

#include <cstdint>
#include <filesystem>
#include <fstream>
#include <string>

namespace sandbox::fuzz {

inline std::string WriteInputFile(const std::uint8_t* data, std::size_t size,
                                  const std::string& extension) {
  static const std::string folder = std::filesystem::is_directory("/dev/shm")
                                        ? "/dev/shm"
                                        : std::filesystem::temp_directory_path().string();
  const std::string file = folder + "/sandbox-fuzz-" + std::to_string(getpid()) + "." + extension;
  std::ofstream out(file, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), std::streamsize(size));
  return file;
}

}  // namespace sandbox::fuzz
