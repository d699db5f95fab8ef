#pragma once
// What the browser view's server and the Foxglove server share: websocketpp
// over standalone Asio (Debian's libasio-dev, C++11's standard library for
// its threads and functions), bound and listening as their options say.

#include <chrono>
#include <string>
#include <vector>

#define ASIO_STANDALONE
#define _WEBSOCKETPP_CPP11_STL_
#include <websocketpp/config/asio_no_tls.hpp>
#include <websocketpp/server.hpp>

#include "web/stream_server.h"

namespace sandbox::web {

using Server = websocketpp::server<websocketpp::config::asio>;
using Handle = websocketpp::connection_hdl;
namespace http_status = websocketpp::http::status_code;

// Quiet logs, the message size limit, then bound to options' address and port
// and accepting; returns the port. Throws ServerError naming `option`
// (--web, --foxglove) and the address when it cannot.
int Listen(Server& server, const ServerOptions& options, const std::string& option);

// A client's backlog: how long its unsent bytes have been over the limit.
struct Backlog {
  // Whether the client, with `buffered` bytes unsent, is sent more now; when
  // not, *drop says it has been behind longer than options.slow_timeout_s.
  bool Admit(std::size_t buffered, const ServerOptions& options,
             std::chrono::steady_clock::time_point now, bool* drop);
  bool behind{false};
  std::chrono::steady_clock::time_point since;
};

// Closes the connections of clients that stayed behind; returns how many.
std::int64_t DropSlow(Server& server, const std::vector<Handle>& slow);

// "SCHEME://ADDRESS:PORT/" as a client on this machine reaches it (127.0.0.1
// or ::1 when bound to every address; IPv6 in brackets).
std::string ServerUrl(const std::string& scheme, const std::string& address, int port);

}  // namespace sandbox::web
