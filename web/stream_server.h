#pragma once
// The browser view's server (`sandbox run --web`): one HTTP and WebSocket
// port, on a thread of its own (websocketpp over standalone Asio). It serves
// the page (web/page), three.js from Debian's libjs-three, and at /stream a
// WebSocket that sends each client the level's model once (a binary glTF) and
// then the newest state (JSON text, and scan samples as binary), at most `max_rate_hz` a second, at the
// client's own pace: a client whose unsent bytes pass `max_queued_bytes`
// skips states (counted) and is dropped when it stays behind for
// `slow_timeout_s`. The loop hands states over with Publish, which never
// waits on a client: the newest replaces one not yet sent, and the server's
// thread encodes it. Read-only: what a client sends is counted and dropped,
// unless `on_text` takes it (`sandbox view`'s player commands).
//
// Safe by default: bound to 127.0.0.1 unless an address is given; a
// WebSocket's Origin, when the client sends one (browsers do), must be the
// page's own (http:// and the request's Host); at most `max_clients` at once;
// a client's message over `max_message_bytes`, a bad request or a bad frame
// closes its connection, counted by reason (docs/reference/web.md).

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <memory>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>

namespace sandbox::web {

struct ServerOptions {
  std::string address{"127.0.0.1"};
  int port{0};  // 0: a free port (port() says which)
  int max_clients{8};
  std::size_t max_message_bytes{64 * 1024};  // a client's message
  std::size_t max_queued_bytes{4 << 20};     // a client's unsent bytes before states are skipped
  double slow_timeout_s{10.0};               // behind that long: dropped
  double max_rate_hz{60.0};                  // states a second to a client
  std::filesystem::path page_dir;            // the page's files (web/page)
  std::filesystem::path three_dir{"/usr/share/javascript/three"};  // libjs-three
  // What is done with a client's text message (on the server's thread);
  // empty: nothing (read-only; counted as dropped). It returns "" when the
  // message is taken, else why not (counted as refused).
  std::function<std::string(const std::string&)> on_text;
};

// What the server has done, by reason (any thread).
struct ServerCounts {
  std::int64_t clients{0};           // connected now
  std::int64_t connections{0};       // WebSockets opened
  std::int64_t http_requests{0};     // plain HTTP requests answered (files)
  std::int64_t not_found{0};         // requests for no file (404)
  std::int64_t refused_origin{0};    // a WebSocket from another origin (403)
  std::int64_t refused_full{0};      // a WebSocket over max_clients (503)
  std::int64_t failed{0};            // handshakes that failed (bad HTTP, bad upgrade)
  std::int64_t messages_dropped{0};  // messages from clients (read-only)
  std::int64_t commands{0};          // messages on_text took (player, camera commands)
  std::int64_t commands_refused{0};  // messages on_text refused
  std::int64_t closed_oversized{0};  // closed for a message over max_message_bytes
  std::int64_t closed_protocol{0};   // closed for a bad frame
  std::int64_t dropped_slow{0};      // closed for staying behind
  std::int64_t states_published{0};  // Publish calls
  std::int64_t states_sent{0};       // states sent, all clients
  std::int64_t states_skipped{0};    // states a client was too far behind for
  std::int64_t camera_frames{0};     // camera frames sent, all clients
  std::int64_t bytes_sent{0};
};

class ServerError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A state as sent: a text message, and a binary one after it when not empty
// (the scan samples, docs/reference/web.md).
struct EncodedState {
  EncodedState(std::string text_message = {}, std::string binary_message = {})
      : text(std::move(text_message)), binary(std::move(binary_message)) {}
  std::string text;
  std::string binary;
};

// A camera's latest frame as the page shows it: in its frustum, at the pose
// it was rendered from.
struct CameraFrame {
  std::string camera;
  std::int64_t tick{0};
  Eigen::Isometry3d X_WC{Eigen::Isometry3d::Identity()};  // x forward, y left, z up
  double fov_y_rad{1.0};
  int width{0}, height{0};
  std::string jpeg;  // the image file's bytes
};
// Its binary message: "CAMF", a little-endian uint32 header length, the
// JSON header (camera, tick, p, q (w, x, y, z), fov_y_deg, width, height;
// padded with spaces to 4 bytes), then the JPEG. docs/reference/web.md.
std::string EncodeCameraFrame(const CameraFrame& frame);

class StreamServer {
 public:
  // Encodes a state for the wire (on the server's thread).
  using Encoder = std::function<EncodedState()>;

  // Binds and starts serving. Throws ServerError naming the address when it
  // cannot (in use, not an address of this machine, no page folder).
  explicit StreamServer(const ServerOptions& options);
  ~StreamServer();
  StreamServer(const StreamServer&) = delete;
  StreamServer& operator=(const StreamServer&) = delete;

  int port() const { return port_; }
  // "http://ADDRESS:PORT/", the page's address (127.0.0.1 when bound to all).
  std::string url() const;

  // Any thread: what every client is sent first (those connected now and
  // each that connects later): the level's description (JSON text) and its
  // model (binary glTF).
  void SetLevel(std::string info_json, std::string glb);
  // Any thread, never waits on a client: the newest state, as a function that
  // encodes it (it owns what it encodes); replaces one not yet encoded.
  void Publish(Encoder encode);
  // Any thread, never waits on a client: a camera's newest frame, sent once
  // to each client (one that is behind gets the newest when it catches up).
  void SetCameraFrame(const CameraFrame& frame);
  // Any thread: whether a state would be sent (a client is connected and
  // the last state published has been taken): the loop builds one only then,
  // so a state is at most one send period old and costs nothing without clients.
  bool WantsState() const;

  ServerCounts counts() const;

 private:
  class Impl;
  std::unique_ptr<Impl> impl_;
  int port_{0};
  std::string address_;
};

}  // namespace sandbox::web
