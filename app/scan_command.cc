#include "app/scan_command.h"

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iomanip>
#include <sstream>

#include "app/command_line.h"
#include "app/defaults.h"
#include "app/loaded_level.h"
#include "app/scan_sheet.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/manifest.h"
#include "scene/terrain_streamer.h"
#include "sensors/face_scanner.h"
#include "sensors/ground_scanner.h"
#include "sensors/lidar.h"
#include "sensors/range_sensor.h"

namespace sandbox::app {
namespace {

const char* kUsage =
    "usage: sandbox scan [LEVEL] --at X,Y,Z[,ROLL,PITCH,YAW] [--sensor face|ground|lidar|ray]\n"
    "                    [--resolution R] [--half-extent E] [--aligned body|world]\n"
    "                    [--lidar SETTINGS] [--see-robots] [--isolate]\n"
    "                    --out FILE.csv|FILE.ply|FILE.png\n"
    "  LEVEL          a level (default: the bundled sample level)\n"
    "  --isolate      read a manifest's files apart first (scene files always are)\n"
    "  --at           sensor pose: metres, roll/pitch/yaw in degrees\n"
    "  --sensor       face (default): the six-face scanner, all faces; ground: height map\n"
    "                 below; lidar: 16 x 1024 beams, -15..15 degrees, 100 m; ray: one ray down\n"
    "  --resolution   grid spacing of face and ground, metres (default 1)\n"
    "  --half-extent  half the box of face and ground, metres (default 25)\n"
    "  --aligned      face box with the sensor's axes (body, default) or the world's\n"
    "  --lidar        the lidar's manifest keys as TOML, e.g. 'channels = 32,\n"
    "                 range_noise_sigma_m = 0.02, seed = 7' (docs/reference/sensors.md)\n"
    "  --see-robots   rays see the level's robots too (default: world actors only)\n"
    "  --out          CSV (face: face,row,col,occupancy,x,y,z; lidar: "
    "channel,step,hit,x,y,z,range,\n"
    "                 intensity, with divergence last_range,last_surface,last_intensity;\n"
    "                 ground: row,col,valid,x,y,z; ray: hit,x,y,z,range; then on every row\n"
    "                 surface,nx,ny,nz: what the sample hit and its normal) or PLY when it\n"
    "                 ends in .ply (occupied points red, free points green, with surface and\n"
    "                 normal); the surface ids' table beside it in FILE_surfaces.csv; face\n"
    "                 scans also as a sheet when it ends in .png (the six faces as distance\n"
    "                 images, unfolded cube, colour bar); see docs/reference/sensors.md\n";

// One sample for the writers.
struct Sample {
  std::string key;  // the leading CSV columns, e.g. "0,12,7"
  bool occupied;
  Eigen::Vector3d point_W;
  std::string extra;        // trailing CSV columns, e.g. ",37.2"
  std::int32_t surface{0};  // what it hit (scene/surface_ids.h), 0: nothing
  Eigen::Vector3f normal_W{Eigen::Vector3f::Zero()};
};

void WriteSamples(const std::string& file, const std::string& header,
                  const std::vector<Sample>& samples) {
  std::ofstream out(file);
  const bool ply = file.size() > 4 && file.substr(file.size() - 4) == ".ply";
  out << std::setprecision(10);
  if (ply) {
    out << "ply\nformat ascii 1.0\ncomment sandbox scan: occupied red, free green; world frame, "
           "metres\nelement vertex "
        << samples.size()
        << "\nproperty double x\nproperty double y\nproperty double z\nproperty uchar red\n"
           "property uchar green\nproperty uchar blue\nproperty int surface\n"
           "property float nx\nproperty float ny\nproperty float nz\nend_header\n";
    for (const Sample& s : samples) {
      out << s.point_W.x() << " " << s.point_W.y() << " " << s.point_W.z() << " "
          << (s.occupied ? "255 0 0" : "0 255 0") << " " << s.surface << " " << s.normal_W.x()
          << " " << s.normal_W.y() << " " << s.normal_W.z() << "\n";
    }
  } else {
    out << header << ",surface,nx,ny,nz\n";
    for (const Sample& s : samples) {
      out << s.key << s.point_W.x() << "," << s.point_W.y() << "," << s.point_W.z() << s.extra
          << "," << s.surface << "," << s.normal_W.x() << "," << s.normal_W.y() << ","
          << s.normal_W.z() << "\n";
    }
  }
  out.close();  // the last buffer's write errors show here
  if (!out) throw CommandError("cannot write " + file);
}

// The surface ids' table (scene::CollisionWorld::SurfaceTable()) as CSV.
void WriteSurfaceTable(const std::string& file, const std::vector<scene::SurfaceEntry>& table) {
  std::ofstream out(file);
  out << "id,kind,name,actor,robot,bone\n";
  for (const scene::SurfaceEntry& e : table) {
    out << e.id << "," << e.kind << "," << e.name << "," << e.actor << "," << e.robot_name << ","
        << e.bone_name << "\n";
  }
  out.close();
  if (!out) throw CommandError("cannot write " + file);
}

// FILE.csv -> FILE_surfaces.csv
std::string SurfaceTableFile(const std::string& out_file) {
  std::filesystem::path path(out_file);
  return (path.parent_path() / (path.stem().string() + "_surfaces.csv")).string();
}

double Positive(const std::string& text, const std::string& option) {
  const std::vector<double> v = ParseNumbers(text, option);
  if (v.size() != 1 || !(v[0] > 0.0)) throw UsageError(option + " must be one positive number");
  return v[0];
}

// The lidar of `sandbox scan`: the manifest's lidar keys given on the command
// line (their defaults without), refused naming the key.
}  // namespace

int RunScan(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed = ParseArgs(
      args, "scan",
      {"--at", "--sensor", "--resolution", "--half-extent", "--aligned", "--lidar", "--out"},
      {"--see-robots", "--isolate"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  const std::string level_file = parsed->level.value_or(kDefaultLevel);
  const std::string at = parsed->Value("--at"), out_file = parsed->Value("--out");
  const std::string sensor = parsed->Value("--sensor", "face");
  const std::string aligned = parsed->Value("--aligned", "body");
  const std::string resolution = parsed->Value("--resolution");
  const std::string half_extent = parsed->Value("--half-extent");
  const bool see_robots = parsed->flags.count("--see-robots") > 0;
  if (at.empty() || out_file.empty()) {
    err << "sandbox scan: --at and --out are required\n" << kUsage;
    return 2;
  }
  if (sensor != "face" && sensor != "ground" && sensor != "lidar" && sensor != "ray") {
    err << "sandbox scan: --sensor must be face, ground, lidar or ray, got '" << sensor << "'\n";
    return 2;
  }
  const bool sheet = out_file.size() > 4 && out_file.substr(out_file.size() - 4) == ".png";
  if (sheet && sensor != "face") {
    err << "sandbox scan: a .png sheet is drawn for face scans only; use .csv or .ply for "
        << sensor << "\n";
    return 2;
  }
  if (aligned != "body" && aligned != "world") {
    err << "sandbox scan: --aligned must be body or world, got '" << aligned << "'\n";
    return 2;
  }
  try {
    const Eigen::Isometry3d X_WS = ParsePose(at, "--at");
    const double res = resolution.empty() ? 1.0 : Positive(resolution, "--resolution");
    const double extent = half_extent.empty() ? 25.0 : Positive(half_extent, "--half-extent");
    if (parsed->values.count("--lidar") > 0 && sensor != "lidar") {
      throw UsageError("--lidar sets the lidar: give --sensor lidar");
    }
    // Checked before the level loads.
    sensors::LidarConfig lidar_config;
    try {
      lidar_config = sensors::LidarConfig::FromText(parsed->Value("--lidar"), "--lidar");
    } catch (const std::invalid_argument& error) {
      throw UsageError(error.what());
    }

    const LoadedLevel loaded = LoadCheckedLevel(
        level_file, {},
        parsed->flags.count("--isolate") > 0 ? Isolation::kAlways : Isolation::kSceneFiles);
    const scene::Level& level = loaded.level;
    scene::CollisionWorld world(level);
    if (level.terrain) {  // the fine tiles around the sensor, in before the scan
      scene::TerrainStreamer terrain(level);
      terrain.Update({X_WS.translation()}, 0.0, &world, scene::TerrainStreamer::Wait::kFine);
      for (const std::string& message : terrain.TakeMessages()) {
        err << "sandbox scan: " << message << "\n";
      }
    }
    // The floating origin at the sensor (whole metres), as the loop keeps it near the robot.
    world.SetOrigin(X_WS.translation().array().round().matrix());
    sensors::RayCaster caster;
    sensors::RayFilter filter;
    if (!see_robots) filter.group_mask = scene::kWorldStatic | scene::kWorldMovable;
    const auto start = std::chrono::steady_clock::now();
    std::vector<Sample> samples;
    std::string header;
    if (sensor == "face") {
      sensors::FaceScannerConfig config;
      config.resolution_m = res;
      config.half_extent_m = extent;
      config.refresh = sensors::Refresh::kFull;
      config.sample_budget = 1e7;  // a one-off scan may be finer than a sensor of the loop
      config.alignment = aligned == "body" ? sensors::Alignment::kBody : sensors::Alignment::kWorld;
      config.normals = true;
      const sensors::FaceScanner scanner(config);
      sensors::FaceScan scan = scanner.EmptyScan();
      scanner.Scan(world, caster, filter, X_WS, 0, &scan);
      if (sheet) {
        try {
          std::ostringstream title;
          title << "face scan " << scan.n << "x" << scan.n << "x6 at " << res << " m, half extent "
                << extent << " m, " << level_file;
          WriteFaceScanSheet(scan, extent, out_file, title.str());
        } catch (const std::runtime_error& error) {
          throw CommandError(error.what());
        }
      }
      header = "face,row,col,occupancy,x,y,z";
      for (int f = 0; f < 6; ++f) {
        const sensors::ScanFace& face = scan.faces[std::size_t(f)];
        for (int k = 0; k < scan.n * scan.n; ++k) {
          const int occupancy = face.occupancy[std::size_t(k)];
          samples.push_back({std::to_string(f) + "," + std::to_string(k / scan.n) + "," +
                                 std::to_string(k % scan.n) + "," + std::to_string(occupancy) + ",",
                             occupancy == sensors::kOccupied, scan.PointW(f, std::size_t(k)), "",
                             face.surface[std::size_t(k)], face.normal_W[std::size_t(k)]});
        }
      }
    } else if (sensor == "ground") {
      sensors::GroundScannerConfig config;
      config.resolution_m = res;
      config.half_extent_m = extent;
      config.normals = true;
      sensors::HeightMap map;
      sensors::GroundScanner(config).Scan(world, caster, filter, X_WS.translation(), &map);
      header = "row,col,valid,x,y,z";
      for (int k = 0; k < map.n * map.n; ++k) {
        const int r = k / map.n, c = k % map.n;
        const double h = map.height_m[std::size_t(k)];
        const bool valid = !std::isnan(h);
        const Eigen::Vector3d p(map.corner_W.x() + c * map.resolution_m,
                                map.corner_W.y() + r * map.resolution_m,
                                valid ? h : X_WS.translation().z() - config.depth_m);
        samples.push_back(
            {std::to_string(r) + "," + std::to_string(c) + "," + std::to_string(int(valid)) + ",",
             valid, p, "", map.surface[std::size_t(k)], map.normal_W[std::size_t(k)]});
      }
    } else if (sensor == "lidar") {
      sensors::LidarConfig config = lidar_config;
      config.normals = true;
      const sensors::Lidar lidar(config);
      sensors::LidarScan scan;
      lidar.Sweep(world, caster, filter, X_WS, X_WS, &scan);
      const bool bright = !scan.intensity.empty(), lasts = !scan.last_range_m.empty();
      header = "channel,step,hit,x,y,z,range";
      if (bright) header += ",intensity";
      if (lasts) header += bright ? ",last_range,last_surface,last_intensity" : ",last_range,last_surface";
      for (std::size_t i = 0; i < scan.range_m.size(); ++i) {
        const std::size_t c = i / std::size_t(scan.azimuth_steps);
        const std::size_t k = i % std::size_t(scan.azimuth_steps);
        std::ostringstream range;
        range << std::setprecision(10) << "," << scan.range_m[i];
        if (bright) range << "," << scan.intensity[i];
        if (lasts) range << "," << scan.last_range_m[i] << "," << scan.last_surface[i];
        if (lasts && bright) range << "," << scan.last_intensity[i];
        samples.push_back({std::to_string(c) + "," + std::to_string(k) + "," +
                               std::to_string(int(scan.hit[i])) + ",",
                           scan.hit[i] != 0, scan.points_W[i], range.str(), scan.surface[i],
                           scan.normal_W[i]});
      }
    } else {
      const sensors::RangeReading reading = sensors::MeasureRange({}, world, caster, filter, X_WS);
      header = "hit,x,y,z,range";
      std::ostringstream range;
      range << std::setprecision(10) << "," << reading.range_m;
      samples.push_back({std::to_string(int(reading.hit)) + ",", reading.hit, reading.point_W,
                         range.str(), reading.surface, reading.normal_W.cast<float>()});
    }
    const double ms =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
    if (!sheet) WriteSamples(out_file, header, samples);
    WriteSurfaceTable(SurfaceTableFile(out_file), world.SurfaceTable());
    std::size_t occupied = 0;
    for (const Sample& s : samples) occupied += s.occupied ? 1 : 0;
    const Eigen::Vector3d p = X_WS.translation();
    out << sensor << " scan at (" << p.x() << ", " << p.y() << ", " << p.z()
        << "): " << samples.size() << " rays, " << occupied << " hit, " << std::fixed
        << std::setprecision(2) << ms << " ms -> " << out_file << " (surfaces "
        << SurfaceTableFile(out_file) << ")\n";
    return 0;
  } catch (const scene::LevelError& error) {
    err << "sandbox scan: " << error.what() << "\n";
    return 1;
  } catch (const UsageError& error) {
    err << "sandbox scan: " << error.what() << "\n";
    return 2;
  } catch (const CommandError& error) {
    err << "sandbox scan: " << error.what() << "\n";
    return 1;
  } catch (const std::invalid_argument& error) {  // a sensor setting from the options
    err << "sandbox scan: " << error.what() << "\n";
    return 2;
  }
}

}  // namespace sandbox::app
