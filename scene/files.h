#pragma once
// Checks before a file is opened. Anything not a regular file is refused:
// opening a FIFO blocks until a writer comes, /dev/zero never ends, and a
// folder reads as nothing.

#include <cstdint>
#include <filesystem>
#include <string>

#include "scene/load_limits.h"

namespace sandbox::scene {

// Why `file` cannot be read as a regular file ("no such file", "is a FIFO,
// not a regular file", ...), or "" when it can. Follows symbolic links.
std::string RegularFileProblem(const std::filesystem::path& file);

// The size of a regular file in bytes (0 when it cannot be told).
std::uint64_t FileBytes(const std::filesystem::path& file);

// The file's extension in lower case, with its dot: ".glb".
std::string LowerExtension(const std::filesystem::path& file);

// Before a level's file is opened: throws LevelError naming it when it is
// missing, not a regular file, empty, unreadable or over limits.max_file_mb.
void CheckReadable(const std::filesystem::path& file, const LoadLimits& limits);

}  // namespace sandbox::scene
