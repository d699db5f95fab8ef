#include "web/stream_server.h"

#include <chrono>
#include <fstream>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>
#include <vector>

#include "web/request_rules.h"
#include "web/websocket_server.h"

namespace sandbox::web {
namespace {

using Clock = std::chrono::steady_clock;

}  // namespace

class StreamServer::Impl {
 public:
  explicit Impl(const ServerOptions& options) : options_(options) {
    if (!std::filesystem::is_regular_file(options.page_dir / "index.html")) {
      throw ServerError("--web: no page at " + (options.page_dir / "index.html").string());
    }
    server_.set_validate_handler([this](Handle h) { return Validate(h); });
    server_.set_http_handler([this](Handle h) { ServeFile(h); });
    server_.set_open_handler([this](Handle h) {
      clients_.emplace(h, Client{});
      ++counts_.connections;
      counts_.clients = std::int64_t(clients_.size());
    });
    server_.set_close_handler([this](Handle h) { Closed(h); });
    server_.set_fail_handler([this](Handle h) {
      const auto code = server_.get_con_from_hdl(h)->get_response_code();
      if (code != http_status::forbidden && code != http_status::service_unavailable &&
          code != http_status::not_found) {
        ++counts_.failed;
      }
    });
    server_.set_message_handler([this](Handle, Server::message_ptr message) {
      if (!options_.on_text || message->get_opcode() != websocketpp::frame::opcode::text) {
        ++counts_.messages_dropped;
      } else if (options_.on_text(message->get_payload()).empty()) {
        ++counts_.commands;
      } else {
        ++counts_.commands_refused;
      }
    });

    port_ = Listen(server_, options, "--web");
    timer_ = std::make_unique<asio::steady_timer>(server_.get_io_service());
    ArmTimer();
    thread_ = std::thread([this] { server_.run(); });
  }

  ~Impl() {
    asio::post(server_.get_io_service(), [this] {
      asio::error_code ec;
      server_.stop_listening(ec);
      timer_->cancel();
      for (auto& [handle, client] : clients_) {
        server_.close(handle, websocketpp::close::status::going_away, "the sandbox stops", ec);
      }
      if (clients_.empty()) {
        server_.stop();
        return;
      }
      // Whatever has not closed in half a second is cut.
      timer_->expires_after(std::chrono::milliseconds(500));
      timer_->async_wait([this](const asio::error_code&) { server_.stop(); });
    });
    thread_.join();
  }

  int port() const { return port_; }

  void SetLevel(std::string info_json, std::string glb) {
    std::lock_guard<std::mutex> lock(mutex_);
    level_info_ = std::make_shared<const std::string>(std::move(info_json));
    level_ = std::make_shared<const std::string>(std::move(glb));
  }

  void Publish(Encoder encode) {
    std::lock_guard<std::mutex> lock(mutex_);
    pending_ = std::move(encode);
    state_pending_ = true;
    ++counts_.states_published;
  }

  void SetCameraFrame(const CameraFrame& frame) {
    auto encoded = std::make_shared<const std::string>(EncodeCameraFrame(frame));
    std::lock_guard<std::mutex> lock(mutex_);
    CameraSlot& slot = cameras_[frame.camera];
    slot.message = std::move(encoded);
    ++slot.sequence;
  }

  bool WantsState() const { return counts_.clients > 0 && !state_pending_; }

  ServerCounts counts() const {
    ServerCounts c;
    c.clients = counts_.clients;
    c.connections = counts_.connections;
    c.http_requests = counts_.http_requests;
    c.not_found = counts_.not_found;
    c.refused_origin = counts_.refused_origin;
    c.refused_full = counts_.refused_full;
    c.failed = counts_.failed;
    c.messages_dropped = counts_.messages_dropped;
    c.commands = counts_.commands;
    c.commands_refused = counts_.commands_refused;
    c.closed_oversized = counts_.closed_oversized;
    c.closed_protocol = counts_.closed_protocol;
    c.dropped_slow = counts_.dropped_slow;
    c.states_published = counts_.states_published;
    c.states_sent = counts_.states_sent;
    c.states_skipped = counts_.states_skipped;
    c.camera_frames = counts_.camera_frames;
    c.bytes_sent = counts_.bytes_sent;
    return c;
  }

