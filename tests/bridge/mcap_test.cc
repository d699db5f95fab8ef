// MCAP recordings: the writer's files read back by the reader in every
// compression, and damaged files (offsets from the specification's record
// layout, not from the code): a bad magic, a chunk whose CRC or compressed
// bytes are wrong, a file cut inside a chunk, a length that lies, a changed
// byte outside the chunks (the data section's CRC). The npm reader
// (@mcap/core) checks the writer independently: tests/python/test_mcap.py.

#include <glib.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <string>
#include <vector>

#include "bridge/event_log.h"
#include "bridge/foxglove_messages.h"
#include "bridge/foxglove_views.h"
#include "bridge/lcm_link.h"
#include "bridge/mcap_reader.h"
#include "bridge/mcap_writer.h"
#include "sandbox_msgs/gnss_t.hpp"
#include "sandbox_msgs/ground_map_t.hpp"
#include "sandbox_msgs/lidar_scan_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "tests/test_util.h"

namespace sandbox::bridge {
namespace {

// The first chunk's record: after the magic (8) and the header (opcode,
// length, an empty profile and the library "sandbox": 1 + 8 + 4 + 4 + 7).
constexpr std::size_t kFirstChunk = 8 + 24;
// Its fields before the records: opcode, length, start, end, size, CRC,
// compression (empty), the records' length.
constexpr std::size_t kRecordsLength = kFirstChunk + 1 + 8 + 8 + 8 + 8 + 4 + 4;

struct Event {
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime;
  bool operator==(const Event& o) const {
    return channel == o.channel && data == o.data && utime == o.utime;
  }
};

std::vector<Event> SomeEvents(int n) {
  std::mt19937 random(7);
  std::vector<Event> events;
  for (int k = 0; k < n; ++k) {
    if (k % 3 == 0) {  // a sandbox type, with a schema
      sandbox_msgs::robot_pose_t pose{};
      pose.utime = k;
      pose.position[0] = 0.5 * k;
      pose.orientation[0] = 1.0;
      std::vector<std::uint8_t> bytes(std::size_t(pose.getEncodedSize()));
      pose.encode(bytes.data(), 0, int(bytes.size()));
      events.push_back({"R/POSE", bytes, 1'000'000 + 10'000 * k});
    } else {  // anything else, without one (sizes 0 to 3000)
      std::vector<std::uint8_t> bytes(random() % 3001);
      for (auto& b : bytes) b = std::uint8_t(random());
      events.push_back({k % 2 ? "OTHER" : "R/SCAN", bytes, 1'000'000 + 10'000 * k});
    }
  }
  return events;
}

void Write(const std::string& path, const std::vector<Event>& events, McapWriter::Options options) {
  McapWriter writer(path, options);
  for (const Event& e : events) {
    ASSERT_TRUE(writer.Write(e.channel, e.data.data(), unsigned(e.data.size()), e.utime));
  }
  ASSERT_TRUE(writer.Close()) << writer.error();
  EXPECT_EQ(writer.events(), std::int64_t(events.size()));
}

std::vector<Event> ReadAll(EventReader& reader) {
  std::vector<Event> events;
  Event e;
  while (reader.Next(&e.channel, &e.data, &e.utime)) events.push_back(e);
  return events;
}

std::string Bytes(const std::string& path) {
  std::string bytes(std::filesystem::file_size(path), '\0');
  std::ifstream(path, std::ios::binary).read(bytes.data(), std::streamsize(bytes.size()));
  return bytes;
}

void Put(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

TEST(McapTest, EveryEventComesBackInOrderInEveryCompression) {
  testing::TempDir dir;
  const std::vector<Event> events = SomeEvents(300);
  for (const std::string compression : {"", "zstd", "lz4"}) {
    const std::string path = (dir.path() / ("run" + compression + ".mcap")).string();
    Write(path, events, {compression, 20'000});  // about 25 chunks
    const std::unique_ptr<EventReader> reader = OpenEventReader(path);
    EXPECT_EQ(ReadAll(*reader), events) << "compression '" << compression << "'";
    EXPECT_EQ(reader->stopped_early(), "");
    EXPECT_EQ(reader->events(), 300);
    EXPECT_DOUBLE_EQ(reader->fraction_read(), 1.0);
  }
}

TEST(McapTest, TheFileNameChoosesTheWriterAndTheFirstBytesTheReader) {
  testing::TempDir dir;
  const std::vector<Event> events = SomeEvents(10);
  for (const std::string name : {"a.mcap", "a.lcmlog", "a"}) {
    const std::string path = (dir.path() / name).string();
    {
      const std::unique_ptr<EventWriter> writer = OpenEventWriter(path);
      for (const Event& e : events)
        writer->Write(e.channel, e.data.data(), unsigned(e.data.size()), e.utime);
      ASSERT_TRUE(writer->Close());
    }
    const bool mcap = Bytes(path).compare(0, 5, "\x89MCAP") == 0;
    EXPECT_EQ(mcap, name == std::string("a.mcap"));
    EXPECT_EQ(ReadAll(*OpenEventReader(path)), events) << name;
  }
}

TEST(McapTest, AFileWithoutTheMagicIsRefusedNamingIt) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "not.mcap").string();
  Put(path, "\x89MCAQ0\r\n and more");
  try {
    McapReader reader(path);
    FAIL() << "read a file without the magic";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "'" + path + "' is not an MCAP file: no MCAP magic at byte 0");
  }
}

class DamagedMcap : public ::testing::Test {
 protected:
  void SetUp() override {
    path_ = (dir_.path() / "run.mcap").string();
    Write(path_, SomeEvents(30), {"", 1 << 20});  // one uncompressed chunk
    bytes_ = Bytes(path_);
    ASSERT_EQ(bytes_[kFirstChunk], '\x06');  // a chunk record
  }
  // Reads the damaged file to its end.
  std::unique_ptr<EventReader> Read(const std::string& bytes) {
    Put(path_, bytes);
    auto reader = OpenEventReader(path_);
    ReadAll(*reader);
    return reader;
  }
  testing::TempDir dir_;
  std::string path_, bytes_;
};

TEST_F(DamagedMcap, AChangedByteInAChunkIsItsCrc) {
  std::string bytes = bytes_;
  bytes[kRecordsLength + 8 + 40] ^= 0x10;  // inside the chunk's records
  const auto reader = Read(bytes);
  EXPECT_EQ(reader->events(), 0);
  EXPECT_EQ(reader->stopped_early().rfind("damaged at byte 32: the chunk's CRC is ", 0), 0u)
      << reader->stopped_early();
}

TEST_F(DamagedMcap, AChunkCutShortStopsAtIt) {
  const auto reader = Read(bytes_.substr(0, kFirstChunk + 500));
  EXPECT_EQ(reader->events(), 0);
  EXPECT_EQ(reader->stopped_early().rfind("damaged at byte 32: a record of ", 0), 0u)
      << reader->stopped_early();
}

TEST_F(DamagedMcap, ALengthThatLiesIsCaughtWithinItsRecord) {
  std::string bytes = bytes_;
  bytes[kRecordsLength + 5] = '\x7f';  // the records' length, now about 5e14
  const auto reader = Read(bytes);
  EXPECT_EQ(reader->events(), 0);
  EXPECT_NE(reader->stopped_early().find("damaged at byte 32: chunk: records says "),
            std::string::npos)
      << reader->stopped_early();
}

TEST_F(DamagedMcap, AChangedByteOutsideTheChunksIsTheDataSectionsCrc) {
  std::string bytes = bytes_;
  bytes[kFirstChunk - 1] = 'X';  // the header's library name: "sandboX"
  const auto reader = Read(bytes);
  EXPECT_EQ(reader->events(), 30);  // every message, then the data end disagrees
  EXPECT_NE(reader->stopped_early().find("the data section's CRC is "), std::string::npos)
      << reader->stopped_early();
}

TEST_F(DamagedMcap, BadCompressedBytesAreAClearError) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "z.mcap").string();
  Write(path, SomeEvents(30), {"zstd", 1 << 20});
  std::string bytes = Bytes(path);
  // The compressed records start 4 bytes later than uncompressed ("zstd").
  for (std::size_t i = kRecordsLength + 4 + 8 + 4; i < kRecordsLength + 4 + 8 + 40; ++i) {
    bytes[i] = '\xff';
  }
  Put(path, bytes);
  const auto reader = OpenEventReader(path);
  ReadAll(*reader);
  EXPECT_EQ(reader->events(), 0);
  EXPECT_EQ(reader->stopped_early().rfind("damaged at byte 32: chunk: zstd: ", 0), 0u)
      << reader->stopped_early();
}

TEST(McapTest, AWriteErrorIsKeptNamingTheFile) {
  if (!std::filesystem::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  McapWriter writer("/dev/full", {"zstd", 1000});
  const std::vector<Event> events = SomeEvents(100);
  for (const Event& e : events)
    writer.Write(e.channel, e.data.data(), unsigned(e.data.size()), e.utime);
  EXPECT_FALSE(writer.Close());
  EXPECT_EQ(writer.error().rfind("cannot write '/dev/full' after ", 0), 0u) << writer.error();
}

// A lidar sweep as Foxglove's PointCloud: each beam's point, range, hit, id
// and intensity at the offsets the fields say, in little-endian bytes.
TEST(FoxgloveViewsTest, ALidarSweepIsAPointCloudWithItsIdsAndIntensities) {
  sandbox_msgs::lidar_scan_t scan{};
  scan.utime = 1'234'567'890;
  scan.channels = 1;
  scan.steps = 2;
  scan.origin[0] = 1000.5;
  scan.start_orientation[0] = scan.end_orientation[0] = 1;
  scan.num_beams = 2;
  scan.range_m = {5.5f, 0.0f};
  scan.hit = {1, 0};
  scan.num_xyz = 6;
  scan.xyz = {1.f, 2.f, 3.f, -4.f, -5.f, -6.f};
  scan.time_s = {0.f, 0.05f};
  scan.num_surface = 2;
  scan.surface = {17, 0};
  scan.num_intensity = 2;
  scan.intensity = {0.25f, 0.f};
  std::vector<std::uint8_t> bytes(std::size_t(scan.getEncodedSize()));
  scan.encode(bytes.data(), 0, int(bytes.size()));
  const std::vector<FoxgloveView> views = FoxgloveViewsOf("R/LIDAR", bytes.data(), bytes.size());
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].topic, "R/LIDAR/points");
  EXPECT_EQ(views[0].schema_name, "foxglove.PointCloud");
  const auto cloud = nlohmann::json::parse(views[0].json);
  EXPECT_EQ(cloud["timestamp"]["sec"], 1234);
  EXPECT_EQ(cloud["timestamp"]["nsec"], 567'890'000);
  EXPECT_EQ(cloud["frame_id"], "world");
  EXPECT_EQ(cloud["pose"]["position"]["x"], 1000.5);
  const int stride = cloud["point_stride"];
  std::map<std::string, int> offset;
  for (const auto& field : cloud["fields"]) offset[field["name"]] = field["offset"];
  gsize size = 0;
  guchar* raw = g_base64_decode(cloud["data"].get<std::string>().c_str(), &size);
  const std::string data(reinterpret_cast<char*>(raw), size);
  g_free(raw);
  ASSERT_EQ(size, std::size_t(stride));  // the beam that hit; the other has no point
  const auto f32 = [&](int point, const std::string& name) {
    float v;
    std::memcpy(&v, data.data() + point * stride + offset.at(name), 4);
    return v;
  };
  const auto i32 = [&](int point, const std::string& name) {
    std::int32_t v;
    std::memcpy(&v, data.data() + point * stride + offset.at(name), 4);
    return v;
  };
  EXPECT_EQ(f32(0, "x"), 1.f);
  EXPECT_EQ(f32(0, "z"), 3.f);
  EXPECT_EQ(f32(0, "range"), 5.5f);
  EXPECT_EQ(i32(0, "surface"), 17);
  EXPECT_EQ(f32(0, "intensity"), 0.25f);
  // Without ids and intensities, no such fields.
  scan.num_surface = scan.num_intensity = 0;
  scan.surface.clear();
  scan.intensity.clear();
  bytes.resize(std::size_t(scan.getEncodedSize()));
  scan.encode(bytes.data(), 0, int(bytes.size()));
  const auto bare =
      nlohmann::json::parse(FoxgloveViewsOf("R/LIDAR", bytes.data(), bytes.size())[0].json);
  EXPECT_EQ(bare["fields"].size(), 4u);  // x, y, z, range
  EXPECT_EQ(bare["point_stride"], 16);
  // A message that is not a sandbox type, or does not decode: no view.
  EXPECT_TRUE(FoxgloveViewsOf("R/LIDAR", bytes.data(), bytes.size() - 1).empty());
}

}  // namespace
}  // namespace sandbox::bridge

namespace sandbox::bridge {
namespace {

template <typename Message>
std::vector<std::uint8_t> Bytes(Message message) {
  std::vector<std::uint8_t> bytes(std::size_t(message.getEncodedSize()));
  message.encode(bytes.data(), 0, int(bytes.size()));
  return bytes;
}

// Each fix of a GNSS message a LocationFix at the time it was taken.
TEST(FoxgloveViewsTest, GnssFixesAreLocationFixes) {
  sandbox_msgs::gnss_t gnss{};
  gnss.utime = 5'000'000;
  gnss.sensor = "rx";
  gnss.num_fixes = 2;
  gnss.fix_utime = {4'800'000, 4'900'000};
  gnss.latitude_deg = {47.25, 47.5};
  gnss.longitude_deg = {8.5, -8.75};
  gnss.height_m = {500.0, 501.5};
  gnss.num_ned = 6;
  gnss.velocity_ned.assign(6, 0.0);
  const std::vector<std::uint8_t> bytes = Bytes(gnss);
  const std::vector<FoxgloveView> views = FoxgloveViewsOf("W/GNSS", bytes.data(), bytes.size());
  ASSERT_EQ(views.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_EQ(views[std::size_t(i)].topic, "W/GNSS/fix");
    EXPECT_EQ(views[std::size_t(i)].schema_name, "foxglove.LocationFix");
    const auto fix = nlohmann::json::parse(views[std::size_t(i)].json);
    EXPECT_EQ(fix["frame_id"], "rx");
    EXPECT_EQ(fix["timestamp"]["sec"], 4);
    EXPECT_EQ(fix["timestamp"]["nsec"], i == 0 ? 800'000'000 : 900'000'000);
    EXPECT_EQ(fix["latitude"], gnss.latitude_deg[std::size_t(i)]);
    EXPECT_EQ(fix["longitude"], gnss.longitude_deg[std::size_t(i)]);
    EXPECT_EQ(fix["altitude"], gnss.height_m[std::size_t(i)]);
  }
}

// A ground map a Grid: cell (r, c) centred on the map's point (r, c).
TEST(FoxgloveViewsTest, AGroundMapIsAGridCentredOnItsPoints) {
  sandbox_msgs::ground_map_t map{};
  map.utime = 7;
  map.n = 2;
  map.resolution_m = 0.5;
  map.corner[0] = 10.0, map.corner[1] = -4.0;
  map.origin_z = 100.0;
  map.num_points = 4;
  map.height = {1.f, 2.f, std::nanf(""), 4.f};
  map.num_surface = 4;
  map.surface = {3, 3, 0, 9};
  const std::vector<std::uint8_t> bytes = Bytes(map);
  const std::vector<FoxgloveView> views = FoxgloveViewsOf("W/GROUND", bytes.data(), bytes.size());
  ASSERT_EQ(views.size(), 1u);
  EXPECT_EQ(views[0].topic, "W/GROUND/grid");
  const auto grid = nlohmann::json::parse(views[0].json);
  EXPECT_EQ(grid["column_count"], 2);
  EXPECT_EQ(grid["cell_size"]["x"], 0.5);
  EXPECT_EQ(grid["pose"]["position"]["x"], 9.75);  // the cell around x = 10 starts at 9.75
  EXPECT_EQ(grid["pose"]["position"]["y"], -4.25);
  EXPECT_EQ(grid["pose"]["position"]["z"], 100.0);
  const int stride = grid["cell_stride"];
  ASSERT_EQ(stride, 8);
  EXPECT_EQ(grid["row_stride"], 16);
  gsize size = 0;
  guchar* raw = g_base64_decode(grid["data"].get<std::string>().c_str(), &size);
  std::vector<std::uint8_t> data(raw, raw + size);
  g_free(raw);
  ASSERT_EQ(size, 32u);
  for (int k = 0; k < 4; ++k) {
    float height;
    std::int32_t surface;
    std::memcpy(&height, data.data() + 8 * k, 4);
    std::memcpy(&surface, data.data() + 8 * k + 4, 4);
    if (k == 2) {
      EXPECT_TRUE(std::isnan(height));
    } else {
      EXPECT_EQ(height, map.height[std::size_t(k)]);
    }
    EXPECT_EQ(surface, map.surface[std::size_t(k)]);
  }
}

// A scene's triangle list written by hand (not through the JSON library):
// still JSON, names escaped, every point and index in order.
TEST(FoxgloveViewsTest, ASceneUpdateIsJsonWithEveryPointAndIndex) {
  SceneMesh mesh;
  mesh.id = "actor/\"quoted\"\n/0";
  mesh.frame_id = "world";
  mesh.X_FE.translation() = Eigen::Vector3d(1, 2, 3);
  mesh.vertices = {{0.f, 0.f, 0.f}, {1.5f, -2.25f, 1e-7f}, {3.f, 1e6f, -0.1f}};
  mesh.indices = {0, 1, 2};
  const FoxgloveView view = SceneUpdate("scene", {mesh, SceneMesh{}}, 2'500'000);
  const auto scene = nlohmann::json::parse(view.json);
  ASSERT_EQ(scene["entities"].size(), 2u);
  const auto& entity = scene["entities"][0];
  EXPECT_EQ(entity["id"], mesh.id);
  EXPECT_EQ(entity["timestamp"]["sec"], 2);
  EXPECT_EQ(entity["timestamp"]["nsec"], 500'000'000);
  const auto& triangles = entity["triangles"][0];
  EXPECT_EQ(triangles["pose"]["position"]["z"], 3.0);
  ASSERT_EQ(triangles["points"].size(), 3u);
  for (std::size_t v = 0; v < 3; ++v) {  // shortest round-trip floats: exact
    EXPECT_EQ(triangles["points"][v]["x"].get<float>(), mesh.vertices[v].x());
    EXPECT_EQ(triangles["points"][v]["y"].get<float>(), mesh.vertices[v].y());
    EXPECT_EQ(triangles["points"][v]["z"].get<float>(), mesh.vertices[v].z());
  }
  EXPECT_EQ(triangles["indices"], nlohmann::json({0, 1, 2}));
  EXPECT_TRUE(scene["entities"][1]["triangles"][0]["points"].empty());
}

// In a recording, an input is written as it came, without the views a
// published message of its type gets; a view given as one is made by the
// writer and lands on its own channel.
TEST(McapTest, InputsGetNoViewsAndGivenViewsTheirOwnChannels) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "run.mcap").string();
  sandbox_msgs::robot_pose_t pose{};
  pose.utime = 10;
  pose.orientation[0] = 1;
  std::vector<std::uint8_t> bytes(std::size_t(pose.getEncodedSize()));
  pose.encode(bytes.data(), 0, int(bytes.size()));
  {
    McapWriter writer(path);
    ASSERT_TRUE(writer.TakesInputs() && writer.TakesViews());
    writer.WriteInput("R/POSE", bytes.data(), unsigned(bytes.size()), 10);
    writer.Write("R/POSE", bytes.data(), unsigned(bytes.size()), 20);
    writer.WriteView([] { return FrameTransforms("R/links", "R", {{"R/a", {}}}, 30); }, 30, 64);
    ASSERT_TRUE(writer.Close());
  }
  const std::unique_ptr<EventReader> reader = OpenEventReader(path);
  std::string channel;
  std::vector<std::uint8_t> data;
  std::int64_t utime = 0;
  std::vector<std::int64_t> times;
  while (reader->Next(&channel, &data, &utime)) times.push_back(utime);
  EXPECT_EQ(times, (std::vector<std::int64_t>{10, 20}));  // the LCM messages, in order
  EXPECT_EQ(reader->skipped(), 2);  // the JSON views: the published pose's, the given one
}

}  // namespace
}  // namespace sandbox::bridge
