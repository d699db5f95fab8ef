// The UDP adapters on 127.0.0.1: FlightGear net_fdm and a vector of doubles.

#include "bridge/udp_inputs.h"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstring>

#include "scene/level.h"
#include "tests/test_util.h"

namespace sandbox::bridge {
namespace {

using Eigen::Vector3d;

void Send(int port, const void* data, std::size_t size) {
  const int s = ::socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(static_cast<std::uint16_t>(port));
  inet_pton(AF_INET, "127.0.0.1", &to.sin_addr);
  ASSERT_EQ(::sendto(s, data, size, 0, reinterpret_cast<sockaddr*>(&to), sizeof(to)),
            ssize_t(size));
  ::close(s);
}

scene::Level WingLevel(const testing::TempDir& dir, const std::string& bridge) {
  const std::string wing =
      (std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/robots/generated/flying_wing.gltf")
          .string();
  return scene::LoadLevel(dir.Write(
      "level.toml",
      "[[robot]]\nname = \"W\"\nfile = \"" + wing +
          "\"\nbones = [\"root\", \"R1\", \"E1\"]\nrotation = \"angles\"\nangle_axes = [\"y\"]\n"
          "\n[robot.bridge]\n" +
          bridge));
}

TEST(UdpInputsTest, NetFdmDrivesPoseAndControlSurfaces) {
  testing::TempDir dir;
  const int port = testing::FreeUdpPort();
  const scene::Level level = WingLevel(
      dir, "geodetic_origin = [47.0, 8.0, 500.0]\nnet_fdm_port = " + std::to_string(port) +
               "\nnet_fdm_elevator = [\"E1\"]\nnet_fdm_max_deflection_deg = 20\n");
  const RobotBridgeConfig config = RobotBridgeConfig::FromModel(level.robots[0]);
  NetFdmInput input(config);
  scene::RobotState state(level.robots[0]);
  NetFdm fdm;
  fdm.latitude_rad = (47.0 + 1.0 / 3600.0) * M_PI / 180.0;  // 30.87 m north
  fdm.longitude_rad = 8.0 * M_PI / 180.0;
  fdm.altitude_m = 600.0;         // 100 m up
  fdm.psi_rad = float(M_PI / 2);  // heading east
  fdm.elevator = 0.5f;
  fdm.cur_time = 1'700'000'000;                  // the sender's clock, whole seconds since 1970
  for (const float lat_offset : {0.0f, 1.0f}) {  // two packets: the newest wins
    NetFdm sent = fdm;
    sent.latitude_rad += lat_offset * 1e-9;
    const std::vector<std::uint8_t> bytes = EncodeNetFdm(sent);
    Send(port, bytes.data(), bytes.size());
  }
  usleep(20000);
  ASSERT_TRUE(input.Apply(&state));
  EXPECT_EQ(input.socket().received(), 2);
  EXPECT_EQ(input.socket().superseded(), 1);
  EXPECT_EQ(input.last_tag().utime, 1'700'000'000'000'000);  // the packet's own time
  EXPECT_EQ(input.last_tag().seq, -1);                       // the format has no counter
  // North: the meridian radius of curvature at 47 degrees (plus the altitude)
  // times the latitude step.
  const double e2 = 0.00669437999014, s47 = std::sin(47.0 * M_PI / 180.0);
  const double meridian = 6378137.0 * (1 - e2) / std::pow(1 - e2 * s47 * s47, 1.5);
  const double step = (1.0 / 3600.0) * M_PI / 180.0 + 1e-9;
  EXPECT_NEAR(state.pose().translation().y(), (meridian + 600.0) * step, 2e-3);
  EXPECT_NEAR(state.pose().translation().z(), 100.0, 0.01);
  EXPECT_TRUE((state.pose().linear() * Vector3d::UnitX()).isApprox(Vector3d::UnitX(), 1e-5));
  state.Update();
  const int e1 = level.robots[0].bones[2].node;
  // Elevator 0.5 of 20 degrees, about the bone's y axis.
  const Eigen::AngleAxisd turned(level.robots[0].nodes[std::size_t(e1)].X_PN.linear().transpose() *
                                 Eigen::Matrix3d(state.node_poses_B()[std::size_t(e1)].linear()));
  EXPECT_NEAR(turned.angle(), 10.0 * M_PI / 180.0, 1e-4);
  // Bad packets: the size and the version, counted, the pose kept.
  std::vector<std::uint8_t> bytes = EncodeNetFdm(fdm);
  Send(port, bytes.data(), 100);
  usleep(20000);
  EXPECT_FALSE(input.Apply(&state));
  EXPECT_EQ(input.socket().last_reject_reason(), "408 bytes expected, got 100");
  bytes[3] = 23;
  Send(port, bytes.data(), bytes.size());
  usleep(20000);
  EXPECT_FALSE(input.Apply(&state));
  EXPECT_EQ(input.socket().last_reject_reason(), "version 24 expected, got 23");
  EXPECT_EQ(input.socket().rejected(), 2);
  EXPECT_NEAR(state.pose().translation().z(), 100.0, 0.01);
  // Finite but nowhere: latitude 1e300 rad, altitude 1e308 m; counted, the pose kept.
  NetFdm nowhere = fdm;
  nowhere.latitude_rad = 1e300;
  bytes = EncodeNetFdm(nowhere);
  Send(port, bytes.data(), bytes.size());
  usleep(20000);
  EXPECT_FALSE(input.Apply(&state));
  EXPECT_EQ(input.socket().last_reject_reason(), "latitude beyond +-pi/2 rad");
  nowhere = fdm;
  nowhere.altitude_m = 1e308;
  bytes = EncodeNetFdm(nowhere);
  Send(port, bytes.data(), bytes.size());
  usleep(20000);
  EXPECT_FALSE(input.Apply(&state));
  EXPECT_EQ(input.socket().last_reject_reason(), "altitude outside -12 km to 1e8 m");
  EXPECT_EQ(input.socket().rejected(), 4);
  EXPECT_NEAR(state.pose().translation().z(), 100.0, 0.01);
}

TEST(UdpInputsTest, DoublesInTheConfiguredLayout) {
  testing::TempDir dir;
  const int port = testing::FreeUdpPort();
  const scene::Level level = WingLevel(dir, "udp_doubles_port = " + std::to_string(port) +
                                                "\nudp_doubles_layout = [\"position\", \"rpy\", "
                                                "\"bones\"]\nudp_doubles_big_endian = true\n");
  const RobotBridgeConfig config = RobotBridgeConfig::FromModel(level.robots[0]);
  DoublesInput input(config, level.robots[0]);
  ASSERT_EQ(input.expected_doubles(), 3u + 3u + 3u);
  scene::RobotState state(level.robots[0]);
  const double values[9] = {1, 2, 3, 0, 0, M_PI / 2, 0.1, 0.2, 0.3};
  std::uint8_t bytes[72];
  for (int i = 0; i < 9; ++i) {
    std::uint8_t b[8];
    std::memcpy(b, &values[i], 8);
    for (int k = 0; k < 8; ++k) bytes[8 * i + k] = b[7 - k];  // big-endian
  }
  Send(port, bytes, sizeof(bytes));
  usleep(20000);
  ASSERT_TRUE(input.Apply(&state));
  EXPECT_TRUE(state.pose().translation().isApprox(Vector3d(1, 2, 3)));
  EXPECT_TRUE((state.pose().linear() * Vector3d::UnitX()).isApprox(Vector3d::UnitY(), 1e-12));
  Send(port, bytes, 64);
  usleep(20000);
  EXPECT_FALSE(input.Apply(&state));
  EXPECT_EQ(input.socket().last_reject_reason(), "expected 9 doubles (72 bytes), got 64 bytes");
  // A good packet and then garbage before the next tick: the good one applies.
  std::uint8_t moved[72];
  std::memcpy(moved, bytes, sizeof(moved));
  const double x = 7.0;
  std::uint8_t b[8];
  std::memcpy(b, &x, 8);
  for (int k = 0; k < 8; ++k) moved[k] = b[7 - k];
  Send(port, moved, sizeof(moved));
  Send(port, bytes, 10);
  usleep(20000);
  ASSERT_TRUE(input.Apply(&state));
  EXPECT_TRUE(state.pose().translation().isApprox(Vector3d(7, 2, 3)));
  EXPECT_EQ(input.socket().rejected(), 2);
}

TEST(UdpInputsTest, DoublesCarryTheirOwnTimeAndSequenceNumber) {
  testing::TempDir dir;
  const int port = testing::FreeUdpPort();
  const scene::Level level = WingLevel(dir, "udp_doubles_port = " + std::to_string(port) +
                                                "\nudp_doubles_layout = [\"time\", \"seq\", "
                                                "\"position\"]\n");
  const RobotBridgeConfig config = RobotBridgeConfig::FromModel(level.robots[0]);
  DoublesInput input(config, level.robots[0]);
  ASSERT_EQ(input.expected_doubles(), 1u + 1u + 3u);
  EXPECT_EQ(input.last_tag().seq, -1);  // nothing applied yet
  scene::RobotState state(level.robots[0]);
  const double packet[5] = {12.5, 41, 1, 2, 3};  // 12.5 s on the sender's clock, its packet 41
  Send(port, packet, sizeof(packet));
  usleep(20000);
  ASSERT_TRUE(input.Apply(&state));
  EXPECT_EQ(input.last_tag().seq, 41);
  EXPECT_EQ(input.last_tag().utime, 12'500'000);
  const double bad_seq[5] = {13, 41.5, 1, 2, 3};
  Send(port, bad_seq, sizeof(bad_seq));
  usleep(20000);
  EXPECT_FALSE(input.Apply(&state));
  EXPECT_EQ(input.socket().last_reject_reason(), "seq must be a whole number from 0");
  EXPECT_EQ(input.last_tag().seq, 41);  // the last good packet's
  const double bad_time[5] = {-1, 42, 1, 2, 3};
  Send(port, bad_time, sizeof(bad_time));
  usleep(20000);
  EXPECT_FALSE(input.Apply(&state));
  EXPECT_EQ(input.socket().last_reject_reason(), "time must be 0 to 9.2e12 s");
}

TEST(UdpInputsTest, GeodeticDoublesBeyondTheEarthAreRejectedAndCounted) {
  testing::TempDir dir;
  const int port = testing::FreeUdpPort();
  const scene::Level level =
      WingLevel(dir, "udp_doubles_port = " + std::to_string(port) +
                         "\nudp_doubles_layout = [\"position\"]\npose_convention = \"geodetic\"\n"
                         "geodetic_origin = [47.0, 8.0, 500.0]\n");
  DoublesInput input(RobotBridgeConfig::FromModel(level.robots[0]), level.robots[0]);
  scene::RobotState state(level.robots[0]);
  const double good[3] = {47.0, 8.0, 600.0};
  Send(port, good, sizeof(good));
  usleep(20000);
  ASSERT_TRUE(input.Apply(&state));
  EXPECT_NEAR(state.pose().translation().z(), 100.0, 0.01);
  for (const auto& [packet, reason] : {std::pair<std::array<double, 3>, std::string>{
                                           {1e300, 8.0, 600.0}, "latitude beyond +-90 deg"},
                                       {{47.0, 8.0, 1e308}, "altitude outside -12 km to 1e8 m"},
                                       {{47.0, 1e5, 600.0}, "longitude beyond +-360 deg"}}) {
    Send(port, packet.data(), sizeof(double) * 3);
    usleep(20000);
    EXPECT_FALSE(input.Apply(&state));
    EXPECT_EQ(input.socket().last_reject_reason(), reason);
  }
  EXPECT_EQ(input.socket().rejected(), 3);
  EXPECT_NEAR(state.pose().translation().z(), 100.0, 0.01);  // the last good pose
}

TEST(UdpInputsTest, BridgeSettingsMistakes) {
  testing::TempDir dir;
  auto error = [&](const std::string& bridge) {
    try {
      RobotBridgeConfig::FromModel(WingLevel(dir, bridge).robots[0]);
    } catch (const scene::LevelError& e) {
      const std::string message = e.what();
      return message.substr(message.find("level.toml"));
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("pose_convention = \"nwu\"\n"),
            "level.toml:9: robot 'W' bridge: 'pose_convention' must be enu, ned, unreal or "
            "geodetic, got 'nwu'");
  EXPECT_EQ(error("net_fdm_port = 70000\n"),
            "level.toml:9: robot 'W' bridge: 'net_fdm_port' must be a port, 0 to 65535");
  EXPECT_EQ(error("net_fdm_rudder = [\"R9\"]\n"),
            "level.toml:9: robot 'W' bridge: 'net_fdm_rudder' names bone 'R9', which is not in "
            "the bone map");
  EXPECT_EQ(error("chanel_prefix = \"X\"\n"),
            "level.toml:9: robot 'W' bridge: unknown key 'chanel_prefix' for a robot bridge");
}

}  // namespace
}  // namespace sandbox::bridge
