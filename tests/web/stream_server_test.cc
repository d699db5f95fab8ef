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
#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "scene/level.h"
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
  explicit RawSocket(int port) : fd_(socket(AF_INET, SOCK_STREAM, 0)) {
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
      status_ = client_.get_con_from_hdl(h)->get_response_code();
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

 private:
  Client client_;
  Client::connection_ptr connection_;
  std::thread thread_;
  std::mutex mutex_;
  std::vector<std::string> text_, binary_;
  std::string order_;
};

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
  server.SetLevel(level);
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
    return !text.empty() && nlohmann::json::parse(text.back())["tick"] == 200;
  }));
  EXPECT_EQ(first.Binary(), std::vector<std::string>{level});
  EXPECT_EQ(first.Order().front(), 'b');
  std::int64_t last = 0;
  for (const std::string& text : first.Text()) {
    const std::int64_t tick = nlohmann::json::parse(text)["tick"];
    EXPECT_GT(tick, last);
    last = tick;
  }
  EXPECT_LE(first.Text().size(), 200u);
  // A client that comes later gets the level too, then the next state.
  StreamClient second(server.port());
  ASSERT_TRUE(WaitFor([&] { return second.open_.load(); }));
  StreamState state;
  state.tick = 201;
  server.Publish([state] { return EncodeState(state); });
  ASSERT_TRUE(WaitFor([&] { return second.Text().size() == 1; }));
  EXPECT_EQ(second.Binary(), std::vector<std::string>{level});
  EXPECT_EQ(nlohmann::json::parse(second.Text()[0])["tick"], 201);
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
  ASSERT_TRUE(WaitFor([&] { return a->open_ && b.open_; }));
  {
    StreamClient c(server.port());
    ASSERT_TRUE(WaitFor([&] { return c.failed_.load(); }));
    EXPECT_EQ(c.status_, 503);
  }
  a.reset();
  ASSERT_TRUE(WaitFor([&] { return server.counts().clients == 1; }));
  StreamClient d(server.port());
  ASSERT_TRUE(WaitFor([&] { return d.open_.load(); }));
  EXPECT_EQ(server.counts().refused_full, 1);
  EXPECT_EQ(server.counts().connections, 3);
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
  RawSocket stuck(server.port());
  stuck.Send(kHandshake);
  EXPECT_EQ(StatusLine(stuck.ReadHeaders()), "HTTP/1.1 101 Switching Protocols");
  StreamClient reader(server.port());
  ASSERT_TRUE(WaitFor([&] { return reader.open_.load(); }));
  // Large states (1 MB each) until the stuck client is dropped.
  std::int64_t tick = 0;
  const bool dropped = WaitFor([&] {
    StreamState state;
    state.tick = ++tick;
    state.actors.resize(12000, StreamState::Body{std::string(40, 'a')});
    server.Publish([state] { return EncodeState(state); });
    std::this_thread::sleep_for(10ms);
    return server.counts().dropped_slow == 1;
  });
  ASSERT_TRUE(dropped);
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
  EXPECT_EQ(json["actors"][0]["name"], "door");
  EXPECT_EQ(json["actors"][0]["p"][2], 6.0);
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
  EXPECT_EQ(model.triangles, model.source_triangles);  // under the budget: all of them
  Assimp::Importer importer;
  const aiScene* read = importer.ReadFileFromMemory(model.glb.data(), model.glb.size(), 0, "glb");
  ASSERT_NE(read, nullptr) << importer.GetErrorString();
  std::size_t faces = 0;
  for (unsigned m = 0; m < read->mNumMeshes; ++m) faces += read->mMeshes[m]->mNumFaces;
  EXPECT_EQ(faces, model.triangles);
  // Over a budget, simplified to about it.
  const LevelModel small = MakeLevelModel(level, 2000);
  EXPECT_LT(small.triangles, 2600u);
  EXPECT_GT(small.triangles, 100u);
}

}  // namespace
}  // namespace sandbox::web
