#include "web/foxglove_server.h"

#include <chrono>
#include <map>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>
#include <vector>

#include "web/foxglove_protocol.h"
#include "web/request_rules.h"
#include "web/websocket_server.h"

namespace sandbox::web {
namespace {

using Clock = std::chrono::steady_clock;

nlohmann::json ChannelJson(std::uint32_t id, const FoxgloveChannel& c) {
  return {{"id", id},
          {"topic", c.topic},
          {"encoding", c.encoding},
          {"schemaName", c.schema_name},
          {"schemaEncoding", c.schema_encoding},
          {"schema", c.schema}};
}

}  // namespace

class FoxgloveServer::Impl {
 public:
  explicit Impl(const ServerOptions& options)
      : options_(options), session_(std::to_string(Clock::now().time_since_epoch().count())) {
    server_.set_validate_handler([this](Handle h) { return Validate(h); });
    server_.set_http_handler([this](Handle h) {
      server_.get_con_from_hdl(h)->set_status(http_status::upgrade_required);
      ++counts_.refused_protocol;
    });
    server_.set_open_handler([this](Handle h) { Opened(h); });
    server_.set_close_handler([this](Handle h) { Closed(h); });
    server_.set_message_handler([this](Handle h, Server::message_ptr m) { Request(h, m); });
    port_ = Listen(server_, options, "--foxglove");
    thread_ = std::thread([this] { server_.run(); });
  }

  ~Impl() {
    asio::post(server_.get_io_service(), [this] {
      asio::error_code ec;
      server_.stop_listening(ec);
      for (auto& [handle, client] : clients_) {
        server_.close(handle, websocketpp::close::status::going_away, "the sandbox stops", ec);
      }
      if (clients_.empty()) return server_.stop();
      stop_timer_ = std::make_unique<asio::steady_timer>(server_.get_io_service());
      stop_timer_->expires_after(std::chrono::milliseconds(500));
      stop_timer_->async_wait([this](const asio::error_code&) { server_.stop(); });
    });
    thread_.join();
  }

  int port() const { return port_; }

  void Defer(std::function<void()> work) {
    if (counts_.clients == 0) return;
    asio::post(server_.get_io_service(), std::move(work));
  }

  std::uint32_t Advertise(const FoxgloveChannel& channel) {
    std::uint32_t id = 0;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      id = std::uint32_t(channels_.size());
      channels_.push_back(channel);
      subscribers_.push_back(0);
    }
    ++counts_.channels;
    asio::post(server_.get_io_service(), [this, id, channel] {
      const std::string message =
          nlohmann::json{{"op", "advertise"}, {"channels", {ChannelJson(id, channel)}}}.dump();
      for (auto& [handle, client] : clients_) SendText(handle, message);
    });
    return id;
  }

  bool Subscribed(std::uint32_t channel) const {
    std::lock_guard<std::mutex> lock(mutex_);
    return channel < subscribers_.size() && subscribers_[channel] > 0;
  }

  static std::string MessageData(std::uint64_t time_ns, const std::string& payload) {
    std::string frame(1 + 4 + 8, '\0');
    frame[0] = 1;  // MessageData; the subscription id (1..4) is set per client
    for (int i = 0; i < 8; ++i) frame[std::size_t(5 + i)] = char((time_ns >> (8 * i)) & 0xff);
    return frame + payload;
  }

  void Latch(std::uint32_t channel, std::uint64_t time_ns, std::function<std::string()> make) {
    auto message = std::make_shared<LatchedMessage>();
    message->time_ns = time_ns;
    message->make = std::move(make);
    {
      std::lock_guard<std::mutex> lock(mutex_);
      latched_[channel] = message;
    }
    if (counts_.clients == 0) return;
    asio::post(server_.get_io_service(), [this, channel, message] {
      if (!Subscribed(channel)) return;
      Send(channel, message->time_ns, Made(message.get()));
    });
  }

  // The server's thread: a latched message's payload, made once.
  static const std::string& Made(LatchedMessage* message) {
    if (!message->made) message->payload = message->make(), message->made = true;
    return message->payload;
  }

