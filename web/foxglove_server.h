#pragma once
// A live Foxglove WebSocket protocol server (`sandbox run --foxglove`,
// foxglove.websocket.v1): Foxglove or Lichtblick connects to ws://ADDR:PORT/
// and subscribes to the channels the server advertises; each message goes to
// a channel's subscribers as MessageData (opcode 1, subscription id, time in
// ns, payload). On a thread of its own (websocketpp over standalone Asio, as
// the browser view's server), with the browser view's rules: 127.0.0.1
// unless an address is given, the Host must name this machine, an Origin
// (browsers send one) must be the server's own address, at most
// `max_clients`, a client's message over `max_message_bytes` closes it, a
// client with more than `max_queued_bytes` unsent skips messages (counted)
// and is dropped when it stays behind `slow_timeout_s`. Clients may
// subscribe and unsubscribe; anything else they send is answered with a
// status message and counted (no client publishing, parameters or services).

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>

#include "web/stream_server.h"

namespace sandbox::web {

struct FoxgloveChannel {
  std::string topic;
  std::string encoding;         // "json"
  std::string schema_name;      // "foxglove.PointCloud"
  std::string schema_encoding;  // "jsonschema"
  std::string schema;
};

// A channel's last message, sent to each client as it subscribes (the
// scene: written once, needed by every client that comes later), made on
// the server's thread when first needed.
struct LatchedMessage {
  std::uint64_t time_ns{0};
  std::function<std::string()> make;
  std::string payload;  // made
  bool made{false};
};

struct FoxgloveCounts {
  std::int64_t clients{0};           // connected now
  std::int64_t connections{0};       // WebSockets opened
  std::int64_t refused_origin{0};    // another Host or Origin (403)
  std::int64_t refused_protocol{0};  // no foxglove.websocket.v1 subprotocol, or another path
  std::int64_t refused_full{0};      // over max_clients (503)
  std::int64_t channels{0};          // advertised
  std::int64_t subscriptions{0};     // taken
  std::int64_t requests_refused{0};  // client messages not understood or not offered
  std::int64_t closed_oversized{0};
  std::int64_t dropped_slow{0};
  std::int64_t messages_sent{0};     // all clients
  std::int64_t messages_skipped{0};  // a client was too far behind for
  std::int64_t bytes_sent{0};
};

class FoxgloveServer {
 public:
  // Binds and starts serving; throws ServerError naming the address when it
  // cannot. Uses `options`' address, port, limits (not the page's folders).
  explicit FoxgloveServer(const ServerOptions& options);
  ~FoxgloveServer();
  FoxgloveServer(const FoxgloveServer&) = delete;
  FoxgloveServer& operator=(const FoxgloveServer&) = delete;

  int port() const { return port_; }
  std::string url() const;  // "ws://ADDRESS:PORT/"

  // Any thread: runs `work` on the server's thread, in order (the caller's
  // conversions stay off its own thread). Nothing is queued without clients.
  void Defer(std::function<void()> work);
  // Any thread: adds a channel, advertised to every client now and later;
  // returns its id.
  std::uint32_t Advertise(const FoxgloveChannel& channel);
  // Any thread: whether a client subscribes to the channel.
  bool Subscribed(std::uint32_t channel) const;
  // The server's thread (in Defer's work): the message to the channel's
  // subscribers; one too far behind skips it.
  void Send(std::uint32_t channel, std::uint64_t time_ns, const std::string& payload);
  bool HasClients() const;
  // Any thread: the channel's message now and for every later subscriber,
  // made by `make` on the server's thread when a client first wants it.
  void Latch(std::uint32_t channel, std::uint64_t time_ns, std::function<std::string()> make);

  FoxgloveCounts counts() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
  int port_{0};
  std::string address_;
};

}  // namespace sandbox::web
