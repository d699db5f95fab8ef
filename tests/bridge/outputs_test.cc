// Outputs over LCM (memq://, one process): what a subscriber decodes is what
// the sensor measured, on <ROBOT>/<TOPIC>, tagged with its input.

#include "bridge/outputs.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "bridge/checked_decode.h"
#include "bridge/face_points.h"
#include "bridge/lcm_link.h"
#include "bridge/robot_bridge_config.h"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/imu_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/range_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sandbox_msgs/scan_face_t.hpp"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "sensors/face_scanner.h"
#include "sensors/range_sensor.h"
#include "sensors/sensor.h"
#include "tests/test_util.h"

namespace sandbox::bridge {
namespace {

TEST(RobotOutputsTest, RangeReadingArrivesOnItsChannelWithItsSensorAndInput) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  sensors::RayCaster caster;
  LcmLink link("memq://");
  LatestInput subscriber(link, "ELAHA/RANGE");
  RobotOutputs outputs(link, "ELAHA");

  // Straight down from 500 m: the sample terrain is below, well within range.
  sensors::RangeSensorConfig altimeter;
  altimeter.range_m = 1000.0;
  const Eigen::Isometry3d X_WS(Eigen::Translation3d(3.0, -4.0, 500.0));
  const sensors::RangeReading reading = sensors::MeasureRange(altimeter, world, caster, {}, X_WS);
  ASSERT_TRUE(reading.hit);
  outputs.Publish(reading, {"altimeter", "RANGE"}, 0, InputTag{42, 4200}, 123456);
  link.Drain();

