// Writes the seed corpora of the fuzz targets into DIR/<target>/ (scripts/fuzz
// runs it; nothing it writes is committed): small valid inputs of every kind
// each target reads, for the fuzzer to mutate.
//
//   make_fuzz_seeds DIR SOURCE_DIR

#include <assimp/scene.h>
#include <cpl_conv.h>
#include <gdal.h>
#include <ogr_srs_api.h>
#include <unistd.h>

#include <assimp/Exporter.hpp>
#include <assimp/Importer.hpp>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "bridge/lcm_link.h"
#include "bridge/mcap_writer.h"
#include "bridge/net_fdm.h"
#include "sandbox_msgs/actor_placements_t.hpp"
#include "sandbox_msgs/bone_values_t.hpp"
#include "sandbox_msgs/camera_command_t.hpp"
#include "sandbox_msgs/robot_pose_t.hpp"
#include "sandbox_msgs/robot_state_t.hpp"
#include "sandbox_msgs/scan_face_compact_t.hpp"
#include "sandbox_msgs/status_t.hpp"
#include "sandbox_msgs/surface_table_t.hpp"
#include "scene/terrain_cache.h"
#include "scene/terrain_source.h"
#include "tests/test_rasters.h"

namespace fs = std::filesystem;
using Bytes = std::string;

