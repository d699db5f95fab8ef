// The browser view's server on 127.0.0.1 against real clients: websocketpp's
// own client for the WebSocket, plain sockets for raw HTTP and misbehaviour.
// What is served is compared with the files on disk; what is refused, with
// the status line a client sees and the server's counts.

#include "web/stream_server.h"

#include <arpa/inet.h>
#include <assimp/scene.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <assimp/Importer.hpp>
#include <array>
#include <chrono>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <thread>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "scene/surface_ids.h"
#include "web/level_model.h"
#include "web/stream_state.h"

#define ASIO_STANDALONE
#define _WEBSOCKETPP_CPP11_STL_
#include <websocketpp/client.hpp>
#include <websocketpp/config/asio_no_tls_client.hpp>

namespace sandbox::web {
namespace {

using Client = websocketpp::client<websocketpp::config::asio_client>;
using namespace std::chrono_literals;

ServerOptions TestOptions() {
  ServerOptions options;
  options.page_dir = SANDBOX_WEB_PAGE_DIR;
  options.max_rate_hz = 200.0;
  return options;
}

std::string ReadFile(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream bytes;
  bytes << in.rdbuf();
  return bytes.str();
}

// Waits (up to 20 s, so a slow machine passes) until done() holds.
template <typename Done>
bool WaitFor(Done done) {
  const auto end = std::chrono::steady_clock::now() + 20s;
  while (!done()) {
    if (std::chrono::steady_clock::now() > end) return false;
    std::this_thread::sleep_for(5ms);
  }
  return true;
}

// A TCP connection to the server, for raw requests.
class RawSocket {
 public:
  // receive_buffer: SO_RCVBUF in bytes (0: the system's), set before connecting.
  explicit RawSocket(int port, int receive_buffer = 0) : fd_(socket(AF_INET, SOCK_STREAM, 0)) {
    if (receive_buffer > 0) {
      setsockopt(fd_, SOL_SOCKET, SO_RCVBUF, &receive_buffer, sizeof receive_buffer);
    }
    sockaddr_in address{};
    address.sin_family = AF_INET;
    address.sin_port = htons(std::uint16_t(port));
    address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    connected_ = connect(fd_, reinterpret_cast<sockaddr*>(&address), sizeof address) == 0;
    timeval timeout{20, 0};
    setsockopt(fd_, SOL_SOCKET, SO_RCVTIMEO, &timeout, sizeof timeout);
  }
  ~RawSocket() { close(fd_); }
  bool connected() const { return connected_; }
  int fd() const { return fd_; }
  void Send(const std::string& bytes) {
    ASSERT_EQ(send(fd_, bytes.data(), bytes.size(), MSG_NOSIGNAL), ssize_t(bytes.size()));
  }
  // Everything until the server closes (or the timeout).
  std::string ReadAll() {
    std::string all;
    char buffer[65536];
    for (ssize_t n; (n = recv(fd_, buffer, sizeof buffer, 0)) > 0;)
      all.append(buffer, std::size_t(n));
    return all;
  }
  // Until the end of the response's headers.
  std::string ReadHeaders() {
    std::string all;
    char c;
    while (all.find("\r\n\r\n") == std::string::npos && recv(fd_, &c, 1, 0) == 1) all += c;
    return all;
  }