  const std::vector<std::uint8_t>* bytes = subscriber.TakeNewest();
  ASSERT_NE(bytes, nullptr);
  sandbox_msgs::range_t message;
  ASSERT_EQ(message.decode(bytes->data(), 0, int(bytes->size())), int(bytes->size()));
  EXPECT_EQ(message.sensor, "altimeter");
  EXPECT_EQ(message.utime, 123456);
  EXPECT_EQ(message.input_seq, 42);
  EXPECT_EQ(message.input_utime, 4200);
  EXPECT_EQ(message.hit, 1);
  EXPECT_EQ(message.surface, reading.surface);
  // The ray as mounted, and the point where it stopped on it.
  EXPECT_DOUBLE_EQ(message.origin[0], 3.0);
  EXPECT_DOUBLE_EQ(message.origin[1], -4.0);
  EXPECT_DOUBLE_EQ(message.origin[2], 500.0);
  EXPECT_DOUBLE_EQ(message.direction[2], -1.0);
  EXPECT_NEAR(message.point[0], 3.0, 1e-4);
  EXPECT_NEAR(message.point[1], -4.0, 1e-4);
  EXPECT_NEAR(message.point[2], 500.0 - message.range_m, 1e-3);
  EXPECT_GT(message.normal[2], 0.0);  // the ground faces up
  EXPECT_EQ(outputs.published(), 1);
}

// Decodes the newest message of `input` as a Message; false when there is none.
template <typename Message>
bool Newest(LatestInput& input, Message* message) {
  const std::vector<std::uint8_t>* bytes = input.TakeNewest();
  return bytes != nullptr &&
         message->decode(bytes->data(), 0, int(bytes->size())) == int(bytes->size());
}

// Every kind's output goes out through the one Publish call, on its kind's
// channel, as its own message type.
TEST(RobotOutputsTest, AnyKindOfOutputGoesOutThroughOneCall) {
  LcmLink link("memq://");
  LatestInput face(link, "W/SCAN_FACE"), ground(link, "W/GROUND"), lidar(link, "W/LIDAR"),
      range(link, "W/RANGE");
  RobotOutputs outputs(link, "W");
  std::vector<sensors::SensorOutput> all(sensors::kSensorKinds.size());
  sensors::FaceScan scan;
  scan.n = 1;
  scan.half_extent_m = 0.0;  // one sample, on the box's axis
  scan.faces[4].tick = 3;    // the +Z face, scanned at tick 3
  scan.faces[4].occupancy = {sensors::kOccupied};
  scan.faces[4].X_WS = scan.faces[4].X_WB = Eigen::Isometry3d(Eigen::Translation3d(1, 2, 0));
  scan.faces[4].distance_m = {3.0f};  // the point (1, 2, 3)
  all[std::size_t(sensors::SensorKind::kFace)] = scan;
  sensors::HeightMap map;
  map.n = 1;
  map.height_m = {7.5};
  all[std::size_t(sensors::SensorKind::kGround)] = map;
  sensors::LidarScan sweep;
  sweep.channels = 1, sweep.azimuth_steps = 2;
  sweep.range_m = {4.0f, 5.0f};
  sweep.hit = {1, 0};
  sweep.points_W = {Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero()};
  sweep.time_s = {0.0, 0.05};
  all[std::size_t(sensors::SensorKind::kLidar)] = sweep;
  sensors::RangeReading reading;
  reading.range_m = 12.0;
  all[std::size_t(sensors::SensorKind::kRange)] = reading;
  for (const sensors::SensorKindInfo& kind : sensors::kSensorKinds) {
    outputs.Publish(all[std::size_t(kind.kind)],
                    {std::string(kind.type) + "_sensor", std::string(kind.channel)}, 3,
                    InputTag{9, 900}, 1000);
  }
  link.Drain();
  EXPECT_EQ(outputs.published(), 4);
  sandbox_msgs::scan_face_t f;
  ASSERT_TRUE(Newest(face, &f));
  EXPECT_EQ(f.face, 4);
  EXPECT_EQ(f.tick, 3);
  EXPECT_EQ(f.occupancy, std::vector<std::int8_t>{sensors::kOccupied});
  EXPECT_EQ(f.xyz, (std::vector<float>{0.0f, 0.0f, 3.0f}));  // from the sensor at (1, 2, 0)
  sandbox_msgs::ground_map_t g;
  ASSERT_TRUE(Newest(ground, &g));
  EXPECT_EQ(g.height, std::vector<float>{7.5f});
  sandbox_msgs::lidar_scan_t l;
  ASSERT_TRUE(Newest(lidar, &l));
  EXPECT_EQ(l.range_m, (std::vector<float>{4.0f, 5.0f}));
  sandbox_msgs::range_t r;
  ASSERT_TRUE(Newest(range, &r));
  EXPECT_EQ(r.sensor, "ray_sensor");
  EXPECT_EQ(r.range_m, 12.0);
  for (const std::int64_t input_seq : {f.input_seq, g.input_seq, l.input_seq, r.input_seq}) {
    EXPECT_EQ(input_seq, 9);
  }
}

// The sample level's wing with extra [[robot.sensor]] tables appended.
scene::Level WingWith(testing::TempDir& dir, const std::string& sensors) {
  const std::string wing =
      (std::filesystem::path(SANDBOX_SOURCE_DIR) / "assets/robots/generated/flying_wing.gltf")
          .string();
  return scene::LoadLevel(dir.Write("level.toml", "[[robot]]\nname = \"W\"\nfile = \"" + wing +
                                                      "\"\nbones = [\"root\"]\n" + sensors));
}

TEST(RobotOutputsTest, StateEchoesThePoseAndTheBoneValuesInUse) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  scene::RobotState wing(level.robots[0]);
  std::vector<double> values(std::size_t(level.robots[0].num_values), 0.0);
  for (std::size_t i = 0; i < values.size(); ++i) values[i] = 0.001 * double(i);
  ASSERT_TRUE(wing.SetBones(values));
  values[3] = std::nan("");
  EXPECT_FALSE(wing.SetBones(values));  // rejected: the echo keeps the last good values
  wing.Update();
  LcmLink link("memq://");
  LatestInput subscriber(link, "ELAHA/STATE");
  RobotOutputs outputs(link, "ELAHA");
  outputs.PublishState(wing, InputTag{7, 700}, 1000);
  link.Drain();
  const std::vector<std::uint8_t>* bytes = subscriber.TakeNewest();
  ASSERT_NE(bytes, nullptr);
  sandbox_msgs::robot_state_t message;
  ASSERT_EQ(message.decode(bytes->data(), 0, int(bytes->size())), int(bytes->size()));
  ASSERT_EQ(message.num_values, level.robots[0].num_values);
  for (int i = 0; i < message.num_values; ++i) {
    EXPECT_EQ(message.bone_values[std::size_t(i)], 0.001 * i) << i;
  }
  EXPECT_EQ(message.input_seq, 7);
}

