#pragma once
// The loop's published messages to the live Foxglove server (--foxglove):
// poses, face scans and lidar sweeps as Foxglove's schemas
// (bridge/foxglove_views.h), each channel advertised when its first message
// comes. The loop's thread only copies a message that has a view while a
// client is connected; the conversion runs on the server's thread, and only
// for a channel not yet advertised or one a client subscribes to.

#include <cstdint>
#include <map>
#include <string>
#include <vector>

#include "web/foxglove_server.h"

namespace sandbox::app {

class FoxgloveFeed {
 public:
  explicit FoxgloveFeed(web::FoxgloveServer& server) : server_(server) {}

  // The loop's thread: a message it published at `utime`.
  void Published(const std::string& channel, const void* data, unsigned size, std::int64_t utime);

 private:
  // The server's thread.
  void Convert(const std::string& channel, const std::string& bytes, std::int64_t utime);

  web::FoxgloveServer& server_;
  std::map<std::string, std::vector<std::uint32_t>> views_;  // LCM channel -> its views' ids
  std::map<std::string, std::uint32_t> ids_;                 // view topic -> id
};

}  // namespace sandbox::app
