// Untrusted bytes and lcm-gen's decoders: what the generated encoder writes
// passes the layout check and decodes to the same message; every cut, every
// extra byte and every hostile count or string length is refused with a
// reason before the generated decoder (which throws, crashes or allocates
// gigabytes on such bytes) runs.

#include "bridge/checked_decode.h"

#include <gtest/gtest.h>

#include <climits>
#include <map>
#include <random>
#include <vector>

#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/air_data_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/imu_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/range_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "sandbox_msgs/surface_table_t.hpp"
#include "sandbox_msgs/wrench_t.hpp"

namespace sandbox::bridge {
namespace {

using Bytes = std::vector<std::uint8_t>;

template <typename Message>
Bytes Encode(const Message& message) {
  Bytes bytes(std::size_t(message.getEncodedSize()));
  EXPECT_EQ(message.encode(bytes.data(), 0, int(bytes.size())), int(bytes.size()));
  return bytes;
}

// Big-endian int32 at `at`.
void PutInt32(std::int32_t value, std::size_t at, Bytes* bytes) {
  for (int i = 3; i >= 0; --i, value = std::int32_t(std::uint32_t(value) >> 8)) {
    (*bytes)[at + std::size_t(i)] = std::uint8_t(value);
  }
}

// One message of every type, with arrays and strings of several lengths
// (including empty ones).
struct Samples {
  std::vector<std::pair<const char*, Bytes>> encoded;

  Samples() {
    using namespace sandbox_msgs;
    robot_pose_t pose{};
    pose.seq = 7, pose.position[2] = 60.0, pose.orientation[0] = 1.0;
    Add("robot_pose_t", pose);
    for (int n : {0, 1, 45}) {
      bone_values_t bones{};
      bones.num_values = n;
      bones.values.assign(std::size_t(n), 0.25);
      Add("bone_values_t", bones);
    }
    for (const std::vector<std::string>& names :
         {std::vector<std::string>{}, {"gate"}, {"", "a b", "tower"}}) {
      actor_placements_t actors{};
      actors.num_actors = int(names.size());
      actors.names = names;
      actors.num_positions = 3 * actors.num_actors;
      actors.positions.assign(std::size_t(actors.num_positions), 1.5);
      actors.num_orientations = 4 * actors.num_actors;
      actors.orientations.assign(std::size_t(actors.num_orientations), 0.5);
      Add("actor_placements_t", actors);
    }
    for (const char* name : {"", "belly"}) {
      camera_command_t camera{};
      camera.active_camera = name;
      camera.zoom = 2.0;
      Add("camera_command_t", camera);
    }
    ground_map_t ground{};
    ground.n = 3, ground.num_points = 9, ground.height.assign(9, 1.0f);
    ground.num_surface = 9, ground.surface.assign(9, 4);
    Add("ground_map_t", ground);
    for (int n : {0, 1, 4}) {
      imu_t imu{};
      imu.sensor = "imu";
      imu.num_samples = n, imu.sample_utime.assign(std::size_t(n), 1000);
      imu.num_xyz = 3 * n;
      imu.specific_force.assign(std::size_t(3 * n), 9.8);
      imu.angular_rate.assign(std::size_t(3 * n), 0.1);
      Add("imu_t", imu);
      gnss_t gnss{};
      gnss.sensor = "gps";
      gnss.num_fixes = n, gnss.fix_utime.assign(std::size_t(n), 2000);
      gnss.latitude_deg.assign(std::size_t(n), 47.0);
      gnss.longitude_deg.assign(std::size_t(n), 8.0);
      gnss.height_m.assign(std::size_t(n), 500.0);
      gnss.num_ned = 3 * n, gnss.velocity_ned.assign(std::size_t(3 * n), 1.5);
      Add("gnss_t", gnss);
      air_data_t air{};
      air.sensor = "adc";
      air.num_samples = n;
      for (auto* field :
           {&air.static_pressure_pa, &air.temperature_k, &air.density_kg_m3,
            &air.pressure_altitude_m, &air.impact_pressure_pa, &air.true_airspeed_m_s,
            &air.indicated_airspeed_m_s, &air.mach, &air.angle_of_attack_rad, &air.sideslip_rad}) {
        field->assign(std::size_t(n), 1.25);
      }
      air.sample_utime.assign(std::size_t(n), 3000);
      Add("air_data_t", air);
    }
    lidar_scan_t lidar{};
    lidar.channels = 2, lidar.steps = 3, lidar.num_beams = 6;
    lidar.range_m.assign(6, 10.0f), lidar.hit.assign(6, 1);
    lidar.num_xyz = 18, lidar.xyz.assign(18, 0.5f), lidar.time_s.assign(3, 0.01f);
    lidar.num_surface = 6, lidar.surface.assign(6, 2);
    lidar.num_normal = 18, lidar.normal.assign(18, 0.5f);
    lidar.num_intensity = 6, lidar.intensity.assign(6, 0.25f);
    lidar.num_last = 6, lidar.last_range_m.assign(6, 11.0f);
    lidar.num_last_xyz = 18, lidar.last_xyz.assign(18, 0.75f);
    lidar.num_last_surface = 6, lidar.last_surface.assign(6, 3);
    lidar.num_last_intensity = 6, lidar.last_intensity.assign(6, 0.125f);
    Add("lidar_scan_t", lidar);
    range_t range{};
    range.sensor = "altimeter", range.range_m = 12.0;
    Add("range_t", range);
    robot_state_t state{};
    state.num_values = 4, state.bone_values = {1, 0, 0, 0};
    Add("robot_state_t", state);
    scan_face_t face{};
    face.n = 2, face.num_points = 4, face.occupancy = {-1, 0, 1, 1};
    face.num_xyz = 12, face.xyz.assign(12, 2.0f);
    face.num_surface = 4, face.surface = {0, 0, 3, 5};
    face.num_normal = 12, face.normal.assign(12, 0.25f);
    Add("scan_face_t", face);
    scan_face_compact_t compact{};
    compact.n = 2, compact.encoding = 1, compact.num_mm = 4, compact.distance_mm = {1, -1, -2, 7};
    compact.num_runs = 2, compact.run_surface = {0, 3}, compact.run_length = {2, 2};
    Add("scan_face_compact_t", compact);
    status_t status{};
    status.num_channels = 2;
    status.channels = {"ELAHA/POSE", "ELAHA/BONES"};
    status.received = {10, 20}, status.superseded = {1, 2}, status.rejected = {0, 3};
    status.stale = {0, 1}, status.last_reject_reason = {"", "non-finite bone value"};
    Add("status_t", status);
    surface_table_t table{};
    table.num_surfaces = 2, table.id = {1, 5}, table.kind = {"actor", "bone"};
    table.name = {"terrain", "ELAHA/wing_left"}, table.actor = {0, -1};
    table.robot = {"", "ELAHA"}, table.bone = {"", "wing_left"};
    table.reflectivity = {0.3f, 0.5f};
    Add("surface_table_t", table);
    wrench_t wrench{};
    wrench.frame = "world";
    Add("wrench_t", wrench);
  }