  void Send(std::uint32_t channel, std::uint64_t time_ns, const std::string& payload) {
    std::string frame = MessageData(time_ns, payload);
    const Clock::time_point now = Clock::now();
    std::vector<Handle> slow;
    for (auto& [handle, client] : clients_) {
      const auto subscription = client.by_channel.find(channel);
      if (subscription == client.by_channel.end()) continue;
      asio::error_code ec;
      const Server::connection_ptr con = server_.get_con_from_hdl(handle, ec);
      if (ec) continue;
      if (bool drop = false;
          !client.backlog.Admit(con->get_buffered_amount(), options_, now, &drop)) {
        ++counts_.messages_skipped;
        if (drop) slow.push_back(handle);
        continue;
      }
      for (int i = 0; i < 4; ++i) frame[std::size_t(1 + i)] = char(subscription->second >> (8 * i));
      if (con->send(frame.data(), frame.size(), websocketpp::frame::opcode::binary)) continue;
      ++counts_.messages_sent;
      counts_.bytes_sent += std::int64_t(frame.size());
    }
    counts_.dropped_slow += DropSlow(server_, slow);
  }

  bool HasClients() const { return counts_.clients > 0; }

  FoxgloveCounts counts() const {
    FoxgloveCounts c;
    c.clients = counts_.clients;
    c.connections = counts_.connections;
    c.refused_origin = counts_.refused_origin;
    c.refused_protocol = counts_.refused_protocol;
    c.refused_full = counts_.refused_full;
    c.channels = counts_.channels;
    c.subscriptions = counts_.subscriptions;
    c.requests_refused = counts_.requests_refused;
    c.closed_oversized = counts_.closed_oversized;
    c.dropped_slow = counts_.dropped_slow;
    c.messages_sent = counts_.messages_sent;
    c.messages_skipped = counts_.messages_skipped;
    c.bytes_sent = counts_.bytes_sent;
    return c;
  }

 private:
  struct Client {
    std::map<std::uint32_t, std::uint32_t> subscriptions;  // subscription id -> channel
    std::map<std::uint32_t, std::uint32_t> by_channel;     // channel -> subscription id
    Backlog backlog;
  };
  struct Counts {
    std::atomic<std::int64_t> clients{0}, connections{0}, refused_origin{0}, refused_protocol{0},
        refused_full{0}, channels{0}, subscriptions{0}, requests_refused{0}, closed_oversized{0},
        dropped_slow{0}, messages_sent{0}, messages_skipped{0}, bytes_sent{0};
  };

  bool Validate(Handle h) {
    const Server::connection_ptr con = server_.get_con_from_hdl(h);
    const std::string host = con->get_request_header("Host");
    if (!HostAllowed(host) || !OriginAllowed(con->get_origin(), host)) {
      ++counts_.refused_origin;
      con->set_status(http_status::forbidden);
      return false;
    }
    bool foxglove = false;
    for (const std::string& protocol : con->get_requested_subprotocols()) {
      foxglove = foxglove || protocol == kFoxgloveSubprotocol;
    }
    if (!foxglove || con->get_resource() != "/") {
      ++counts_.refused_protocol;
      con->set_status(http_status::bad_request);
      return false;
    }
    if (clients_.size() >= std::size_t(options_.max_clients)) {
      ++counts_.refused_full;
      con->set_status(http_status::service_unavailable);
      return false;
    }
    con->select_subprotocol(kFoxgloveSubprotocol);
    return true;
  }