 private:
  // A camera's newest frame, encoded, and how many it has had.
  struct CameraSlot {
    std::shared_ptr<const std::string> message;
    std::int64_t sequence{0};
  };
  struct Client {
    std::map<std::string, std::int64_t> camera_sequence;  // the last frame sent of each
    bool level_sent{false};
    Backlog backlog;
  };
  // ServerCounts, as atomics (written on the server's thread, read anywhere).
  struct Counts {
    std::atomic<std::int64_t> clients{0}, connections{0}, http_requests{0}, not_found{0},
        refused_origin{0}, refused_full{0}, failed{0}, messages_dropped{0}, commands{0},
        commands_refused{0}, closed_oversized{0}, camera_frames{0}, closed_protocol{0},
        dropped_slow{0}, states_published{0}, states_sent{0}, states_skipped{0}, bytes_sent{0};
  };

  bool Validate(Handle h) {
    const Server::connection_ptr con = server_.get_con_from_hdl(h);
    if (con->get_resource() != "/stream") {
      ++counts_.not_found;
      con->set_status(http_status::not_found);
      return false;
    }
    const std::string host = con->get_request_header("Host");
    const std::string origin = con->get_origin();
    if (!HostAllowed(host) || !OriginAllowed(origin, host)) {
      ++counts_.refused_origin;
      con->set_status(http_status::forbidden);
      return false;
    }
    if (clients_.size() >= std::size_t(options_.max_clients)) {
      ++counts_.refused_full;
      con->set_status(http_status::service_unavailable);
      return false;
    }
    return true;
  }

  void ServeFile(Handle h) {
    const Server::connection_ptr con = server_.get_con_from_hdl(h);
    if (!HostAllowed(con->get_request_header("Host"))) {
      ++counts_.refused_origin;
      con->set_status(http_status::forbidden);
      return;
    }
    const std::filesystem::path file =
        RequestedFile(con->get_resource(), options_.page_dir, options_.three_dir);
    std::ifstream in(file, std::ios::binary);
    if (file.empty() || !std::filesystem::is_regular_file(file) || !in) {
      ++counts_.not_found;
      con->set_status(http_status::not_found);
      con->set_body("not found\n");
      return;
    }
    std::ostringstream body;
    body << in.rdbuf();
    ++counts_.http_requests;
    con->set_status(http_status::ok);
    con->replace_header("Content-Type", ContentType(file));
    con->replace_header("Cache-Control", "no-cache");
    con->set_body(body.str());
  }

  void Closed(Handle h) {
    const Server::connection_ptr con = server_.get_con_from_hdl(h);
    const auto code = con->get_local_close_code();
    if (code == websocketpp::close::status::message_too_big) ++counts_.closed_oversized;
    if (code == websocketpp::close::status::protocol_error ||
        code == websocketpp::close::status::invalid_payload) {
      ++counts_.closed_protocol;
    }
    clients_.erase(h);
    counts_.clients = std::int64_t(clients_.size());
  }

  void ArmTimer() {
    const auto period = std::chrono::duration<double>(1.0 / std::max(1.0, options_.max_rate_hz));
    timer_->expires_after(std::chrono::duration_cast<Clock::duration>(period));
    timer_->async_wait([this](const asio::error_code& ec) {
      if (ec) return;  // cancelled: the server stops
      SendToClients();
      ArmTimer();
    });
  }