  template <typename Message>
  void Add(const char* type, const Message& message) {
    encoded.emplace_back(type, Encode(message));
  }
};

// The checked decoder of each type, by name: its result, and the message
// encoded again.
struct Decoded {
  std::string problem;
  Bytes encoded_again;
};

template <typename Message>
Decoded DecodeAs(const std::uint8_t* data, std::size_t size) {
  Message message{};
  Decoded decoded{DecodeChecked(data, size, &message), {}};
  if (decoded.problem.empty()) decoded.encoded_again = Encode(message);
  return decoded;
}

Decoded Decode(const std::string& type, const std::uint8_t* data, std::size_t size) {
  using namespace sandbox_msgs;
  using Decoder = Decoded (*)(const std::uint8_t*, std::size_t);
  static const std::map<std::string, Decoder> decoders = {
      {"robot_pose_t", DecodeAs<robot_pose_t>},
      {"bone_values_t", DecodeAs<bone_values_t>},
      {"actor_placements_t", DecodeAs<actor_placements_t>},
      {"camera_command_t", DecodeAs<camera_command_t>},
      {"ground_map_t", DecodeAs<ground_map_t>},
      {"imu_t", DecodeAs<imu_t>},
      {"gnss_t", DecodeAs<gnss_t>},
      {"air_data_t", DecodeAs<air_data_t>},
      {"lidar_scan_t", DecodeAs<lidar_scan_t>},
      {"range_t", DecodeAs<range_t>},
      {"robot_state_t", DecodeAs<robot_state_t>},
      {"scan_face_t", DecodeAs<scan_face_t>},
      {"scan_face_compact_t", DecodeAs<scan_face_compact_t>},
      {"status_t", DecodeAs<status_t>},
      {"surface_table_t", DecodeAs<surface_table_t>},
      {"wrench_t", DecodeAs<wrench_t>}};
  return decoders.at(type)(data, size);
}

std::string Check(const std::string& type, const std::uint8_t* data, std::size_t size) {
  return Decode(type, data, size).problem;
}

TEST(CheckedDecodeTest, WhatTheEncoderWritesDecodesToTheSameMessage) {
  for (const auto& [type, bytes] : Samples().encoded) {
    const Decoded decoded = Decode(type, bytes.data(), bytes.size());
    EXPECT_EQ(decoded.problem, "") << type;
    EXPECT_EQ(decoded.encoded_again, bytes) << type;
  }
}

TEST(CheckedDecodeTest, EveryCutAndEveryExtraByteIsRefused) {
  for (const auto& [type, bytes] : Samples().encoded) {
    for (std::size_t n = 0; n < bytes.size(); ++n) {
      EXPECT_NE(Check(type, bytes.data(), n), "") << type << " cut to " << n << " bytes";
    }
    Bytes longer = bytes;
    longer.push_back(0);
    EXPECT_EQ(Check(type, longer.data(), longer.size()),
              std::string("cannot decode as ") + type + ": bytes after the message");
  }
}

TEST(CheckedDecodeTest, AnotherTypesBytesAreRefused) {
  const Samples samples;
  for (const auto& [type, bytes] : samples.encoded) {
    for (const auto& [other, ignored] : samples.encoded) {
      if (std::string(other) == type) continue;
      EXPECT_EQ(Check(other, bytes.data(), bytes.size()),
                std::string("cannot decode as ") + other + ": wrong fingerprint (another type?)");
    }
  }
}

TEST(CheckedDecodeTest, HostileCountsAreRefusedBeforeTheGeneratedDecoderSeesThem) {
  using namespace sandbox_msgs;
  bone_values_t bones{};
  bones.num_values = 2;
  bones.values = {0.1, 0.2};
  // The count sits after the fingerprint, utime and seq.
  Bytes negative = Encode(bones);
  PutInt32(-1, 24, &negative);
  bone_values_t decoded{};
  EXPECT_EQ(DecodeChecked(negative.data(), negative.size(), &decoded),
            "cannot decode as bone_values_t: num_values is negative");
  // What the generated decoder does with these bytes: it resizes first.
  EXPECT_THROW(decoded.decode(negative.data(), 0, int(negative.size())), std::length_error);
  Bytes huge = Encode(bones);
  PutInt32(INT_MAX, 24, &huge);
  EXPECT_EQ(DecodeChecked(huge.data(), huge.size(), &decoded),
            "cannot decode as bone_values_t: values runs past the end");

  // Strings: a length that counts no '\0', a negative one, one past the end,
  // and one whose last byte is not '\0'.
  actor_placements_t actors{};
  actors.num_actors = 1;
  actors.names = {"gate"};
  actors.num_positions = 3, actors.positions = {0, 0, 0};
  actors.num_orientations = 4, actors.orientations = {1, 0, 0, 0};
  const Bytes good = Encode(actors);
  const std::size_t length_at = 8 + 16 + 4;  // fingerprint, utime, seq, num_actors
  for (const auto& [length, reason] : std::vector<std::pair<std::int32_t, std::string>>{
           {0, "names has a string without its '\\0'"},
           {-5, "names is negative"},
           {1 << 30, "names runs past the end"},
           {4, "names has a string without its '\\0'"}}) {
    Bytes bad = good;
    PutInt32(length, length_at, &bad);
    EXPECT_EQ(CheckLayout<actor_placements_t>(bad.data(), bad.size()),
              "cannot decode as actor_placements_t: " + reason)
        << length;
  }
  // A count of a hundred million names in a 100-byte message.
  Bytes many = good;
  PutInt32(100000000, 24, &many);
  EXPECT_NE(CheckLayout<actor_placements_t>(many.data(), many.size()), "");
  // status_t: every per-channel array counts against the bytes.
  status_t status{};
  Bytes channels = Encode(status);
  PutInt32(1 << 20, 8 + 40, &channels);
  EXPECT_EQ(CheckLayout<status_t>(channels.data(), channels.size()),
            "cannot decode as status_t: too short for channels");
}

TEST(CheckedDecodeTest, MutatedMessagesEitherPassAndDecodeExactlyOrAreRefused) {
  // A short deterministic fuzz (the fuzz targets in tests/fuzz run longer):
  // whatever the check lets through, the generated decoder reads exactly.
  std::mt19937 random(11);
  const Samples samples;
  int passed = 0, refused = 0;
  for (int round = 0; round < 20000; ++round) {
    const auto& [type, original] = samples.encoded[random() % samples.encoded.size()];
    Bytes bytes = original;
    const int flips = 1 + int(random() % 4);
    for (int i = 0; i < flips && !bytes.empty(); ++i) {
      bytes[random() % bytes.size()] = std::uint8_t(random());
    }
    const Decoded decoded = Decode(type, bytes.data(), bytes.size());
    if (decoded.problem.empty()) {
      ++passed;
      // It was read exactly: encoding it again gives the same bytes.
      EXPECT_EQ(decoded.encoded_again, bytes) << type;
    } else {
      ++refused;
    }
  }
  // Both outcomes happen: the mutations reach the counts and the values.
  EXPECT_GT(passed, 1000);
  EXPECT_GT(refused, 1000);
}

}  // namespace
}  // namespace sandbox::bridge
