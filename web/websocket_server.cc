#include "web/websocket_server.h"

namespace sandbox::web {

int Listen(Server& server, const ServerOptions& options, const std::string& option) {
  server.clear_access_channels(websocketpp::log::alevel::all);
  server.clear_error_channels(websocketpp::log::elevel::all);
  server.init_asio();
  server.set_reuse_addr(true);
  server.set_max_message_size(options.max_message_bytes);
  server.set_max_http_body_size(options.max_message_bytes);
  asio::error_code ec;
  const asio::ip::address address = asio::ip::make_address(options.address, ec);
  if (ec) throw ServerError(option + ": '" + options.address + "' is no IP address");
  if (options.port < 0 || options.port > 65535) {
    throw ServerError(option + ": port " + std::to_string(options.port) + " is out of 0-65535");
  }
  server.listen(asio::ip::tcp::endpoint(address, std::uint16_t(options.port)), ec);
  if (ec) {
    throw ServerError(option + ": cannot listen on " + options.address + ":" +
                      std::to_string(options.port) + ": " + ec.message());
  }
  server.start_accept(ec);
  if (ec) throw ServerError(option + ": cannot accept on " + options.address + ": " + ec.message());
  return server.get_local_endpoint(ec).port();
}

bool Backlog::Admit(std::size_t buffered, const ServerOptions& options,
                    std::chrono::steady_clock::time_point now, bool* drop) {
  *drop = false;
  if (buffered <= options.max_queued_bytes) {
    behind = false;
    return true;
  }
  if (!behind) behind = true, since = now;
  *drop = std::chrono::duration<double>(now - since).count() > options.slow_timeout_s;
  return false;
}

std::int64_t DropSlow(Server& server, const std::vector<Handle>& slow) {
  for (const Handle& handle : slow) {
    asio::error_code ec;
    server.close(handle, websocketpp::close::status::policy_violation, "too slow", ec);
  }
  return std::int64_t(slow.size());
}

std::string ServerUrl(const std::string& scheme, const std::string& address, int port) {
  // Bound to every address: this machine's own is one of them.
  std::string host = address == "0.0.0.0" ? "127.0.0.1" : address == "::" ? "::1" : address;
  if (host.find(':') != std::string::npos) host = "[" + host + "]";
  return scheme + "://" + host + ":" + std::to_string(port) + "/";
}

}  // namespace sandbox::web