 private:
  int fd_;
  bool connected_{false};
};

// A WebSocket opening handshake for /stream, as a raw request.
const char* const kHandshake =
    "GET /stream HTTP/1.1\r\nHost: 127.0.0.1\r\nUpgrade: websocket\r\n"
    "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
    "Sec-WebSocket-Version: 13\r\n\r\n";

std::string Get(int port, const std::string& path, const std::string& host = "127.0.0.1") {
  RawSocket socket(port);
  EXPECT_TRUE(socket.connected());
  socket.Send("GET " + path + " HTTP/1.1\r\nHost: " + host + ":" + std::to_string(port) +
              "\r\nConnection: close\r\n\r\n");
  return socket.ReadAll();
}

std::string StatusLine(const std::string& response) {
  return response.substr(0, response.find("\r\n"));
}
std::string Body(const std::string& response) {
  const auto end = response.find("\r\n\r\n");
  return end == std::string::npos ? std::string() : response.substr(end + 4);
}

// A WebSocket client on its own thread, keeping what it receives.
class StreamClient {
 public:
  explicit StreamClient(int port, const std::string& origin = "", const std::string& host = "") {
    client_.clear_access_channels(websocketpp::log::alevel::all);
    client_.clear_error_channels(websocketpp::log::elevel::all);
    client_.init_asio();
    client_.set_message_handler([this](websocketpp::connection_hdl, Client::message_ptr message) {
      std::lock_guard<std::mutex> lock(mutex_);
      if (message->get_opcode() == websocketpp::frame::opcode::binary) {
        binary_.push_back(message->get_payload());
      } else {
        text_.push_back(message->get_payload());
      }
      order_ += message->get_opcode() == websocketpp::frame::opcode::binary ? 'b' : 't';
    });
    client_.set_open_handler([this](websocketpp::connection_hdl) { open_ = true; });
    client_.set_fail_handler([this](websocketpp::connection_hdl h) {
      const Client::connection_ptr con = client_.get_con_from_hdl(h);
      {
        std::lock_guard<std::mutex> lock(mutex_);
        fail_reason_ = con->get_ec().message();
      }
      status_ = con->get_response_code();
      failed_ = true;
    });
    client_.set_close_handler([this](websocketpp::connection_hdl h) {
      close_code_ = client_.get_con_from_hdl(h)->get_remote_close_code();
      closed_ = true;
    });
    websocketpp::lib::error_code ec;
    connection_ = client_.get_connection("ws://127.0.0.1:" + std::to_string(port) + "/stream", ec);
    if (!origin.empty()) connection_->replace_header("Origin", origin);
    if (!host.empty()) connection_->replace_header("Host", host);
    client_.connect(connection_);
    thread_ = std::thread([this] { client_.run(); });
  }
  ~StreamClient() {
    websocketpp::lib::error_code ec;
    if (open_ && !closed_) connection_->close(websocketpp::close::status::normal, "bye", ec);
    WaitFor([this] { return closed_ || failed_ || !open_; });
    client_.stop();
    thread_.join();
  }
  void Send(const std::string& text) { connection_->send(text, websocketpp::frame::opcode::text); }
  std::atomic<bool> open_{false}, failed_{false}, closed_{false};
  std::atomic<int> status_{0}, close_code_{0};
  std::vector<std::string> Text() {
    std::lock_guard<std::mutex> lock(mutex_);
    return text_;
  }
  std::vector<std::string> Binary() {
    std::lock_guard<std::mutex> lock(mutex_);
    return binary_;
  }
  std::string Order() {
    std::lock_guard<std::mutex> lock(mutex_);
    return order_;
  }
  // How it stands, for a failing test's message.
  std::string Describe() {
    std::lock_guard<std::mutex> lock(mutex_);
    return "open " + std::to_string(open_) + ", failed " + std::to_string(failed_) + " (" +
           fail_reason_ + ", status " + std::to_string(status_) + "), closed " +
           std::to_string(closed_);
  }