TEST(RobotOutputsTest, EachChannelCountsItsOwnMessages) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  scene::RobotState wing(level.robots[0]);
  LcmLink link("memq://");
  LatestInput range(link, "ELAHA/RANGE"), state(link, "ELAHA/STATE");
  RobotOutputs outputs(link, "ELAHA");
  sensors::RangeReading reading;
  std::vector<std::int64_t> range_seqs, state_seqs;
  for (int i = 0; i < 3; ++i) {
    outputs.Publish(reading, {"a", "RANGE"}, i, InputTag{i, i}, 1000 + i);
    outputs.PublishState(wing, InputTag{i, i}, 1000 + i);
    outputs.Publish(reading, {"b", "RANGE"}, i, InputTag{i, i},
                    1000 + i);  // a second sensor, same channel
    link.Drain();
    sandbox_msgs::range_t r;
    const std::vector<std::uint8_t>* bytes = range.TakeNewest();
    ASSERT_NE(bytes, nullptr);
    ASSERT_EQ(r.decode(bytes->data(), 0, int(bytes->size())), int(bytes->size()));
    range_seqs.push_back(r.seq);
    sandbox_msgs::robot_state_t s;
    bytes = state.TakeNewest();
    ASSERT_NE(bytes, nullptr);
    ASSERT_EQ(s.decode(bytes->data(), 0, int(bytes->size())), int(bytes->size()));
    state_seqs.push_back(s.seq);
  }
  EXPECT_EQ(range_seqs, (std::vector<std::int64_t>{1, 3, 5}));  // the newest of each two
  EXPECT_EQ(state_seqs, (std::vector<std::int64_t>{0, 1, 2}));
}