  void Opened(Handle h) {
    clients_.emplace(h, Client{});
    ++counts_.connections;
    counts_.clients = std::int64_t(clients_.size());
    SendText(h, nlohmann::json{{"op", "serverInfo"},
                               {"name", "sandbox"},
                               {"capabilities", nlohmann::json::array()},
                               {"supportedEncodings", nlohmann::json::array()},
                               {"metadata", nlohmann::json::object()},
                               {"sessionId", session_}}
                    .dump());
    nlohmann::json channels = nlohmann::json::array();
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (std::uint32_t id = 0; id < channels_.size(); ++id) {
        channels.push_back(ChannelJson(id, channels_[id]));
      }
    }
    if (!channels.empty())
      SendText(h, nlohmann::json{{"op", "advertise"}, {"channels", channels}}.dump());
  }

  void Closed(Handle h) {
    const auto code = server_.get_con_from_hdl(h)->get_local_close_code();
    if (code == websocketpp::close::status::message_too_big) ++counts_.closed_oversized;
    const auto it = clients_.find(h);
    if (it == clients_.end()) return;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& [channel, id] : it->second.by_channel) --subscribers_[channel];
    }
    clients_.erase(it);
    counts_.clients = std::int64_t(clients_.size());
  }

  void Request(Handle h, Server::message_ptr message) {
    Client& client = clients_[h];
    std::string problem;
    if (message->get_opcode() != websocketpp::frame::opcode::text) {
      problem = "binary messages (client publishing) are not offered";
    } else {
      try {
        const FoxgloveRequest request = ParseFoxgloveRequest(message->get_payload());
        if (request.op == FoxgloveRequest::Op::kSubscribe) {
          for (const auto& [id, channel] : request.subscribe)
            problem += Subscribe(h, &client, id, channel);
        } else if (request.op == FoxgloveRequest::Op::kUnsubscribe) {
          for (const std::uint32_t id : request.unsubscribe) Unsubscribe(&client, id);
        } else {
          problem = "\"" + request.op_name + "\" is not offered (subscribe and unsubscribe are)";
        }
      } catch (const std::invalid_argument& e) {
        problem = std::string("not a request: ") + e.what();
      }
    }
    if (problem.empty()) return;
    ++counts_.requests_refused;
    SendText(h, nlohmann::json{{"op", "status"}, {"level", 1}, {"message", problem}}.dump());
  }

  std::string Subscribe(Handle h, Client* client, std::uint32_t id, std::uint32_t channel) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (channel >= channels_.size()) return "no channel " + std::to_string(channel) + "; ";
    if (client->subscriptions.count(id) || client->by_channel.count(channel)) {
      return "subscription " + std::to_string(id) + " or its channel is taken; ";
    }
    client->subscriptions[id] = channel;
    client->by_channel[channel] = id;
    ++subscribers_[channel];
    ++counts_.subscriptions;
    if (const auto latched = latched_.find(channel); latched != latched_.end()) {
      std::string frame = MessageData(latched->second->time_ns, Made(latched->second.get()));
      for (int i = 0; i < 4; ++i) frame[std::size_t(1 + i)] = char(id >> (8 * i));
      asio::error_code ec;
      server_.send(h, frame.data(), frame.size(), websocketpp::frame::opcode::binary, ec);
      if (!ec) ++counts_.messages_sent, counts_.bytes_sent += std::int64_t(frame.size());
    }
    return "";
  }

  void Unsubscribe(Client* client, std::uint32_t id) {
    const auto it = client->subscriptions.find(id);
    if (it == client->subscriptions.end()) return;
    std::lock_guard<std::mutex> lock(mutex_);
    --subscribers_[it->second];
    client->by_channel.erase(it->second);
    client->subscriptions.erase(it);
  }

  void SendText(Handle h, const std::string& text) {
    asio::error_code ec;
    server_.send(h, text, websocketpp::frame::opcode::text, ec);
    if (!ec) counts_.bytes_sent += std::int64_t(text.size());
  }

  const ServerOptions options_;
  const std::string session_;
  Server server_;
  std::thread thread_;
  std::unique_ptr<asio::steady_timer> stop_timer_;
  int port_{0};
  std::map<Handle, Client, std::owner_less<Handle>> clients_;  // server thread only
  mutable std::mutex mutex_;
  std::vector<FoxgloveChannel> channels_;                             // by id
  std::vector<int> subscribers_;                                      // by channel
  std::map<std::uint32_t, std::shared_ptr<LatchedMessage>> latched_;  // by channel
  Counts counts_;
};

FoxgloveServer::FoxgloveServer(const ServerOptions& options)
    : impl_(std::make_unique<Impl>(options)), port_(impl_->port()), address_(options.address) {}
FoxgloveServer::~FoxgloveServer() = default;

std::string FoxgloveServer::url() const { return ServerUrl("ws", address_, port_); }
void FoxgloveServer::Defer(std::function<void()> work) { impl_->Defer(std::move(work)); }
std::uint32_t FoxgloveServer::Advertise(const FoxgloveChannel& channel) {
  return impl_->Advertise(channel);
}
void FoxgloveServer::Latch(std::uint32_t channel, std::uint64_t time_ns,
                           std::function<std::string()> make) {
  impl_->Latch(channel, time_ns, std::move(make));
}
bool FoxgloveServer::Subscribed(std::uint32_t channel) const { return impl_->Subscribed(channel); }
void FoxgloveServer::Send(std::uint32_t channel, std::uint64_t time_ns,
                          const std::string& payload) {
  impl_->Send(channel, time_ns, payload);
}
bool FoxgloveServer::HasClients() const { return impl_->HasClients(); }
FoxgloveCounts FoxgloveServer::counts() const { return impl_->counts(); }

}  // namespace sandbox::web