 private:
  Client client_;
  Client::connection_ptr connection_;
  std::thread thread_;
  std::mutex mutex_;
  std::vector<std::string> text_, binary_;
  std::string order_, fail_reason_;
};

std::string Describe(const ServerCounts& counts) {
  return "clients " + std::to_string(counts.clients) + ", connections " +
         std::to_string(counts.connections) + ", refused_full " +
         std::to_string(counts.refused_full) + ", failed " + std::to_string(counts.failed);
}

TEST(StreamServerTest, ServesThePageAndThreeJsAsTheyAreOnDisk) {
  StreamServer server(TestOptions());
  ASSERT_GT(server.port(), 0);
  const std::filesystem::path page = SANDBOX_WEB_PAGE_DIR;
  std::string response = Get(server.port(), "/");
  EXPECT_EQ(StatusLine(response), "HTTP/1.1 200 OK");
  EXPECT_EQ(Body(response), ReadFile(page / "index.html"));
  response = Get(server.port(), "/view.js");
  EXPECT_EQ(Body(response), ReadFile(page / "view.js"));
  EXPECT_NE(response.find("Content-Type: text/javascript"), std::string::npos);
  response = Get(server.port(), "/three/build/three.module.js");
  EXPECT_EQ(Body(response), ReadFile("/usr/share/javascript/three/build/three.module.js"));
  for (const char* bad : {"/nothing.js", "/../CMakeLists.txt", "/three/../../../etc/passwd",
                          "/%2e%2e/etc/passwd", "/three/", "//etc/passwd"}) {
    EXPECT_EQ(StatusLine(Get(server.port(), bad)), "HTTP/1.1 404 Not Found") << bad;
  }
  EXPECT_EQ(server.counts().not_found, 6);
  EXPECT_EQ(server.counts().http_requests, 3);
  // A page on another name that resolves here (DNS rebinding) is refused.
  EXPECT_EQ(StatusLine(Get(server.port(), "/", "evil.example")), "HTTP/1.1 403 Forbidden");
  EXPECT_EQ(StatusLine(Get(server.port(), "/", "localhost")), "HTTP/1.1 200 OK");
}

TEST(StreamServerTest, EachClientGetsTheLevelFirstThenTheNewestState) {
  StreamServer server(TestOptions());
  const std::string level = std::string("glTF") + std::string(1000, '\x01');
  const std::string info = R"({"type":"level"})";
  server.SetLevel(info, level);
  StreamClient first(server.port());
  ASSERT_TRUE(WaitFor([&] { return first.open_.load(); }));
  // Published faster than sent: a client sees increasing ticks, the last one last.
  for (int tick = 1; tick <= 200; ++tick) {
    StreamState state;
    state.tick = tick;
    server.Publish([state] { return EncodeState(state); });
    std::this_thread::sleep_for(100us);
  }
  ASSERT_TRUE(WaitFor([&] {
    const auto text = first.Text();
    return text.size() > 1 && nlohmann::json::parse(text.back())["tick"] == 200;
  }));
  EXPECT_EQ(first.Binary(), std::vector<std::string>{level});
  EXPECT_EQ(first.Order().substr(0, 2), "tb");  // the level's description, then its model
  EXPECT_EQ(first.Text().front(), info);
  std::int64_t last = 0;
  for (std::size_t i = 1; i < first.Text().size(); ++i) {
    const std::int64_t tick = nlohmann::json::parse(first.Text()[i])["tick"];
    EXPECT_GT(tick, last);
    last = tick;
  }
  EXPECT_LE(first.Text().size(), 201u);
  // A client that comes later gets the level too, then the next state, its
  // binary part after its text.
  StreamClient second(server.port());
  ASSERT_TRUE(WaitFor([&] { return second.open_.load(); }));
  StreamState state;
  state.tick = 201;
  server.Publish([state] { return EncodedState(EncodeState(state), "SMPL-samples"); });
  ASSERT_TRUE(WaitFor([&] { return second.Binary().size() == 2; }));
  EXPECT_EQ(second.Binary(), (std::vector<std::string>{level, "SMPL-samples"}));
  EXPECT_EQ(second.Order(), "tbtb");
  EXPECT_EQ(nlohmann::json::parse(second.Text()[1])["tick"], 201);
  EXPECT_EQ(server.counts().connections, 2);
  EXPECT_EQ(server.counts().states_published, 201);
}

TEST(StreamServerTest, AnotherOriginOrHostIsRefusedAndTheSameOriginServed) {
  StreamServer server(TestOptions());
  const std::string self = "127.0.0.1:" + std::to_string(server.port());
  {
    StreamClient other(server.port(), "http://evil.example");
    ASSERT_TRUE(WaitFor([&] { return other.failed_.load(); }));
    EXPECT_EQ(other.status_, 403);
  }
  {
    StreamClient rebound(server.port(), "http://evil.example:80", "evil.example:80");
    ASSERT_TRUE(WaitFor([&] { return rebound.failed_.load(); }));
    EXPECT_EQ(rebound.status_, 403);
  }
  {
    StreamClient same(server.port(), "http://" + self);
    ASSERT_TRUE(WaitFor([&] { return same.open_.load(); }));
  }
  EXPECT_EQ(server.counts().refused_origin, 2);
  EXPECT_EQ(server.counts().connections, 1);
}

TEST(StreamServerTest, ClientsOverTheLimitAreRefusedUntilOneLeaves) {
  ServerOptions options = TestOptions();
  options.max_clients = 2;
  StreamServer server(options);
  auto a = std::make_unique<StreamClient>(server.port());
  StreamClient b(server.port());
  ASSERT_TRUE(WaitFor([&] { return a->open_ && b.open_; }))
      << a->Describe() << "; " << b.Describe();
  // A client is the server's once its open handler has run, just after the
  // client has seen the handshake's answer.
  ASSERT_TRUE(WaitFor([&] { return server.counts().clients == 2; })) << Describe(server.counts());
  {
    StreamClient c(server.port());
    ASSERT_TRUE(WaitFor([&] { return c.failed_.load(); })) << c.Describe();
    EXPECT_EQ(c.status_, 503) << c.Describe() << "; " << Describe(server.counts());
  }
  a.reset();
  ASSERT_TRUE(WaitFor([&] { return server.counts().clients == 1; })) << Describe(server.counts());
  StreamClient d(server.port());
  ASSERT_TRUE(WaitFor([&] { return d.open_.load(); })) << d.Describe();
  EXPECT_EQ(server.counts().refused_full, 1) << Describe(server.counts());
  EXPECT_EQ(server.counts().connections, 3) << Describe(server.counts());
}

TEST(StreamServerTest, MessagesAreDroppedAndAnOversizedOneClosesTheConnection) {
  ServerOptions options = TestOptions();
  options.max_message_bytes = 1024;
  StreamServer server(options);
  StreamClient client(server.port());
  ASSERT_TRUE(WaitFor([&] { return client.open_.load(); }));
  client.Send("hello");
  ASSERT_TRUE(WaitFor([&] { return server.counts().messages_dropped == 1; }));
  client.Send(std::string(4096, 'x'));
  ASSERT_TRUE(WaitFor([&] { return client.closed_.load(); }));
  EXPECT_EQ(client.close_code_, 1009);  // message too big
  EXPECT_EQ(server.counts().closed_oversized, 1);
  EXPECT_EQ(server.counts().messages_dropped, 1);
}

// A message in fragments that never ends (no frame with FIN): closed once its
// fragments pass the message limit, as an oversized message is.
TEST(StreamServerTest, AFragmentedMessageWithoutEndIsClosedAtTheLimit) {
  ServerOptions options = TestOptions();
  options.max_message_bytes = 1024;
  StreamServer server(options);
  RawSocket socket(server.port());
  socket.Send(kHandshake);
  EXPECT_EQ(StatusLine(socket.ReadHeaders()), "HTTP/1.1 101 Switching Protocols");
  // Masked frames of 100 bytes, FIN clear: a text frame, then continuations.
  auto fragment = [](unsigned char opcode) {
    std::string frame;
    frame += char(opcode);    // FIN 0
    frame += char(0x80 | 100);  // masked, 100 bytes
    frame += std::string(4, '\0');  // a zero mask: the payload as it is
    frame += std::string(100, 'x');
    return frame;
  };
  socket.Send(fragment(0x1));
  for (int i = 0; i < 20 && server.counts().closed_oversized == 0; ++i) {
    if (send(socket.fd(), fragment(0x0).data(), 106, MSG_NOSIGNAL) != 106) break;
    std::this_thread::sleep_for(10ms);
  }
  ASSERT_TRUE(WaitFor([&] { return server.counts().closed_oversized == 1; }));
  EXPECT_EQ(server.counts().messages_dropped, 0);  // never a whole message
  EXPECT_EQ(server.counts().clients, 0);
}

// With on_text (sandbox view, --web-control) a text message is a command:
// taken or refused, counted; a binary one is still dropped.
TEST(StreamServerTest, OnTextTakesOrRefusesEachTextMessage) {
  ServerOptions options = TestOptions();
  std::vector<std::string> taken;
  std::mutex mutex;
  options.on_text = [&](const std::string& text) -> std::string {
    if (text != "good") return "not good";
    std::lock_guard<std::mutex> lock(mutex);
    taken.push_back(text);
    return "";
  };
  StreamServer server(options);
  StreamClient client(server.port());
  ASSERT_TRUE(WaitFor([&] { return client.open_.load(); }));
  client.Send("good");
  client.Send("bad");
  client.Send("good");
  ASSERT_TRUE(WaitFor([&] { return server.counts().commands == 2; }));
  ASSERT_TRUE(WaitFor([&] { return server.counts().commands_refused == 1; }));
  std::lock_guard<std::mutex> lock(mutex);
  EXPECT_EQ(taken, (std::vector<std::string>{"good", "good"}));
  EXPECT_EQ(server.counts().messages_dropped, 0);
}

TEST(StreamServerTest, MalformedRequestsAndFramesAreRefusedAndCounted) {
  StreamServer server(TestOptions());
  {
    RawSocket garbage(server.port());
    garbage.Send("NONSENSE\r\n\r\n");
    EXPECT_EQ(StatusLine(garbage.ReadAll()).substr(0, 12), "HTTP/1.1 400");
  }
  ASSERT_TRUE(WaitFor([&] { return server.counts().failed == 1; }));
  // A handshake, then a frame with a reserved opcode: a protocol error.
  RawSocket socket(server.port());
  socket.Send(kHandshake);
  EXPECT_EQ(StatusLine(socket.ReadHeaders()), "HTTP/1.1 101 Switching Protocols");
  socket.Send(std::string("\x83\x80\x00\x00\x00\x00", 6));  // FIN, opcode 3, masked, empty
  ASSERT_TRUE(WaitFor([&] { return server.counts().closed_protocol == 1; }));
  EXPECT_EQ(server.counts().clients, 0);
}

TEST(StreamServerTest, AClientThatNeverReadsSkipsStatesThenIsDroppedAndOthersKeepUp) {
  ServerOptions options = TestOptions();
  options.max_queued_bytes = 256 * 1024;
  options.slow_timeout_s = 0.5;
  StreamServer server(options);
  // The stuck client's socket takes little (a small receive buffer), so the
  // states it never reads back up in the server's queue within a few ticks.
  RawSocket stuck(server.port(), 4096);
  stuck.Send(kHandshake);
  EXPECT_EQ(StatusLine(stuck.ReadHeaders()), "HTTP/1.1 101 Switching Protocols");
  StreamClient reader(server.port());
  ASSERT_TRUE(WaitFor([&] { return reader.open_.load(); }));
  // States of 64 KB at most 100 a second: 6.4 MB/s, which the reader keeps
  // up with on a machine 10x slower than this one.
  const auto samples = std::make_shared<const std::string>(64 << 10, '\x5a');
  std::int64_t tick = 0;
  const bool dropped = WaitFor([&] {
    StreamState state;
    state.tick = ++tick;
    server.Publish([text = EncodeState(state), samples] { return EncodedState(text, *samples); });
    std::this_thread::sleep_for(10ms);
    return server.counts().dropped_slow >= 1;
  });
  const ServerCounts counts = server.counts();
  ASSERT_TRUE(dropped) << "published " << counts.states_published << ", sent "
                       << counts.states_sent << ", skipped " << counts.states_skipped
                       << ", bytes " << counts.bytes_sent << ", clients " << counts.clients;
  // (The stuck client's connection ends when its close handshake times out.)
  EXPECT_EQ(server.counts().dropped_slow, 1) << "the reader was dropped too";
  EXPECT_GT(server.counts().states_skipped, 0);
  EXPECT_GT(reader.Text().size(), 5u);
  EXPECT_TRUE(reader.open_ && !reader.closed_);
}

TEST(StreamServerTest, AnAddressItCannotBindIsAnErrorNamingIt) {
  StreamServer first(TestOptions());
  ServerOptions options = TestOptions();
  options.port = first.port();
  try {
    StreamServer second(options);
    FAIL() << "bound a port in use";
  } catch (const ServerError& error) {
    EXPECT_NE(std::string(error.what()).find("127.0.0.1:" + std::to_string(first.port())),
              std::string::npos)
        << error.what();
  }
  options.address = "not-an-address";
  EXPECT_THROW(StreamServer{options}, ServerError);
  options = TestOptions();
  options.page_dir = "/nowhere";
  EXPECT_THROW(StreamServer{options}, ServerError);
}

TEST(StreamStateTest, EncodesEveryFieldAsJson) {
  StreamState state;
  state.tick = 42;
  state.time_s = 1.5;
  state.tick_ms = 0.25;
  state.late_ms = 0.125;
  StreamState::Robot robot;
  robot.name = "wing";
  robot.p_W = {1, 2, 3};
  robot.q_W = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()));
  robot.has_pose = true;
  robot.rejected = 3;
  robot.stale = {"wing/BONES"};
  robot.bone_values = {0.5, -0.25};
  robot.joints = {1.0, 0.0, 0.0, 0.123456789, 0.0, 1.0, 0.0, -2.000004, 0.0, 0.0, 1.0, 3.0};
  state.robots.push_back(robot);
  state.actors.push_back({"door", {4, 5, 6}, Eigen::Quaterniond::Identity()});
  const nlohmann::json json = nlohmann::json::parse(EncodeState(state));
  EXPECT_EQ(json["type"], "state");
  EXPECT_EQ(json["tick"], 42);
  EXPECT_EQ(json["t"], 1.5);
  EXPECT_EQ(json["robots"][0]["name"], "wing");
  EXPECT_EQ(json["robots"][0]["p"], nlohmann::json({1.0, 2.0, 3.0}));
  EXPECT_NEAR(double(json["robots"][0]["q"][0]), std::sqrt(0.5), 1e-12);  // w
  EXPECT_NEAR(double(json["robots"][0]["q"][3]), std::sqrt(0.5), 1e-12);  // z
  EXPECT_EQ(json["robots"][0]["stale"][0], "wing/BONES");
  EXPECT_EQ(json["robots"][0]["rejected"], 3);
  EXPECT_EQ(json["robots"][0]["bones"], nlohmann::json({0.5, -0.25}));
  ASSERT_EQ(json["robots"][0]["joints"].size(), 12u);
  EXPECT_EQ(json["robots"][0]["joints"][3], 0.12346);  // to 1e-5
  EXPECT_EQ(json["robots"][0]["joints"][7], -2.0);
  EXPECT_EQ(json["actors"][0]["name"], "door");
  EXPECT_EQ(json["actors"][0]["p"][2], 6.0);
}