// The instruments: a message a run that brought samples (none for a run
// without), every sample in it, the sensor named.
TEST(RobotOutputsTest, InstrumentsPublishTheirSamplesBatched) {
  LcmLink link("memq://");
  LatestInput imu_in(link, "W/IMU"), gnss_in(link, "W/GNSS");
  RobotOutputs outputs(link, "W");
  sensors::ImuSamples samples;
  outputs.Publish(samples, {"imu1", "IMU"}, 0, InputTag{3, 30}, 40);
  samples.utime = {10, 20};
  samples.specific_force_S = {Eigen::Vector3d(1, 2, 3), Eigen::Vector3d(4, 5, 6)};
  samples.angular_rate_S = {Eigen::Vector3d(0.1, 0.2, 0.3), Eigen::Vector3d(0.4, 0.5, 0.6)};
  outputs.Publish(samples, {"imu1", "IMU"}, 1, InputTag{4, 40}, 50);
  sensors::GnssFixes fixes;
  fixes.fixes.push_back({7, 47.5, 8.25, 612.5, Eigen::Vector3d(1.0, -2.0, 0.5)});
  outputs.Publish(fixes, {"gps", "GNSS"}, 1, InputTag{4, 40}, 50);
  link.Drain();
  sandbox_msgs::imu_t imu;
  const std::vector<std::uint8_t>* bytes = imu_in.TakeNewest();
  ASSERT_NE(bytes, nullptr);
  ASSERT_EQ(DecodeChecked(bytes->data(), bytes->size(), &imu), "");
  EXPECT_EQ(imu_in.received(), 1);  // the empty run sent nothing
  EXPECT_EQ(imu.sensor, "imu1");
  EXPECT_EQ(imu.input_utime, 40);
  EXPECT_EQ(imu.sample_utime, (std::vector<std::int64_t>{10, 20}));
  EXPECT_EQ(imu.specific_force, (std::vector<double>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(imu.angular_rate, (std::vector<double>{0.1, 0.2, 0.3, 0.4, 0.5, 0.6}));
  sandbox_msgs::gnss_t gnss;
  bytes = gnss_in.TakeNewest();
  ASSERT_NE(bytes, nullptr);
  ASSERT_EQ(DecodeChecked(bytes->data(), bytes->size(), &gnss), "");
  EXPECT_EQ(gnss.sensor, "gps");
  EXPECT_EQ(gnss.fix_utime, (std::vector<std::int64_t>{7}));
  EXPECT_EQ(gnss.latitude_deg[0], 47.5);
  EXPECT_EQ(gnss.longitude_deg[0], 8.25);
  EXPECT_EQ(gnss.height_m[0], 612.5);
  EXPECT_EQ(gnss.velocity_ned, (std::vector<double>{1.0, -2.0, 0.5}));
}

// A GNSS receiver needs the world's geodetic anchor: refused at load without
// one, naming the line of its type; a robot's geodetic_origin gives one.
TEST(RobotOutputsTest, AGnssWithoutAGeodeticAnchorIsRefusedAtLoad) {
  testing::TempDir dir;
  const std::string gnss = "[[robot.sensor]]\nname = \"gps\"\ntype = \"gnss\"\n";
  try {
    RobotBridgeConfigs(WingWith(dir, gnss));
    ADD_FAILURE() << "a gnss sensor without an anchor was accepted";
  } catch (const scene::LevelError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("level.toml:7: sensor 'gps': a gnss sensor needs the world's geodetic "
                           "anchor: give the level a [[terrain]] (its anchor) or a robot a "
                           "geodetic_origin"),
              std::string::npos)
        << message;
  }
  const scene::Level level =
      WingWith(dir, gnss + "[robot.bridge]\ngeodetic_origin = [47.0, 8.0, 500.0]\n");
  const std::vector<RobotBridgeConfig> configs = RobotBridgeConfigs(level);
  const auto anchor = WorldAnchor(level, configs);
  ASSERT_TRUE(anchor.has_value());
  EXPECT_EQ(anchor->latitude_deg, 47.0);
  EXPECT_EQ(anchor->height_m, 500.0);
}

TEST(RobotOutputsTest, TwoSensorsOfATypeNeedTheirOwnChannels) {
  testing::TempDir dir;
  const std::string face =
      "[[robot.sensor]]\nname = \"nose\"\ntype = \"face\"\n"
      "[[robot.sensor]]\nname = \"tail\"\ntype = \"face\"\n";
  try {
    CheckOutputChannels(WingWith(dir, face));
    ADD_FAILURE() << "two face scanners on one channel were accepted";
  } catch (const scene::LevelError& error) {
    const std::string message = error.what();
    EXPECT_NE(message.find("sensor 'tail': publishes on SCAN_FACE like sensor 'nose'; give one of "
                           "them its own 'channel'"),
              std::string::npos)
        << message;
  }
  // With a channel of its own the second scanner publishes there.
  const scene::Level level = WingWith(dir, face +
                                               "channel = \"SCAN_FACE_TAIL\"\n"
                                               "[[robot.sensor]]\nname = \"a1\"\ntype = \"ray\"\n"
                                               "[[robot.sensor]]\nname = \"a2\"\ntype = \"ray\"\n");
  EXPECT_NO_THROW(CheckOutputChannels(level));  // range sensors share RANGE: they say their names
  EXPECT_EQ(sensors::OutputChannel(level.robots[0].sensors[1]), "SCAN_FACE_TAIL");
  LcmLink link("memq://");
  LatestInput own(link, "W/SCAN_FACE_TAIL"), shared(link, "W/SCAN_FACE");
  RobotOutputs outputs(link, "W");
  sensors::FaceScan scan;
  scan.n = 1;
  scan.faces[2].tick = 5;
  scan.faces[2].occupancy = {sensors::kFree};
  scan.faces[2].distance_m = {25.0f};
  outputs.Publish(scan, {"tail", sensors::OutputChannel(level.robots[0].sensors[1])}, 5, {}, 0);
  link.Drain();
  EXPECT_NE(own.TakeNewest(), nullptr);
  EXPECT_EQ(shared.TakeNewest(), nullptr);
}

TEST(RobotOutputsTest, ChannelMistakesAreNamed) {
  testing::TempDir dir;
  try {
    WingWith(dir, "[[robot.camera]]\nname = \"c\"\ntype = \"chase\"\nchannel = \"CAM\"\n");
    ADD_FAILURE() << "a camera channel was accepted";
  } catch (const scene::LevelError& error) {
    EXPECT_NE(std::string(error.what()).find("camera 'c': a camera publishes no channel"),
              std::string::npos)
        << error.what();
  }
  try {
    WingWith(dir, "[[robot.sensor]]\nname = \"s\"\ntype = \"face\"\nchannel = \"MY SCAN\"\n");
    ADD_FAILURE() << "a channel with a space was accepted";
  } catch (const scene::LevelError& error) {
    EXPECT_NE(
        std::string(error.what()).find("'channel' must be a name without spaces, got 'MY SCAN'"),
        std::string::npos)
        << error.what();
  }
}

}  // namespace
}  // namespace sandbox::bridge

