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

#include "bridge/foxglove_views.h"
#include "web/foxglove_server.h"

namespace sandbox::app {

class FoxgloveFeed {
 public:
  explicit FoxgloveFeed(web::FoxgloveServer& server) : server_(server) {}

  // The loop's thread: a message it published at `utime`.
  void Published(const std::string& channel, const void* data, unsigned size, std::int64_t utime);
  // Any thread: a view no LCM message carries (a link frame, a camera
  // image) on `topic`, made on the server's thread if a client wants it.
  void PublishView(const std::string& topic, bridge::MakeView make, std::int64_t utime);
  bool HasClients() const { return server_.HasClients(); }
  // The loop's thread: a view every client gets when it subscribes, also
  // later (the scene), made on the server's thread when first wanted. A
  // topic latched again replaces its message.
  void Latch(const std::string& topic, const std::string& schema_name, const std::string& schema,
             bridge::MakeView make, std::int64_t utime);

 private:
  // The server's thread.
  void Convert(const std::string& channel, const std::string& bytes, std::int64_t utime);
  void Send(const bridge::FoxgloveView& view, std::int64_t utime, std::vector<std::uint32_t>* ids);

  web::FoxgloveServer& server_;
  std::map<std::string, std::vector<std::uint32_t>> views_;  // LCM channel -> its views' ids
  std::map<std::string, std::uint32_t> ids_;                 // view topic -> id
  std::map<std::string, std::uint32_t> latched_ids_;  // the loop's thread: latched topic -> id
};

}  // namespace sandbox::app
