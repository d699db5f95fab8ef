// Fuzz target: what a browser (or anything else) sends the browser view's
// server: an HTTP request, a WebSocket handshake and frames, parsed by
// websocketpp (as `sandbox run --web` does, here over its in-memory
// transport) with the server's own rules for files, hosts and origins
// (web/request_rules.h), its limits on message size and, for text messages,
// `sandbox view`'s player and --web-control's camera commands (web/commands.h).

#include <cstdint>
#include <sstream>
#include <string>
#include <websocketpp/config/core.hpp>
#include <websocketpp/server.hpp>

#include "web/commands.h"
#include "web/request_rules.h"

namespace {

using Server = websocketpp::server<websocketpp::config::core>;

Server& TheServer() {
  static Server* server = [] {
    auto* s = new Server;
    s->clear_access_channels(websocketpp::log::alevel::all);
    s->clear_error_channels(websocketpp::log::elevel::all);
    s->set_max_message_size(64 * 1024);
    s->set_max_http_body_size(64 * 1024);
    s->set_validate_handler([s](websocketpp::connection_hdl h) {
      const Server::connection_ptr con = s->get_con_from_hdl(h);
      const std::string host = con->get_request_header("Host");
      return con->get_resource() == "/stream" && sandbox::web::HostAllowed(host) &&
             sandbox::web::OriginAllowed(con->get_origin(), host);
    });
    s->set_http_handler([s](websocketpp::connection_hdl h) {
      const Server::connection_ptr con = s->get_con_from_hdl(h);
      const std::filesystem::path file = sandbox::web::RequestedFile(
          con->get_resource(), "/nonexistent/page", "/nonexistent/three");
      con->set_status(file.empty() ? websocketpp::http::status_code::not_found
                                   : websocketpp::http::status_code::ok);
      con->set_body(sandbox::web::ContentType(file));
    });
    // What `sandbox view` and `--web-control` do with a text message: a
    // player or a camera command.
    s->set_message_handler([](websocketpp::connection_hdl, Server::message_ptr message) {
      try {
        (void)sandbox::web::ParsePlayerCommand(message->get_payload());
      } catch (const std::invalid_argument&) {
      }
      try {
        (void)sandbox::web::ParseCameraCommand(message->get_payload());
      } catch (const std::invalid_argument&) {
      }
    });
    return s;
  }();
  return *server;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  Server& server = TheServer();
  std::stringstream output;
  server.register_ostream(&output);
  const Server::connection_ptr con = server.get_connection();
  con->start();
  // In two reads, as bytes come off a socket: the cut at the first byte's value.
  const std::size_t cut = size == 0 ? 0 : std::min<std::size_t>(size, data[0] * 4u);
  con->read_some(reinterpret_cast<const char*>(data), cut);
  con->read_some(reinterpret_cast<const char*>(data) + cut, size - cut);
  con->eof();
  return 0;
}