// The samples' binary layout, read back field by field as the page reads it.
TEST(StreamStateTest, EncodesSamplesAsAHeaderAndAlignedArrays) {
  StreamState state;
  state.tick = 7;
  EXPECT_EQ(EncodeSamples(state), "");  // none with this state
  state.has_samples = true;
  state.samples_tick = 5;
  state.samples_origin = {100.0, -200.0, 3.0};
  StreamState::Samples a{"wing", "scanner", "face", {1, 2, 3, 4, 5, 6, 7, 8, 9}, {1, 0, 1}, {5, 0, 9}};
  StreamState::Samples b{"wing", "alt", "ray", {-1.5f, 2.5f, 0.25f}, {1}, {123456}};
  state.samples = {a, b};
  const std::string out = EncodeSamples(state);
  ASSERT_EQ(out.substr(0, 4), "SMPL");
  std::uint32_t length = 0;
  std::memcpy(&length, out.data() + 4, 4);
  EXPECT_EQ(length % 4, 0u);
  const nlohmann::json header = nlohmann::json::parse(out.substr(8, length));
  EXPECT_EQ(header["tick"], 5);  // the tick they were taken at
  EXPECT_EQ(header["origin"], nlohmann::json({100.0, -200.0, 3.0}));
  ASSERT_EQ(header["sets"].size(), 2u);
  std::size_t offset = 8 + length;
  for (std::size_t s = 0; s < 2; ++s) {
    const StreamState::Samples& set = state.samples[s];
    EXPECT_EQ(header["sets"][s]["sensor"], set.sensor);
    EXPECT_EQ(header["sets"][s]["type"], set.type);
    const std::size_t n = header["sets"][s]["count"];
    ASSERT_EQ(n, set.hit.size());
    EXPECT_EQ(offset % 4, 0u);  // each array where a typed array may view it
    std::vector<float> xyz(3 * n);
    std::memcpy(xyz.data(), out.data() + offset, 12 * n);
    EXPECT_EQ(xyz, set.xyz);
    offset += 12 * n;
    std::vector<std::int32_t> surface(n);
    std::memcpy(surface.data(), out.data() + offset, 4 * n);
    EXPECT_EQ(surface, set.surface);
    offset += 4 * n;
    EXPECT_EQ(std::vector<std::uint8_t>(out.begin() + std::ptrdiff_t(offset),
                                        out.begin() + std::ptrdiff_t(offset + n)),
              set.hit);
    offset += (n + 3) / 4 * 4;
  }
  EXPECT_EQ(offset, out.size());
}

