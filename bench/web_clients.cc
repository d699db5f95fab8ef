// web_clients URL N SECONDS: N WebSocket clients on a browser view's stream
// (sandbox run --web), each reading for SECONDS; prints what they received:
// the level's bytes, states and bytes a second per client (states, scan
// samples and camera frames apart). For
// scripts/bench-web; it asserts nothing.

#include <atomic>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <thread>
#include <vector>

#define ASIO_STANDALONE
#define _WEBSOCKETPP_CPP11_STL_
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

namespace {

using Client = websocketpp::client<websocketpp::config::asio_client>;

struct Received {
  std::atomic<std::int64_t> level_bytes{0}, states{0}, state_bytes{0}, sample_bytes{0},
      camera_bytes{0};
  std::atomic<bool> open{false}, failed{false};
};

}  // namespace

int main(int argc, char** argv) {
  if (argc != 4) {
    std::fprintf(stderr, "usage: web_clients ws://HOST:PORT/stream CLIENTS SECONDS\n");
    return 2;
  }
  const std::string url = argv[1];
  const int count = std::atoi(argv[2]);
  const double seconds = std::atof(argv[3]);
  Client client;
  client.clear_access_channels(websocketpp::log::alevel::all);
  client.clear_error_channels(websocketpp::log::elevel::all);
  client.init_asio();
  std::vector<std::unique_ptr<Received>> received;
  std::vector<Client::connection_ptr> connections;
  for (int i = 0; i < count; ++i) {
    received.push_back(std::make_unique<Received>());
    Received* r = received.back().get();
    websocketpp::lib::error_code ec;
    Client::connection_ptr con = client.get_connection(url, ec);
    if (ec) {
      std::fprintf(stderr, "web_clients: %s: %s\n", url.c_str(), ec.message().c_str());
      return 1;
    }
    con->set_message_handler([r](websocketpp::connection_hdl, Client::message_ptr message) {
      const std::string& payload = message->get_payload();
      if (payload.rfind("SMPL", 0) == 0) {
        r->sample_bytes += std::int64_t(payload.size());
      } else if (payload.rfind("CAMF", 0) == 0) {
        r->camera_bytes += std::int64_t(payload.size());
      } else if (payload.rfind("glTF", 0) == 0 || payload.rfind("{\"type\":\"level\"", 0) == 0) {
        r->level_bytes += std::int64_t(payload.size());
      } else {
        ++r->states;
        r->state_bytes += std::int64_t(payload.size());
      }
    });
    con->set_open_handler([r](websocketpp::connection_hdl) { r->open = true; });
    con->set_fail_handler([r](websocketpp::connection_hdl) { r->failed = true; });
    client.connect(con);
    connections.push_back(con);
  }
  std::thread thread([&client] { client.run(); });
  std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
  for (const auto& con : connections) {
    websocketpp::lib::error_code ec;
    con->close(websocketpp::close::status::normal, "done", ec);
  }
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  client.stop();
  thread.join();
  int opened = 0;
  std::int64_t states = 0, bytes = 0, sample_bytes = 0, camera_bytes = 0, level = 0;
  for (const auto& r : received) {
    opened += r->open ? 1 : 0;
    states += r->states;
    bytes += r->state_bytes;
    sample_bytes += r->sample_bytes;
    camera_bytes += r->camera_bytes;
    level = std::max<std::int64_t>(level, r->level_bytes);
  }
  std::printf(
      "web_clients: %d of %d connected, level %.2f MB, %.1f states/s and %.1f kB/s a client "
      "(states %.1f kB/s, samples %.1f kB/s, camera frames %.1f kB/s)\n",
      opened, count, double(level) / 1e6, double(states) / std::max(1, count) / seconds,
      double(bytes + sample_bytes + camera_bytes) / std::max(1, count) / seconds / 1e3,
      double(bytes) / std::max(1, count) / seconds / 1e3,
      double(sample_bytes) / std::max(1, count) / seconds / 1e3,
      double(camera_bytes) / std::max(1, count) / seconds / 1e3);
  return opened == count ? 0 : 1;
}
