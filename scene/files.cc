#include "scene/files.h"

#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstring>

#include "scene/placement.h"

namespace sandbox::scene {

std::string RegularFileProblem(const std::filesystem::path& file) {
  struct stat info {};
  if (::stat(file.c_str(), &info) != 0) {
    return errno == ENOENT ? "no such file"
                           : std::string("cannot be read: ") + std::strerror(errno);
  }
  if (S_ISDIR(info.st_mode)) return "is a folder, not a file";
  if (S_ISFIFO(info.st_mode)) return "is a FIFO, not a regular file";
  if (S_ISSOCK(info.st_mode)) return "is a socket, not a regular file";
  if (S_ISCHR(info.st_mode) || S_ISBLK(info.st_mode)) return "is a device, not a regular file";
  if (!S_ISREG(info.st_mode)) return "is not a regular file";
  if (::access(file.c_str(), R_OK) != 0)
    return std::string("cannot be read: ") + std::strerror(errno);
  return "";
}

std::uint64_t FileBytes(const std::filesystem::path& file) {
  struct stat info {};
  if (::stat(file.c_str(), &info) != 0 || !S_ISREG(info.st_mode)) return 0;
  return std::uint64_t(info.st_size);
}

void CheckReadable(const std::filesystem::path& file, const LoadLimits& limits) {
  if (const std::string problem = RegularFileProblem(file); !problem.empty()) {
    throw LevelError(file.string() + ": " + problem);
  }
  if (FileBytes(file) == 0) throw LevelError(file.string() + ": file is empty");
  limits.CheckFileSize(file);
}

std::string LowerExtension(const std::filesystem::path& file) {
  std::string ext = file.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace sandbox::scene