  // The level to those that have not had it, then the newest state to each
  // that keeps up.
  void SendToClients() {
    Encoder encode;
    std::shared_ptr<const std::string> level, level_info;
    std::map<std::string, CameraSlot> cameras;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      encode = std::move(pending_);
      pending_ = nullptr;
      state_pending_ = false;
      level = level_;
      level_info = level_info_;
      cameras = cameras_;
    }
    if (clients_.empty()) return;
    const EncodedState state = encode ? encode() : EncodedState();
    const Clock::time_point now = Clock::now();
    std::vector<Handle> slow;
    for (auto& [handle, client] : clients_) {
      asio::error_code ec;
      const Server::connection_ptr con = server_.get_con_from_hdl(handle, ec);
      if (ec) continue;
      if (!client.level_sent && level) {
        con->send(*level_info, websocketpp::frame::opcode::text);
        con->send(level->data(), level->size(), websocketpp::frame::opcode::binary);
        counts_.bytes_sent += std::int64_t(level_info->size() + level->size());
        client.level_sent = true;
      }
      if (con->get_buffered_amount() <= options_.max_queued_bytes) {
        for (const auto& [camera, slot] : cameras) {
          std::int64_t& sent = client.camera_sequence[camera];
          if (sent == slot.sequence || !slot.message) continue;
          sent = slot.sequence;
          con->send(slot.message->data(), slot.message->size(), websocketpp::frame::opcode::binary);
          ++counts_.camera_frames;
          counts_.bytes_sent += std::int64_t(slot.message->size());
        }
      }
      if (state.text.empty()) continue;
      if (bool drop = false;
          !client.backlog.Admit(con->get_buffered_amount(), options_, now, &drop)) {
        ++counts_.states_skipped;
        if (drop) slow.push_back(handle);
        continue;
      }
      con->send(state.text, websocketpp::frame::opcode::text);
      if (!state.binary.empty()) {
        con->send(state.binary.data(), state.binary.size(), websocketpp::frame::opcode::binary);
      }
      ++counts_.states_sent;
      counts_.bytes_sent += std::int64_t(state.text.size() + state.binary.size());
    }
    counts_.dropped_slow += DropSlow(server_, slow);
  }

  const ServerOptions options_;
  Server server_;
  std::unique_ptr<asio::steady_timer> timer_;
  std::thread thread_;
  int port_{0};
  std::map<Handle, Client, std::owner_less<Handle>> clients_;  // server thread only
  mutable std::mutex mutex_;
  Encoder pending_;
  std::atomic<bool> state_pending_{false};
  std::shared_ptr<const std::string> level_, level_info_;
  std::map<std::string, CameraSlot> cameras_;
  Counts counts_;
};

StreamServer::StreamServer(const ServerOptions& options)
    : impl_(std::make_unique<Impl>(options)), port_(impl_->port()), address_(options.address) {}
StreamServer::~StreamServer() = default;

std::string StreamServer::url() const { return ServerUrl("http", address_, port_); }
void StreamServer::SetCameraFrame(const CameraFrame& frame) { impl_->SetCameraFrame(frame); }

std::string EncodeCameraFrame(const CameraFrame& frame) {
  const Eigen::Vector3d p = frame.X_WC.translation();
  const Eigen::Quaterniond q(frame.X_WC.linear());
  std::string header = nlohmann::json({{"camera", frame.camera},
                                       {"tick", frame.tick},
                                       {"p", {p.x(), p.y(), p.z()}},
                                       {"q", {q.w(), q.x(), q.y(), q.z()}},
                                       {"fov_y_deg", frame.fov_y_rad * 180.0 / M_PI},
                                       {"width", frame.width},
                                       {"height", frame.height}})
                           .dump();
  header.append((4 - header.size() % 4) % 4, ' ');
  std::string out = "CAMF";
  const std::uint32_t length = std::uint32_t(header.size());
  out.append(reinterpret_cast<const char*>(&length), 4);  // little-endian (x86, ARM)
  out += header;
  out += frame.jpeg;
  return out;
}

void StreamServer::SetLevel(std::string info_json, std::string glb) {
  impl_->SetLevel(std::move(info_json), std::move(glb));
}
void StreamServer::Publish(Encoder encode) { impl_->Publish(std::move(encode)); }
bool StreamServer::WantsState() const { return impl_->WantsState(); }
ServerCounts StreamServer::counts() const { return impl_->counts(); }

}  // namespace sandbox::web