namespace sandbox::bridge {
namespace {

// A full scan of the sample level from above the valley, in `encoding`.
sensors::FaceScan SampleScan(sensors::FaceEncoding encoding, double resolution_m,
                             double half_extent_m, const Eigen::Isometry3d& X_WS) {
  const scene::Level level = scene::LoadLevel(testing::SampleLevel());
  const scene::CollisionWorld world(level);
  sensors::FaceScannerConfig config;
  config.refresh = sensors::Refresh::kFull;
  config.resolution_m = resolution_m;
  config.half_extent_m = half_extent_m;
  config.encoding = encoding;
  const sensors::FaceScanner scanner(config);
  sensors::RayCaster caster(1);
  sensors::FaceScan scan = scanner.EmptyScan();
  scanner.Scan(world, caster, {}, X_WS, 7, &scan);
  return scan;
}

TEST(CompactFaceTest, DecodedPointsAreTheScannersPoints) {
  const Eigen::Isometry3d X_WS(Eigen::Translation3d(20, -25, 22) *
                               Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                               Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitX()));
  for (const auto& [encoding, tolerance_m] :
       {std::pair{sensors::FaceEncoding::kMillimetres, 0.5e-3 + 1e-5},
        std::pair{sensors::FaceEncoding::kFloat, 1e-5}}) {
    const sensors::FaceScan scan = SampleScan(encoding, 0.5, 25.0, X_WS);
    sensors::FaceScan scan_without_ids = scan;
    scan_without_ids.surface_ids = false;
    int occupied = 0, free = 0;
    double worst_m = 0.0;
    for (int f = 0; f < 6; ++f) {
      sandbox_msgs::scan_face_compact_t message{};
      EncodeCompactFace(scan, f, &message);
      const FacePoints decoded = DecodeCompactFace(message);
      const sensors::ScanFace& face = scan.faces[std::size_t(f)];
      ASSERT_EQ(decoded.occupancy, face.occupancy) << "face " << f;
      ASSERT_EQ(decoded.surface, face.surface) << "face " << f;  // the id plane, whole
      scan_without_ids.faces[std::size_t(f)] = face;
      EncodeCompactFace(scan_without_ids, f, &message);
      EXPECT_EQ(message.num_runs, 0);
      EXPECT_TRUE(DecodeCompactFace(message).surface.empty());
      for (std::size_t k = 0; k < face.distance_m.size(); ++k) {
        worst_m = std::max(worst_m, (decoded.points_W[k] - scan.PointW(f, k)).norm());
        occupied += face.occupancy[k] == sensors::kOccupied;
        free += face.occupancy[k] == sensors::kFree;
      }
    }
    EXPECT_LE(worst_m, tolerance_m);
    EXPECT_GT(occupied, 5000);  // the valley below and beside
    EXPECT_GT(free, 5000);      // the sky
  }
}

TEST(CompactFaceTest, DistancesBeyondTheMillimetreRangeAreMarkedNeverWrapped) {
  // 90 m above the ground with a 100 m box: the ground below is beyond 65.532 m.
  const sensors::FaceScan scan = SampleScan(sensors::FaceEncoding::kMillimetres, 10.0, 100.0,
                                            Eigen::Isometry3d(Eigen::Translation3d(0, 0, 100)));
  sandbox_msgs::scan_face_compact_t message{};
  EncodeCompactFace(scan, 5, &message);  // -Z
  const sensors::ScanFace& face = scan.faces[5];
  int beyond = 0;
  for (std::size_t k = 0; k < face.distance_m.size(); ++k) {
    const auto code = std::uint16_t(message.distance_mm[k]);
    if (face.occupancy[k] != sensors::kOccupied) continue;
    if (face.distance_m[k] > 65.5325f) {
      EXPECT_EQ(code, kBeyondMm) << k;
      ++beyond;
    } else {
      EXPECT_NEAR(1e-3 * code, face.distance_m[k], 0.5e-3) << k;
    }
  }
  EXPECT_GT(beyond, 100);
  const FacePoints decoded = DecodeCompactFace(message);
  for (std::size_t k = 0; k < face.distance_m.size(); ++k) {
    if (std::uint16_t(message.distance_mm[k]) != kBeyondMm) continue;
    EXPECT_EQ(decoded.occupancy[k], sensors::kOccupied);
    EXPECT_TRUE(std::isnan(decoded.points_W[k].x()));
  }
}

// Crafted messages that pass the layout check (DecodeChecked) but are not
// faces: refused by the decoder before it allocates, the field named.
TEST(CompactFaceTest, AMessageThatIsNotAFaceIsRefusedBeforeAnythingIsAllocated) {
  const auto through_the_wire = [](const sandbox_msgs::scan_face_compact_t& message) {
    std::vector<std::uint8_t> bytes(std::size_t(message.getEncodedSize()));
    message.encode(bytes.data(), 0, int(bytes.size()));
    sandbox_msgs::scan_face_compact_t decoded;
    EXPECT_EQ(DecodeChecked(bytes.data(), bytes.size(), &decoded), "");
    return decoded;
  };
  const auto refusal = [&](const sandbox_msgs::scan_face_compact_t& message) -> std::string {
    try {
      DecodeCompactFace(through_the_wire(message));
    } catch (const std::invalid_argument& e) {
      return e.what();
    }
    return "accepted";
  };
  sandbox_msgs::scan_face_compact_t good{};
  good.face = 2, good.n = 3, good.resolution_m = 1.0, good.half_extent_m = 1.0;
  good.encoding = 1, good.num_mm = 9, good.distance_mm.assign(9, std::int16_t(-1));
  EXPECT_EQ(DecodeCompactFace(through_the_wire(good)).occupancy.size(), 9u);

  auto huge = good;  // 2e9 per side with no data: 4e18 cells if trusted
  huge.n = 2000000000, huge.num_mm = 0, huge.distance_mm.clear();
  EXPECT_NE(refusal(huge).find("n = 2000000000 needs n^2 distances"), std::string::npos)
      << refusal(huge);
  auto negative = good;  // (-3)^2 = 9 would match the data
  negative.n = -3;
  EXPECT_NE(refusal(negative).find("n = -3"), std::string::npos);
  auto face99 = good;
  face99.face = 99;
  EXPECT_NE(refusal(face99).find("face 99 is not 0..5"), std::string::npos);
  auto encoding = good;
  encoding.encoding = 7;
  EXPECT_NE(refusal(encoding).find("encoding 7"), std::string::npos);
  auto grid = good;  // 3 per side is 2 * 1 / 1 + 1; 2 m half extent needs 5
  grid.half_extent_m = 2.0;
  EXPECT_NE(refusal(grid).find("does not match"), std::string::npos);
  auto resolution = good;
  resolution.resolution_m = std::nan("");
  EXPECT_NE(refusal(resolution).find("resolution_m"), std::string::npos);
  auto wrong_array = good;  // the float array filled, the mm one announced
  wrong_array.num_mm = 0, wrong_array.distance_mm.clear();
  wrong_array.num_m = 9, wrong_array.distance_m.assign(9, 1.0f);
  EXPECT_NE(refusal(wrong_array).find("needs n^2 distances, the message holds 0"),
            std::string::npos);
}

TEST(CompactFaceTest, AScannerWithACompactEncodingPublishesCompactFaces) {
  LcmLink link("memq://");
  LatestInput subscriber(link, "W/SCAN_FACE");
  RobotOutputs outputs(link, "W");
  const sensors::FaceScan scan = SampleScan(sensors::FaceEncoding::kFloat, 1.0, 25.0,
                                            Eigen::Isometry3d(Eigen::Translation3d(20, -25, 22)));
  outputs.Publish(scan, {"scanner", "SCAN_FACE"}, 7, InputTag{9, 900}, 1000);
  link.Drain();
  EXPECT_EQ(outputs.published(), 6);
  sandbox_msgs::scan_face_compact_t message;
  ASSERT_TRUE(Newest(subscriber, &message));
  EXPECT_EQ(message.face, 5);
  EXPECT_EQ(message.tick, 7);
  EXPECT_EQ(message.input_seq, 9);
  EXPECT_EQ(message.encoding, 2);
  EXPECT_EQ(message.num_mm, 0);
  ASSERT_EQ(message.num_m, 51 * 51);
  EXPECT_EQ(message.resolution_m, 1.0);
  EXPECT_EQ(message.half_extent_m, 25.0);
  // 51 x 51 floats and a header: under a third of the points message's 13
  // bytes a sample (in millimetres: under a sixth).
  EXPECT_LT(message.getEncodedSize(), 51 * 51 * 13 / 3);
}

// examples/scan_face_points.m, run by Octave on a message the sandbox
// encoded, gives the scanner's own points (and occupancy).
TEST(CompactFaceTest, TheOctaveFunctionGivesTheScannersPoints) {
  if (std::system("command -v octave > /dev/null 2>&1") != 0) GTEST_SKIP() << "no octave";
  if (!std::filesystem::exists(SANDBOX_MSGS_JAR)) GTEST_SKIP() << "no " << SANDBOX_MSGS_JAR;
  testing::TempDir dir;
  const sensors::FaceScan scan = SampleScan(sensors::FaceEncoding::kMillimetres, 2.0, 20.0,
                                            Eigen::Translation3d(-30, 10, 18) *
                                                Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()) *
                                                Eigen::AngleAxisd(-0.3, Eigen::Vector3d::UnitY()));
  for (const int f : {0, 3, 5}) {
    sandbox_msgs::scan_face_compact_t message{};
    EncodeCompactFace(scan, f, &message);
    std::vector<std::uint8_t> bytes(std::size_t(message.getEncodedSize()));
    message.encode(bytes.data(), 0, int(bytes.size()));
    const auto in = dir.path() / "face.lcm", out = dir.path() / "points.txt";
    std::ofstream(in, std::ios::binary)
        .write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
    const std::string script =
        "javaaddpath('/usr/share/java/lcm.jar'); javaaddpath('" SANDBOX_MSGS_JAR
        "'); "
        "addpath('" SANDBOX_SOURCE_DIR
        "/examples'); "
        "msg = javaObject('sandbox_msgs.scan_face_compact_t', javaObject("
        "'java.io.DataInputStream', javaObject('java.io.FileInputStream', '" +
        in.string() + "'))); [p, o, s] = scan_face_points(msg); dlmwrite('" + out.string() +
        "', [p, o, s], 'precision', '%.9g');";
    ASSERT_EQ(std::system(("octave --no-gui --quiet --eval \"" + script + "\" > " +
                           (dir.path() / "octave.log").string() + " 2>&1")
                              .c_str()),
              0)
        << "face " << f << ": see " << (dir.path() / "octave.log");
    const sensors::ScanFace& face = scan.faces[std::size_t(f)];
    std::ifstream rows(out);
    std::string line;
    std::size_t k = 0;
    double worst_m = 0.0;
    while (std::getline(rows, line) && k < face.distance_m.size()) {
      double x, y, z, occupancy, surface;
      ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf", &x, &y, &z, &occupancy, &surface),
                5)
          << line;
      EXPECT_EQ(int(occupancy), int(face.occupancy[k])) << "face " << f << ", point " << k;
      EXPECT_EQ(int(surface), face.surface[k]) << "face " << f << ", point " << k;
      worst_m = std::max(worst_m, (Eigen::Vector3d(x, y, z) - scan.PointW(f, k)).norm());
      ++k;
    }
    EXPECT_EQ(k, face.distance_m.size()) << "face " << f;
    EXPECT_LE(worst_m, 0.5e-3 + 1e-5) << "face " << f;
  }
}

}  // namespace
}  // namespace sandbox::bridge