namespace {

void Write(const fs::path& file, const Bytes& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
}

Bytes Read(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream contents;
  contents << in.rdbuf();
  return contents.str();
}

template <typename Message>
Bytes Encode(const Message& message) {
  Bytes bytes(std::size_t(message.getEncodedSize()), '\0');
  message.encode(bytes.data(), 0, int(bytes.size()));
  return bytes;
}

// The LCM messages the sandbox reads, valid, of several sizes.
void LcmSeeds(const fs::path& dir) {
  sandbox_msgs::robot_pose_t pose{};
  pose.seq = 1, pose.position[2] = 60, pose.orientation[0] = 1;
  Write(dir / "pose", Encode(pose));
  sandbox_msgs::bone_values_t bones{};
  bones.num_values = 45;
  bones.values.assign(45, 0.05);
  Write(dir / "bones", Encode(bones));
  bones.num_values = 2, bones.values = {0.1, 0.2};
  Write(dir / "bones_short", Encode(bones));
  sandbox_msgs::actor_placements_t actors{};
  actors.num_actors = 1, actors.names = {"gate"};
  actors.num_positions = 3, actors.positions = {1, 2, 3};
  actors.num_orientations = 4, actors.orientations = {1, 0, 0, 0};
  Write(dir / "actors", Encode(actors));
  sandbox_msgs::camera_command_t camera{};
  camera.active_camera = "belly", camera.zoom = 2;
  Write(dir / "camera", Encode(camera));
  sandbox_msgs::status_t status{};
  status.num_channels = 1, status.channels = {"ELAHA/POSE"}, status.received = {3};
  status.superseded = {0}, status.rejected = {1}, status.stale = {0};
  status.last_reject_reason = {"non-finite pose"};
  Write(dir / "status", Encode(status));
  sandbox_msgs::surface_table_t table{};
  table.num_surfaces = 1, table.id = {7}, table.kind = {"bone"}, table.name = {"ELAHA/wing"};
  table.actor = {-1}, table.robot = {"ELAHA"}, table.bone = {"wing"};
  table.reflectivity = {0.5f};
  Write(dir / "surfaces", Encode(table));
}

void UdpSeeds(const fs::path& dir) {
  sandbox::bridge::NetFdm fdm;
  fdm.latitude_rad = 0.82, fdm.longitude_rad = 0.14, fdm.altitude_m = 600, fdm.elevator = 0.5f;
  const std::vector<std::uint8_t> packet = sandbox::bridge::EncodeNetFdm(fdm);
  Write(dir / "net_fdm", Bytes(packet.begin(), packet.end()));
  // Layout 0 (position, quaternion, bones): the first byte picks it.
  std::vector<double> values = {1, 2, 3, 1, 0, 0, 0};
  values.resize(7 + 45, 0.0);
  Bytes doubles(1, '\0');
  doubles.append(reinterpret_cast<const char*>(values.data()), values.size() * 8);
  Write(dir / "doubles", doubles);
  Bytes rpy(1, '\1');
  const double pose[6] = {1, 2, 3, 0.1, 0.2, 0.3};
  rpy.append(reinterpret_cast<const char*>(pose), sizeof(pose));
  Write(dir / "doubles_rpy", rpy);
}

// Requests to the browser view's server: plain GETs, a WebSocket handshake
// followed by masked frames (text, binary, ping, close), one from another origin.
void WebRequestSeeds(const fs::path& dir) {
  const Bytes handshake =
      "GET /stream HTTP/1.1\r\nHost: 127.0.0.1:8080\r\nUpgrade: websocket\r\n"
      "Connection: Upgrade\r\nSec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\n"
      "Origin: http://127.0.0.1:8080\r\nSec-WebSocket-Version: 13\r\n\r\n";
  auto frame = [](unsigned char opcode, const Bytes& payload) {
    const unsigned char mask[4] = {0x12, 0x34, 0x56, 0x78};
    Bytes f;
    f += char(0x80 | opcode);
    f += char(0x80 | payload.size());  // under 126 bytes here
    f.append(reinterpret_cast<const char*>(mask), 4);
    for (std::size_t i = 0; i < payload.size(); ++i) f += char(payload[i] ^ mask[i % 4]);
    return f;
  };
  Write(dir / "get_page", "GET / HTTP/1.1\r\nHost: 127.0.0.1:8080\r\n\r\n");
  Write(dir / "get_three",
        "GET /three/build/three.module.js?v=1 HTTP/1.1\r\nHost: localhost\r\n\r\n");
  Write(dir / "get_outside", "GET /three/../../etc/passwd HTTP/1.1\r\nHost: [::1]:80\r\n\r\n");
  Write(dir / "stream_frames", handshake + frame(0x1, "hello") + frame(0x2, Bytes("\0\1\2", 3)) +
                                   frame(0x9, "ping") + frame(0x8, Bytes("\x03\xe8", 2)));
  Write(dir / "stream_player", handshake + frame(0x1, R"({"type":"player","play":true})") +
                                   frame(0x1, R"({"type":"player","speed":4,"seek":120})") +
                                   frame(0x1, R"({"type":"player","seek":-1})") +
                                   frame(0x1, R"({"type":"camera","key":"zoom_in"})"));
  Bytes other = handshake;
  other.replace(other.find("Origin: http://127.0.0.1:8080"), 29, "Origin: http://evil.example");
  Write(dir / "stream_other_origin", other);
}

void LogSeeds(const fs::path& dir) {
  fs::create_directories(dir);
  sandbox::bridge::LogWriter log((dir / "flight").string());
  sandbox_msgs::robot_pose_t pose{};
  pose.orientation[0] = 1;
  for (int i = 0; i < 3; ++i) {
    pose.seq = i;
    const Bytes bytes = Encode(pose);
    log.Write("ELAHA/POSE", bytes.data(), unsigned(bytes.size()), 1000 * i);
  }
  log.Close();
  // A --record log's STATEs, of the robot the target replays from its states.
  sandbox::bridge::LogWriter recorded((dir / "recorded").string());
  sandbox_msgs::robot_state_t state{};
  state.orientation[0] = 1;
  state.num_values = 2;
  state.bone_values = {0.5, -0.5};
  for (int i = 0; i < 3; ++i) {
    state.seq = i;
    const Bytes bytes = Encode(state);
    recorded.Write("R/STATE", bytes.data(), unsigned(bytes.size()), 1000 * i);
  }
  recorded.Close();
}

// Small recordings in each chunk compression, one with a message of a type
// the sandbox does not know (a channel without a schema).
void McapSeeds(const fs::path& dir) {
  fs::create_directories(dir);
  sandbox_msgs::robot_pose_t pose{};
  pose.orientation[0] = 1;
  const Bytes other = "not an LCM message";
  for (const std::string compression : {"zstd", "lz4", ""}) {
    sandbox::bridge::McapWriter writer((dir / ("flight_" + compression)).string(),
                                       {compression, 200});
    for (int i = 0; i < 4; ++i) {
      pose.seq = i;
      const Bytes bytes = Encode(pose);
      writer.Write("ELAHA/POSE", bytes.data(), unsigned(bytes.size()), 1000 * i);
      writer.Write("OTHER", other.data(), unsigned(other.size()), 1000 * i);
    }
    writer.Close();
  }
}

// What Foxglove and Lichtblick send the live server, and what they might.
void FoxgloveRequestSeeds(const fs::path& dir) {
  fs::create_directories(dir);
  Write(dir / "subscribe",
        R"({"op":"subscribe","subscriptions":[{"id":0,"channelId":3},{"id":1,"channelId":0}]})");
  Write(dir / "unsubscribe", R"({"op":"unsubscribe","subscriptionIds":[0,1]})");
  Write(
      dir / "advertise",
      R"({"op":"advertise","channels":[{"id":1,"topic":"/x","encoding":"json","schemaName":"s"}]})");
  Write(dir / "get_parameters", R"({"op":"getParameters","parameterNames":[],"id":"a"})");
}

// PNG's CRC-32, for the zip below.
std::uint32_t Crc32(const Bytes& bytes) {
  std::uint32_t crc = 0xffffffffu;
  for (const char c : bytes) {
    crc ^= std::uint8_t(c);
    for (int k = 0; k < 8; ++k) crc = (crc >> 1) ^ (0xedb88320u & (0u - (crc & 1u)));
  }
  return ~crc;
}

Bytes Little(std::uint32_t v, int n) {
  Bytes out;
  for (int i = 0; i < n; ++i) out += char((v >> (8 * i)) & 0xff);
  return out;
}

// A zip holding one stored (uncompressed) file.
Bytes StoredZip(const std::string& name, const Bytes& data) {
  const std::uint32_t crc = Crc32(data), size = std::uint32_t(data.size());
  const Bytes local = Little(0x04034b50, 4) + Little(20, 2) + Little(0, 2) + Little(0, 2) +
                      Little(0, 4) + Little(crc, 4) + Little(size, 4) + Little(size, 4) +
                      Little(std::uint32_t(name.size()), 2) + Little(0, 2) + name;
  const Bytes central = Little(0x02014b50, 4) + Little(20, 2) + Little(20, 2) + Little(0, 2) +
                        Little(0, 2) + Little(0, 4) + Little(crc, 4) + Little(size, 4) +
                        Little(size, 4) + Little(std::uint32_t(name.size()), 2) + Little(0, 2) +
                        Little(0, 2) + Little(0, 2) + Little(0, 2) + Little(0, 4) + Little(0, 4) +
                        name;
  const std::uint32_t central_at = std::uint32_t(local.size() + data.size());
  return local + data + central + Little(0x06054b50, 4) + Little(0, 2) + Little(0, 2) +
         Little(1, 2) + Little(1, 2) + Little(std::uint32_t(central.size()), 4) +
         Little(central_at, 4) + Little(0, 2);
}

// Level files: a textured box exported by assimp in each format it writes,
// and hand-made files of the rest. The first byte picks the format.
void LevelFileSeeds(const fs::path& dir) {
  const char* formats[] = {"obj", "ply", "stl", "off", "gltf", "glb", "dae", "fbx",
                           "3ds", "x",   "3mf", "pk3", "ter",  "png", "pgm"};
  auto index = [&](const std::string& format) {
    for (std::size_t i = 0; i < std::size(formats); ++i) {
      if (format == formats[i]) return char(i);
    }
    std::fprintf(stderr, "make_fuzz_seeds: no format %s\n", format.c_str());
    std::exit(1);
  };
  auto seed = [&](const std::string& format, const std::string& name, const Bytes& bytes) {
    Write(dir / format / name, Bytes(1, index(format)) + bytes);
  };
  const char* obj =
      "mtllib none.mtl\no box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\n"
      "v 0 1 1\nvt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nf 1/1/1 4/2/1 3/3/1 2/1/1\nf 5 6 7 8\n"
      "f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n";
  seed("obj", "box.obj", obj);
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFileFromMemory(obj, std::strlen(obj), 0, "obj");
  if (scene == nullptr) {
    std::fprintf(stderr, "make_fuzz_seeds: %s\n", importer.GetErrorString());
    std::exit(1);
  }
  Assimp::Exporter exporter;
  const std::pair<const char*, const char*> exports[] = {
      {"ply", "ply"},    {"plyb", "ply"}, {"stl", "stl"},     {"stlb", "stl"},
      {"gltf2", "gltf"}, {"glb2", "glb"}, {"collada", "dae"}, {"fbx", "fbx"},
      {"fbxa", "fbx"},   {"3ds", "3ds"},  {"x", "x"},         {"3mf", "3mf"}};
  for (const auto& [id, format] : exports) {
    // To a file and back (assimp 5.2.5's 3MF exporter ignores ExportToBlob),
    // in a folder of its own (glTF writes its buffer beside it).
    const fs::path folder =
        fs::temp_directory_path() / ("make_fuzz_seeds_" + std::to_string(getpid()));
    fs::create_directories(folder);
    const fs::path file = folder / (std::string("box.") + format);
    if (exporter.Export(scene, id, file.string()) == AI_SUCCESS) {
      seed(format, std::string("box.") + id, Read(file));
    } else {
      std::fprintf(stderr, "make_fuzz_seeds: no %s export: %s\n", id, exporter.GetErrorString());
    }
    fs::remove_all(folder);
  }
  seed("off", "box.off", "OFF\n4 2 0\n0 0 0\n1 0 0\n1 1 0\n0 1 0\n3 0 1 2\n3 0 2 3\n");
  // A Quake 3 map's skeleton: "IBSP", version 46, 17 lumps of nothing.
  Bytes bsp = "IBSP" + Little(46, 4);
  for (int lump = 0; lump < 17; ++lump) bsp += Little(8 + 17 * 8, 4) + Little(0, 4);
  seed("pk3", "empty.pk3", StoredZip("maps/empty.bsp", bsp));
  // Terragen: 3 x 3 points.
  Bytes ter =
      "TERRAGENTERRAIN SIZE" + Little(2, 2) + Little(0, 2) + "ALTW" + Little(256, 2) + Little(1, 2);
  for (int i = 0; i < 9; ++i) ter += Little(std::uint32_t(i * 100), 2);
  seed("ter", "hills.ter", ter + "EOF ");
  cv::Mat grey(8, 8, CV_8UC1);
  for (int i = 0; i < 64; ++i) grey.data[i] = std::uint8_t(i * 4);
  std::vector<std::uint8_t> png;
  cv::imencode(".png", grey, png);
  seed("png", "hills.png", Bytes(png.begin(), png.end()));
  seed("pgm", "hills.pgm", "P5\n4 4\n255\n" + Bytes(16, '\x40'));
}

void ManifestSeeds(const fs::path& dir, const fs::path& source) {
  for (const char* file :
       {"assets/sample/level.toml", "assets/robots/robots.toml", "tests/data/kuka_iiwa.toml",
        "tests/data/net_fdm_wing.toml", "tests/data/px4_uneven_ground.toml"}) {
    Write(dir / fs::path(file).filename(), Read(source / file));
  }
  // The instruments and [wind].
  Write(dir / "instruments.toml", Read(source / "examples/instruments/level.toml"));
  Write(dir / "limits.toml",
        "[level]\nname = \"l\"\nmax_triangles = 100\nmax_file_mb = 1\n"
        "[[actor]]\nname = \"a\"\nheightmap = \"h.png\"\nsize = [1, 2, 3]\n"
        "quaternion_wxyz = [1, 0, 0, 0]\nscale = [1, 2, 3]\nup = \"y\"\nunit_scale = 0.01\n");
  Write(dir / "reflectivity.toml",
        "[[actor]]\nname = \"w\"\nfile = \"w.obj\"\nreflectivity = 0.4\n"
        "material_reflectivity = { Rock = 0.2, \"Snow 1\" = 0.9 }\n"
        "[[robot]]\nname = \"R\"\nfile = \"r.gltf\"\n[[robot.sensor]]\nname = \"l\"\n"
        "type = \"lidar\"\ndivergence_deg = 0.5\ndivergence_rays = 6\nreturn_separation_m = 1\n"
        "range_noise_sigma_m = 0.02\ndropout_probability = 0.1\nseed = 3\n"
        "[[robot.camera]]\nname = \"c\"\ntype = \"chase\"\noverlay = true\n"
        "overlay_colour = \"surface\"\n");
  // `sandbox scan --lidar`'s one line of settings (ParseSettingsText).
  Write(dir / "lidar_settings.txt",
        "channels = 32, range_noise_sigma_m = 0.02, seed = 7, elevations_deg = [-10, 0, 10], "
        "kernel = \"general\", intensity = false");
}

// A small GeoTIFF in WGS84 near (lon 8, lat 46), as bytes: `bands` of
// `type`, with GDAL creation `options`.
Bytes GeoTiff(const fs::path& file, int cols, int rows, int bands, GDALDataType type,
              std::vector<std::string> options = {}) {
  sandbox::testing::WriteRaster(
      file, cols, rows, 8.0, 46.01, 0.0003, bands, type,
      [](int c, int r, int b) { return 400.0 + 3.0 * c - 2.0 * r + 50.0 * b; }, options);
  const Bytes bytes = Read(file);
  fs::remove(file);
  return bytes;
}

// Rasters as GDAL reads them: elevation and imagery, plain, tiled, compressed.
void RasterSeeds(const fs::path& dir) {
  fs::create_directories(dir);
  Write(dir / "elevation.tif", GeoTiff(dir / "e.tmp.tif", 40, 40, 1, GDT_Float32));
  Write(dir / "elevation_int16.tif", GeoTiff(dir / "i.tmp.tif", 24, 20, 1, GDT_Int16));
  Write(dir / "imagery.tif", GeoTiff(dir / "r.tmp.tif", 32, 32, 3, GDT_Byte));
  Write(dir / "tiled_deflate.tif",
        GeoTiff(dir / "t.tmp.tif", 48, 48, 1, GDT_Float32,
                {"TILED=YES", "BLOCKXSIZE=16", "BLOCKYSIZE=16", "COMPRESS=DEFLATE"}));
}

// Tile-cache files of the fuzz target's settings (16 samples a tile, coarse
// factor 4, 8 px textures): a fine and a coarse tile, with imagery.
void TileCacheSeeds(const fs::path& dir) {
  fs::create_directories(dir);
  const fs::path elevation = dir / "e.tmp.tif", imagery = dir / "r.tmp.tif";
  Write(elevation, GeoTiff(dir / "e0.tmp.tif", 70, 70, 1, GDT_Float32));
  Write(imagery, GeoTiff(dir / "r0.tmp.tif", 64, 64, 3, GDT_Byte));
  sandbox::scene::TerrainSpec spec;
  spec.elevation = {elevation};
  spec.imagery = {imagery};
  spec.anchor = {46.0, 8.01, 500.0};
  spec.tile_samples = 16, spec.coarse_factor = 4, spec.texture_px = 8;
  const sandbox::scene::TerrainSource source(spec);
  for (const int lod : {0, 1}) {
    Write(dir / ("tile_lod" + std::to_string(lod)),
          sandbox::scene::TerrainCache::Encode(source.Build({lod, 0, 0, 0})));
  }
  spec.imagery.clear();
  const sandbox::scene::TerrainSource bare(spec);
  Write(dir / "tile_bare", sandbox::scene::TerrainCache::Encode(bare.Build({0, 0, 0, 0})));
  fs::remove(elevation);
  fs::remove(imagery);
}

// Compact faces as the sandbox publishes them: millimetres and metres.
void CompactFaceSeeds(const fs::path& dir) {
  for (const int encoding : {1, 2}) {
    sandbox_msgs::scan_face_compact_t face{};
    face.face = std::int8_t(encoding + 2), face.n = 5, face.resolution_m = 0.5;
    face.half_extent_m = 1.0, face.encoding = std::int8_t(encoding);
    face.sensor_position[2] = 60, face.sensor_orientation[0] = 1, face.box_orientation[0] = 1;
    if (encoding == 1) {
      face.num_mm = 25;
      for (int k = 0; k < 25; ++k) face.distance_mm.push_back(std::int16_t(k * 1000 - 3));
    } else {
      face.num_m = 25;
      for (int k = 0; k < 25; ++k) face.distance_m.push_back(k % 3 ? 0.25f * float(k) : INFINITY);
      face.num_runs = 3, face.run_surface = {0, 4, 9}, face.run_length = {5, 12, 8};  // an id plane
    }
    Write(dir / ("face_" + std::to_string(encoding)), Encode(face));
  }
}

// Robot descriptions: the first byte picks the format (even URDF, odd SDF).
void RobotDescriptionSeeds(const fs::path& dir, const fs::path& source) {
  Write(dir / "arm.urdf", "\x00" + Read(source / "assets/arm/arm.urdf"));
  Write(dir / "joints.sdf",
        "\x01<?xml version=\"1.0\"?>\n<sdf version=\"1.7\"><model name=\"m\">"
        "<link name=\"a\"><visual name=\"v\"><geometry><box><size>1 1 1</size></box>"
        "</geometry></visual><collision name=\"c\"><geometry><sphere><radius>0.5</radius>"
        "</sphere></geometry></collision></link>"
        "<link name=\"b\"><pose>1 2 3 0.1 0.2 0.3</pose><visual name=\"v\"><geometry>"
        "<cylinder><radius>0.2</radius><length>1</length></cylinder></geometry></visual></link>"
        "<joint name=\"j\" type=\"revolute\"><parent>a</parent><child>b</child>"
        "<pose>0.4 -0.2 0.1 0.5 0 -0.4</pose><axis><xyz>0 0 1</xyz><limit><lower>-1</lower>"
        "<upper>1</upper></limit></axis></joint>"
        "<link name=\"c\"><visual name=\"v\"><geometry><box><size>1 1 1</size></box>"
        "</geometry></visual></link><joint name=\"k\" type=\"prismatic\"><parent>b</parent>"
        "<child>c</child><axis><xyz>1 0 0</xyz><limit><lower>0</lower><upper>0.5</upper>"
        "</limit></axis></joint></model></sdf>\n");
}

}  // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: make_fuzz_seeds DIR SOURCE_DIR\n");
    return 2;
  }
  const fs::path dir = argv[1];
  ManifestSeeds(dir / "manifest", argv[2]);
  LcmSeeds(dir / "lcm_inputs");
  UdpSeeds(dir / "udp");
  LogSeeds(dir / "lcm_log");
  McapSeeds(dir / "mcap");
  FoxgloveRequestSeeds(dir / "foxglove_request");
  LevelFileSeeds(dir / "level_file");
  RasterSeeds(dir / "raster");
  TileCacheSeeds(dir / "tile_cache");
  CompactFaceSeeds(dir / "compact_face");
  RobotDescriptionSeeds(dir / "robot_description", argv[2]);
  WebRequestSeeds(dir / "web_request");
  std::printf("make_fuzz_seeds: seeds in %s\n", dir.string().c_str());
  return 0;
}
