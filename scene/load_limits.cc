#include "scene/load_limits.h"

#include "scene/files.h"
#include "scene/placement.h"

namespace sandbox::scene {

void LoadLimits::Check(const std::filesystem::path& file, const std::string& what,
                       std::uint64_t amount, std::uint64_t limit, const char* key) {
  if (amount <= limit) return;
  throw LevelError(file.string() + ": " + what + ", over the limit of " + std::to_string(limit) +
                   " ([level] " + key + " in a level manifest)");
}

void LoadLimits::CheckFileSize(const std::filesystem::path& file) const {
  const std::uint64_t mb = (FileBytes(file) + (1u << 20) - 1) >> 20;
  Check(file, std::to_string(mb) + " MB", mb, max_file_mb, "max_file_mb");
}

}  // namespace sandbox::scene