// What the page is told before the model: the surfaces, the robots' bones and sensors.
TEST(LevelModelTest, TheLevelsDescriptionNamesItsSurfacesBonesAndSensors) {
  const scene::Level level =
      scene::LoadLevel(std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml");
  const nlohmann::json info = nlohmann::json::parse(LevelInfoJson(level));
  EXPECT_EQ(info["type"], "level");
  EXPECT_EQ(info["name"], "sample");
  const scene::SurfaceIds ids(level);
  ASSERT_EQ(info["surfaces"].size(), ids.entries().size());
  EXPECT_EQ(info["surfaces"][0]["id"], 1);
  EXPECT_EQ(info["surfaces"][0]["name"], level.actors[0].name);
  const nlohmann::json& robot = info["robots"][0];
  EXPECT_EQ(robot["name"], "ELAHA");
  ASSERT_EQ(robot["bones"].size(), level.robots[0].bones.size());
  int values = 0;
  for (const auto& bone : robot["bones"]) values += int(bone["values"]);
  EXPECT_EQ(values, level.robots[0].num_values);
  EXPECT_EQ(robot["sensors"][0]["name"], "scanner");
  EXPECT_EQ(robot["sensors"][0]["type"], "face");
}

TEST(LevelModelTest, TheSampleLevelAsABinaryGltfThatAssimpReadsBack) {
  const scene::Level level =
      scene::LoadLevel(std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml");
  const LevelModel model = MakeLevelModel(level);
  ASSERT_GE(model.glb.size(), 12u);
  EXPECT_EQ(model.glb.substr(0, 4), "glTF");
  std::uint32_t header[3];
  std::memcpy(header, model.glb.data(), 12);
  EXPECT_EQ(header[1], 2u);                               // glTF 2
  EXPECT_EQ(header[2], std::uint32_t(model.glb.size()));  // its length
  std::size_t actor_triangles = 0;
  for (const scene::Actor& actor : level.actors) actor_triangles += actor.num_triangles();
  EXPECT_EQ(model.source_triangles, actor_triangles);
  std::size_t robot_triangles = 0;
  for (const scene::RobotModel& robot : level.robots)
    for (const scene::SkinnedMesh& mesh : robot.meshes) robot_triangles += mesh.bind.num_triangles();
  EXPECT_GT(robot_triangles, 0u);
  EXPECT_EQ(model.robot_triangles, robot_triangles);
  // Under the budget: all of them.
  EXPECT_EQ(model.triangles, model.source_triangles + robot_triangles);
  Assimp::Importer importer;
  const aiScene* read = importer.ReadFileFromMemory(model.glb.data(), model.glb.size(), 0, "glb");
  ASSERT_NE(read, nullptr) << importer.GetErrorString();
  std::size_t faces = 0;
  for (unsigned m = 0; m < read->mNumMeshes; ++m) faces += read->mMeshes[m]->mNumFaces;
  EXPECT_EQ(faces, model.triangles);
  // Over a budget, simplified to about it.
  const LevelModel small = MakeLevelModel(level, 2000);
  EXPECT_EQ(small.robot_triangles, robot_triangles);  // robots are not simplified
  EXPECT_LT(small.triangles - small.robot_triangles, 2600u);
  EXPECT_GT(small.triangles - small.robot_triangles, 100u);
}

// A textured scene's base colour textures go in as their files are, with the
// meshes' texture coordinates: assimp reads back the same bytes and the same UVs.
TEST(LevelModelTest, BaseColourTexturesAndTheirCoordinatesGoIn) {
  const std::filesystem::path truck =
      std::filesystem::path(SANDBOX_SHARED_ASSETS) / "cesium-milk-truck/CesiumMilkTruck.glb";
  if (!std::filesystem::exists(truck)) GTEST_SKIP() << truck << " is not on this machine";
  scene::LoadOptions options;
  const scene::Level level = scene::LoadLevel(truck, options);
  ASSERT_FALSE(level.textures.empty());
  const LevelModel model = MakeLevelModel(level);
  EXPECT_EQ(model.textures, 1u);  // the truck's one texture, shared by its materials
  EXPECT_EQ(model.textures_left_out, 0u);
  Assimp::Importer importer;
  const aiScene* read = importer.ReadFileFromMemory(model.glb.data(), model.glb.size(), 0, "glb");
  ASSERT_NE(read, nullptr) << importer.GetErrorString();
  ASSERT_EQ(read->mNumTextures, 1u);
  const aiTexture* texture = read->mTextures[0];
  ASSERT_EQ(texture->mHeight, 0u);
  const scene::EmbeddedTexture& source = level.textures[0];
  EXPECT_EQ(std::string(reinterpret_cast<const char*>(texture->pcData), texture->mWidth),
            std::string(source.bytes.begin(), source.bytes.end()));
  // A textured material names it; the first textured mesh has its UVs.
  std::size_t textured = 0;
  for (unsigned m = 0; m < read->mNumMaterials; ++m) {
    aiString file;
    if (read->mMaterials[m]->GetTexture(aiTextureType_DIFFUSE, 0, &file) == AI_SUCCESS) {
      EXPECT_EQ(std::string(file.C_Str()), "*0");
      ++textured;
    }
  }
  EXPECT_GT(textured, 0u);
  // Each textured vertex read back is one of the level's: the same position
  // with the same coordinates (the exporter joins identical vertices, so
  // counts and order may differ).
  std::set<std::array<long, 5>> in_level;
  auto key = [](float x, float y, float z, float u, float v) {
    return std::array<long, 5>{std::lround(x * 1e4), std::lround(y * 1e4), std::lround(z * 1e4),
                               std::lround(u * 1e5), std::lround(v * 1e5)};
  };
  for (const scene::Actor& actor : level.actors) {
    for (const scene::Mesh& mesh : actor.meshes) {
      for (std::size_t v = 0; v < mesh.uvs.size(); ++v) {
        const Eigen::Vector3f p = (actor.X_WA.cast<float>() * mesh.positions_A[v]);
        in_level.insert(key(p.x(), p.y(), p.z(), mesh.uvs[v].x(), mesh.uvs[v].y()));
      }
    }
  }
  std::size_t checked = 0, matched = 0;
  for (unsigned m = 0; m < read->mNumMeshes; ++m) {
    const aiMesh* mesh = read->mMeshes[m];
    if (!mesh->HasTextureCoords(0)) continue;
    for (unsigned v = 0; v < mesh->mNumVertices; ++v, ++checked) {
      const aiVector3D& p = mesh->mVertices[v];
      const aiVector3D& uv = mesh->mTextureCoords[0][v];
      matched += in_level.count(key(p.x, p.y, p.z, uv.x, uv.y));
    }
  }
  EXPECT_GT(checked, 1000u);
  EXPECT_EQ(matched, checked);
  // Over the byte budget: left out (counted), the base colour stays.
  const LevelModel lean = MakeLevelModel(level, 2'000'000, 1000);
  EXPECT_EQ(lean.textures, 0u);
  EXPECT_EQ(lean.textures_left_out, 1u);
}

// The robot as the browser skins it: the model's skin joints, weights and
// inverse bind matrices, read back by assimp and applied to the joint poses
// of a bent robot, put each vertex where the sandbox's own skinning does.
TEST(LevelModelTest, ARobotsSkinPutsItsVerticesWhereTheSandboxDoes) {
  const scene::Level level =
      scene::LoadLevel(std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/sample/level.toml");
  ASSERT_FALSE(level.robots.empty());
  const scene::RobotModel& robot = level.robots[0];
  scene::RobotState state(robot);
  std::vector<double> values = state.bone_values();
  for (std::size_t b = 1; b < robot.bones.size(); ++b) {  // bone 0 is the root
    const scene::Bone& bone = robot.bones[b];
    if (bone.rotation == scene::BoneRotation::kAngles)
      values[std::size_t(bone.first_value)] = 0.04 * double(b % 7);  // wings bent in steps
  }
  ASSERT_TRUE(state.SetBones(values)) << state.last_rejection();
  state.Update();

  const LevelModel model = MakeLevelModel(level);
  Assimp::Importer importer;
  const aiScene* read = importer.ReadFileFromMemory(model.glb.data(), model.glb.size(), 0, "glb");
  ASSERT_NE(read, nullptr) << importer.GetErrorString();
  const std::string prefix = RobotNodeName(0) + "_joint";
  const aiNode* robot_node = read->mRootNode->FindNode(RobotNodeName(0).c_str());
  ASSERT_NE(robot_node, nullptr);
  std::size_t checked = 0;
  double worst = 0.0;
  for (unsigned c = 0; c < robot_node->mNumChildren; ++c) {
    const aiNode* child = robot_node->mChildren[c];
    for (unsigned i = 0; i < child->mNumMeshes; ++i) {
      const aiMesh* mesh = read->mMeshes[child->mMeshes[i]];
      const int m = std::stoi(std::string(child->mName.C_Str()).substr(RobotNodeName(0).size() + 5));
      const std::vector<Eigen::Vector3f>& expected = state.positions_B(m);
      ASSERT_EQ(mesh->mNumVertices, expected.size());
      ASSERT_GT(mesh->mNumBones, 0u);
      std::vector<Eigen::Vector3d> skinned(mesh->mNumVertices, Eigen::Vector3d::Zero());
      for (unsigned b = 0; b < mesh->mNumBones; ++b) {
        const aiBone* bone = mesh->mBones[b];
        const std::string name = bone->mName.C_Str();
        ASSERT_EQ(name.rfind(prefix, 0), 0u) << name;
        const int k = std::stoi(name.substr(prefix.size()));
        Eigen::Matrix4d offset;
        for (int row = 0; row < 4; ++row)
          for (int col = 0; col < 4; ++col) offset(row, col) = bone->mOffsetMatrix[row][col];
        const Eigen::Matrix4d X = state.node_poses_B()[std::size_t(robot.joints[std::size_t(k)].node)].matrix() * offset;
        for (unsigned w = 0; w < bone->mNumWeights; ++w) {
          const aiVertexWeight& weight = bone->mWeights[w];
          const aiVector3D& v = mesh->mVertices[weight.mVertexId];
          skinned[weight.mVertexId] += weight.mWeight * (X * Eigen::Vector4d(v.x, v.y, v.z, 1.0)).head<3>();
        }
      }
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const std::uint32_t influences =
            robot.meshes[std::size_t(m)].influence_begin[v + 1] - robot.meshes[std::size_t(m)].influence_begin[v];
        if (influences > 4) continue;  // glTF's four: nearly, not exactly
        worst = std::max(worst, (skinned[v] - expected[v].cast<double>()).norm());
        ++checked;
      }
    }
  }
  EXPECT_GT(checked, 100u);
  EXPECT_LT(worst, 1e-4);
}

}  // namespace
}  // namespace sandbox::web
