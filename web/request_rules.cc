#include "web/request_rules.h"

#include <arpa/inet.h>
#include <unistd.h>

#include <sstream>

namespace sandbox::web {
namespace {

// A path under a folder: letters, digits and . _ - / only, no empty, "." or
// ".." segment; empty when it is not one.
std::string SafeRelativePath(const std::string& path) {
  if (path.empty() || path.back() == '/') return {};
  for (const char c : path) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '.' || c == '_' || c == '-' || c == '/';
    if (!ok) return {};
  }
  std::stringstream segments(path);
  std::string segment;
  while (std::getline(segments, segment, '/')) {
    if (segment.empty() || segment == "." || segment == "..") return {};
  }
  return path;
}

bool IsIpAddress(const std::string& name) {
  unsigned char bytes[16];
  return inet_pton(AF_INET, name.c_str(), bytes) == 1 ||
         inet_pton(AF_INET6, name.c_str(), bytes) == 1;
}

}  // namespace

std::filesystem::path RequestedFile(const std::string& resource,
                                    const std::filesystem::path& page_dir,
                                    const std::filesystem::path& three_dir) {
  const std::string path = resource.substr(0, resource.find('?'));
  if (path == "/") return page_dir / "index.html";
  if (path.rfind("/three/", 0) == 0) {
    const std::string relative = SafeRelativePath(path.substr(7));
    return relative.empty() ? std::filesystem::path() : three_dir / relative;
  }
  if (path.size() < 2 || path[0] != '/') return {};
  const std::string relative = SafeRelativePath(path.substr(1));
  return relative.empty() ? std::filesystem::path() : page_dir / relative;
}

bool HostAllowed(const std::string& host) {
  if (host.empty()) return false;
  std::string name = host;
  if (name.front() == '[') {  // [IPv6]:port
    const auto end = name.find(']');
    if (end == std::string::npos) return false;
    name = name.substr(1, end - 1);
  } else if (const auto colon = name.rfind(':'); colon != std::string::npos) {
    name = name.substr(0, colon);
  }
  if (name == "localhost" || IsIpAddress(name)) return true;
  char own[256] = {};
  return gethostname(own, sizeof own - 1) == 0 && name == own;
}

bool OriginAllowed(const std::string& origin, const std::string& host) {
  return origin.empty() || origin == "http://" + host;
}

std::string ContentType(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".html") return "text/html; charset=utf-8";
  if (ext == ".js") return "text/javascript; charset=utf-8";
  if (ext == ".css") return "text/css; charset=utf-8";
  if (ext == ".json") return "application/json";
  if (ext == ".png") return "image/png";
  return "application/octet-stream";
}

}  // namespace sandbox::web
