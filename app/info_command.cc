#include "app/info_command.h"

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <iomanip>
#include <optional>
#include <sstream>
#include <variant>

#include "app/command_line.h"
#include "app/defaults.h"
#include "app/isolated_load.h"
#include "app/loaded_level.h"
#include "app/process_stats.h"
#include "scene/collision_world.h"
#include "scene/level.h"
#include "scene/terrain_source.h"
#include "sensors/sensor.h"

namespace sandbox::app {
namespace {

// The link a described robot's joint moves: its bone's node, or the node
// hanging from it (a joint turning about a point off its link's origin).
const std::string& MovedLink(const scene::RobotModel& r, const scene::Bone& bone) {
  const std::string& name = r.nodes[std::size_t(bone.node)].name;
  if (std::find(r.links.begin(), r.links.end(), name) != r.links.end()) return name;
  for (const scene::RobotNode& node : r.nodes) {
    if (node.parent == bone.node) return node.name;
  }
  return name;
}

// A robot description's joint kind, from its bone.
const char* JointType(const scene::Bone& bone) {
  if (bone.rotation == scene::BoneRotation::kSlide) return "prismatic";
  return std::isfinite(bone.lower) || std::isfinite(bone.upper) ? "revolute" : "continuous";
}

using scene::Level;

struct LoadFigures {
  double level_s{0.0};            // files read and converted
  double collision_world_s{0.0};  // Bullet shapes and BVHs built
  double peak_memory_mib{0.0};
  int collision_objects{0};
  std::size_t merged_static_triangles{0};  // CollisionWorld::merged_static_triangles
};

// A level's [[terrain]] as its rasters give it (the terrain actor has no
// meshes: its tiles are built while running).
struct TerrainFigures {
  int usable{0};                 // elevation rasters that serve
  double fine_tile_m{0.0};       // a fine tile's side
  Eigen::AlignedBox3d bounds_W;  // TerrainSource::Bounds_W
  Eigen::AlignedBox2d ground_W;  // TerrainSource::InnerFootprint_W
};

std::optional<TerrainFigures> TerrainOf(const Level& level) {
  if (!level.terrain) return std::nullopt;
  const scene::TerrainSource source(*level.terrain);
  return TerrainFigures{source.num_usable(), source.fine_tile_m(), source.Bounds_W(),
                        source.InnerFootprint_W()};
}

// The level's bounds with its terrain's.
Eigen::AlignedBox3d BoundsOf(const Level& level, const std::optional<TerrainFigures>& terrain) {
  Eigen::AlignedBox3d bounds = level.bounds_W();
  if (terrain && !terrain->bounds_W.isEmpty()) bounds.extend(terrain->bounds_W);
  return bounds;
}

// An actor's bounds; the terrain actor's are its rasters'.
Eigen::AlignedBox3d ActorBounds(const Level& level, std::size_t actor,
                                const std::optional<TerrainFigures>& terrain) {
  if (terrain && int(actor) == level.terrain_actor) return terrain->bounds_W;
  return level.actors[actor].bounds_W;
}

std::string JsonString(const std::string& text) {
  std::string out = "\"";
  for (const char c : text) {
    if (c == '"' || c == '\\') {
      out += '\\', out += c;
    } else if (static_cast<unsigned char>(c) < 0x20) {
      char escaped[8];
      std::snprintf(escaped, sizeof(escaped), "\\u%04x", c);
      out += escaped;
    } else {
      out += c;
    }
  }
  return out + "\"";
}

std::string JsonVector(const Eigen::Vector3d& v) {
  std::ostringstream out;
  out << std::setprecision(9) << "[" << v.x() << ", " << v.y() << ", " << v.z() << "]";
  return out.str();
}

// Empty bounds (an actor without meshes) print as zeros.
Eigen::Vector3d Lo(const Eigen::AlignedBox3d& b) {
  return b.isEmpty() ? Eigen::Vector3d::Zero() : b.min();
}
Eigen::Vector3d Hi(const Eigen::AlignedBox3d& b) {
  return b.isEmpty() ? Eigen::Vector3d::Zero() : b.max();
}

void PrintJson(const Level& level, const std::vector<sensors::MountedSensor>& sensors,
               const LoadFigures& figures, const std::optional<TerrainFigures>& terrain,
               std::ostream& out) {
  std::size_t vertices = 0, collision_actors = 0, movable_actors = 0;
  out << "{\n  \"level\": {\"name\": " << JsonString(level.name)
      << ", \"file\": " << JsonString(level.file.string()) << "},\n  \"actors\": [";
  for (std::size_t i = 0; i < level.actors.size(); ++i) {
    const scene::Actor& a = level.actors[i];
    vertices += a.num_vertices();
    collision_actors += a.collision ? 1 : 0;
    movable_actors += a.movable ? 1 : 0;
    out << (i > 0 ? ",\n" : "\n") << "    {\"name\": " << JsonString(a.name)
        << ", \"triangles\": " << a.num_triangles() << ", \"vertices\": " << a.num_vertices()
        << ", \"collision\": " << (a.collision ? "true" : "false")
        << ", \"movable\": " << (a.movable ? "true" : "false")
        << ", \"bounds_min\": " << JsonVector(Lo(ActorBounds(level, i, terrain)))
        << ", \"bounds_max\": " << JsonVector(Hi(ActorBounds(level, i, terrain))) << "}";
  }
  out << "\n  ],\n  \"robots\": [";
  for (std::size_t i = 0; i < level.robots.size(); ++i) {
    const scene::RobotModel& r = level.robots[i];
    out << (i > 0 ? ",\n" : "\n") << "    {\"name\": " << JsonString(r.name)
        << ", \"file\": " << JsonString(r.file.string()) << ", \"nodes\": " << r.nodes.size()
        << ", \"bones\": " << r.bones.size() << ", \"bone_values\": " << r.num_values
        << ", \"vertices\": " << r.num_vertices() << ", \"triangles\": " << r.num_triangles()
        << ", \"collision\": " << (r.collision ? "true" : "false")
        << ", \"spawn_position\": " << JsonVector(r.X_WB_spawn.translation());
    if (r.described) {
      out << ", \"links\": [";
      for (std::size_t n = 0; n < r.links.size(); ++n) {
        out << (n > 0 ? ", " : "") << JsonString(r.links[n]);
      }
      out << "], \"joints\": [";
      for (std::size_t b = 0; b < r.bones.size(); ++b) {
        const scene::Bone& bone = r.bones[b];
        const scene::RobotNode& moving = r.nodes[std::size_t(bone.node)];
        auto limit = [](double value) {
          return std::isfinite(value) ? std::to_string(value) : std::string("null");
        };
        out << (b > 0 ? ", " : "") << "{\"name\": " << JsonString(bone.name)
            << ", \"type\": " << JsonString(JointType(bone))
            << ", \"link\": " << JsonString(MovedLink(r, bone))
            << ", \"parent\": " << JsonString(r.nodes[std::size_t(moving.parent)].name)
            << ", \"axis\": " << JsonVector(bone.axes[0]) << ", \"lower\": " << limit(bone.lower)
            << ", \"upper\": " << limit(bone.upper) << "}";
      }
      out << "]";
    }
    out << ", \"sensors\": [";
    bool first = true;
    for (const sensors::MountedSensor& sensor : sensors) {
      if (sensor.robot != static_cast<int>(i)) continue;
      out << (first ? "" : ", ") << "{\"name\": " << JsonString(sensor.spec.name)
          << ", \"type\": " << JsonString(sensor.spec.type)
          << ", \"mount\": " << JsonString(sensor.spec.mount.empty() ? "body" : sensor.spec.mount)
          << ", \"rate_hz\": " << sensor.spec.rate_hz << "}";
      first = false;
    }
    out << "]}";
  }
  out << "\n  ],\n";
  if (terrain) {
    const scene::TerrainSpec& t = *level.terrain;
    const Eigen::AlignedBox2d& g = terrain->ground_W;
    auto xy = [](const Eigen::Vector2d& v) { return JsonVector({v.x(), v.y(), 0.0}); };
    out << "  \"terrain\": {\"name\": " << JsonString(t.name)
        << ", \"elevation_rasters\": " << t.elevation.size()
        << ", \"usable_rasters\": " << terrain->usable
        << ", \"imagery_rasters\": " << t.imagery.size() << ", \"anchor\": "
        << JsonVector({t.anchor.latitude_deg, t.anchor.longitude_deg, t.anchor.height_m})
        << ", \"fine_tile_m\": " << terrain->fine_tile_m
        << ", \"collision_radius_m\": " << t.collision_radius_m
        << ", \"view_radius_m\": " << t.view_radius_m
        << ", \"bounds_min\": " << JsonVector(Lo(terrain->bounds_W))
        << ", \"bounds_max\": " << JsonVector(Hi(terrain->bounds_W))
        << ", \"ground_min\": " << xy(g.isEmpty() ? Eigen::Vector2d::Zero() : g.min())
        << ", \"ground_max\": " << xy(g.isEmpty() ? Eigen::Vector2d::Zero() : g.max()) << "},\n";
  }
  const Eigen::AlignedBox3d bounds = BoundsOf(level, terrain);
  out << "  \"totals\": {\"actors\": " << level.actors.size()
      << ", \"collision_actors\": " << collision_actors
      << ", \"movable_actors\": " << movable_actors << ", \"triangles\": " << level.num_triangles()
      << ", \"vertices\": " << vertices << ", \"materials\": " << level.materials.size()
      << ", \"textures\": " << level.textures.size()
      << ", \"collision_objects\": " << figures.collision_objects
      << ", \"merged_static_triangles\": " << figures.merged_static_triangles
      << ", \"bounds_min\": " << JsonVector(Lo(bounds))
      << ", \"bounds_max\": " << JsonVector(Hi(bounds)) << "},\n";
  out << std::fixed << std::setprecision(4) << "  \"load\": {\"level_s\": " << figures.level_s
      << ", \"collision_world_s\": " << figures.collision_world_s
      << ", \"total_s\": " << figures.level_s + figures.collision_world_s << std::setprecision(1)
      << ", \"peak_memory_mib\": " << figures.peak_memory_mib << "},\n  \"warnings\": [";
  for (std::size_t i = 0; i < level.warnings.size(); ++i) {
    out << (i > 0 ? ", " : "") << JsonString(level.warnings[i]);
  }
  out << "]\n}\n";
}

void PrintText(const Level& level, const std::vector<sensors::MountedSensor>& sensors,
               const LoadFigures& figures, const std::optional<TerrainFigures>& terrain,
               std::ostream& out) {
  std::size_t name_width = 5;
  for (const scene::Actor& a : level.actors) name_width = std::max(name_width, a.name.size());
  name_width = std::min<std::size_t>(name_width, 48);
  out << "level " << level.name << " (" << level.file.string() << ")\n\n";
  out << std::left << std::setw(static_cast<int>(name_width)) << "actor" << std::right
      << std::setw(11) << "triangles"
      << "  collision  movable  bounds min .. max (m)\n";
  out << std::fixed << std::setprecision(2);
  for (std::size_t i = 0; i < level.actors.size(); ++i) {
    const scene::Actor& a = level.actors[i];
    const Eigen::AlignedBox3d box = ActorBounds(level, i, terrain);
    const Eigen::Vector3d lo = Lo(box), hi = Hi(box);
    out << std::left << std::setw(static_cast<int>(name_width)) << a.name << std::right
        << std::setw(11) << a.num_triangles() << "  " << std::left << std::setw(9)
        << (a.collision ? "yes" : "no") << "  " << std::setw(7) << (a.movable ? "yes" : "no")
        << std::right << "  (" << lo.x() << ", " << lo.y() << ", " << lo.z() << ") .. (" << hi.x()
        << ", " << hi.y() << ", " << hi.z() << ")\n";
  }
  for (const scene::RobotModel& r : level.robots) {
    const Eigen::Vector3d p = r.X_WB_spawn.translation();
    out << "robot " << r.name << ": " << r.file.filename().string() << ", " << r.nodes.size()
        << " nodes, " << r.bones.size() << " bones (" << r.num_values << " values), "
        << r.num_vertices() << " vertices, " << r.num_triangles() << " triangles, collision "
        << (r.collision ? "on" : "off") << ", spawn (" << p.x() << ", " << p.y() << ", " << p.z()
        << ")\n";
    if (r.described) {
      out << "  links:";
      for (const std::string& link : r.links) out << " " << link;
      out << "\n";
      for (std::size_t b = 0; b < r.bones.size(); ++b) {
        const scene::Bone& bone = r.bones[b];
        const scene::RobotNode& moving = r.nodes[std::size_t(bone.node)];
        const Eigen::Vector3d& axis = bone.axes[0];
        out << "  joint " << b << " " << bone.name << ": " << JointType(bone) << ", moves "
            << MovedLink(r, bone) << " on " << r.nodes[std::size_t(moving.parent)].name
            << ", axis (" << axis.x() << ", " << axis.y() << ", " << axis.z() << ")";
        if (std::isfinite(bone.lower) || std::isfinite(bone.upper)) {
          out << std::setprecision(4) << ", limits " << bone.lower << " .. " << bone.upper
              << (bone.rotation == scene::BoneRotation::kSlide ? " m" : " rad")
              << std::setprecision(2);
        }
        out << "\n";
      }
    }
    for (const sensors::MountedSensor& sensor : sensors) {
      if (level.robots[static_cast<std::size_t>(sensor.robot)].name != r.name) continue;
      out << "  sensor " << sensor.spec.name << ": " << sensor.Describe() << "\n";
    }
  }
  if (terrain) {
    const scene::TerrainSpec& t = *level.terrain;
    const Eigen::AlignedBox2d& ground = terrain->ground_W;
    out << "terrain " << t.name << ": " << terrain->usable << " of " << t.elevation.size()
        << " elevation rasters, " << t.imagery.size() << " imagery; anchor " << std::setprecision(6)
        << t.anchor.latitude_deg << ", " << t.anchor.longitude_deg << ", " << std::setprecision(2)
        << t.anchor.height_m << " m; fine tiles of " << terrain->fine_tile_m << " m within "
        << t.collision_radius_m << " m, coarse within " << t.view_radius_m
        << " m (streamed while running)\n";
    if (!ground.isEmpty()) {
      out << "  ground from (" << ground.min().x() << ", " << ground.min().y() << ") to ("
          << ground.max().x() << ", " << ground.max().y() << ") m, inside the outermost tiles\n";
    }
  }
  const Eigen::AlignedBox3d bounds = BoundsOf(level, terrain);
  const Eigen::Vector3d size = Hi(bounds) - Lo(bounds);
  out << "\ntotal " << level.actors.size() << " actors, " << level.num_triangles() << " triangles, "
      << level.materials.size() << " materials, " << level.textures.size() << " embedded textures, "
      << figures.collision_objects << " collision objects\n";
  out << "rays  "
      << (figures.merged_static_triangles > 0
              ? "the static actors' " + std::to_string(figures.merged_static_triangles) +
                    " triangles in one hierarchy"
              : std::string("a hierarchy per object (fewer than two static objects, "
                            "or over 2^20 static triangles)"))
      << "\n";
  out << "size  " << size.x() << " x " << size.y() << " x " << size.z() << " m, from ("
      << Lo(bounds).x() << ", " << Lo(bounds).y() << ", " << Lo(bounds).z() << ") to ("
      << Hi(bounds).x() << ", " << Hi(bounds).y() << ", " << Hi(bounds).z() << ")\n";
  out << std::setprecision(3) << "load  " << figures.level_s + figures.collision_world_s
      << " s (files " << figures.level_s << " s, collision world " << figures.collision_world_s
      << " s), peak memory " << std::setprecision(1) << figures.peak_memory_mib << " MiB\n";
  for (const std::string& warning : level.warnings) out << "warning: " << warning << "\n";
}

const char* kUsage =
    "usage: sandbox info [LEVEL] [--json] [--up AXIS] [--unit-scale METRES] [--isolate]\n"
    "  LEVEL         a level manifest (.toml) or any scene file assimp reads\n"
    "                (default: the bundled sample level); a scene file is first read in a\n"
    "                separate process, so that a file that crashes assimp is an error\n"
    "  --isolate     read a manifest's assets that way too\n"
    "  --json        machine-readable output (docs/reference/info-json.md)\n"
    "  --up AXIS     up axis of a scene file that does not say: x, -x, y, -y, z, -z\n"
    "  --unit-scale  metres per unit of a scene file that does not say\n";

}  // namespace

int RunInfo(const std::vector<std::string>& args, std::ostream& out, std::ostream& err) {
  const auto parsed =
      ParseArgs(args, "info", {"--up", "--unit-scale"}, {"--json", "--isolate"}, kUsage, err);
  if (!parsed) return 2;
  if (parsed->help) {
    out << kUsage;
    return 0;
  }
  const std::string file = parsed->level.value_or(kDefaultLevel);
  const bool json = parsed->flags.count("--json") > 0;
  scene::AssetConversion conversion;
  if (parsed->values.count("--up") > 0) {
    conversion.up = scene::ParseUpAxis(parsed->Value("--up"));
    if (!conversion.up) {
      err << "sandbox info: --up must be one of x, -x, y, -y, z, -z, got '" << parsed->Value("--up")
          << "'\n";
      return 2;
    }
  }
  if (parsed->values.count("--unit-scale") > 0) {
    const std::string text = parsed->Value("--unit-scale");
    char* end = nullptr;
    const double value = std::strtod(text.c_str(), &end);
    if (*end != '\0' || !(value > 0.0) || !std::isfinite(value)) {
      err << "sandbox info: --unit-scale must be a positive number, got '" << text << "'\n";
      return 2;
    }
    conversion.unit_scale_m = value;
  }

  // A scene file is someone else's: assimp reads it apart first (a crash
  // becomes an error). A manifest's own assets are read apart with --isolate.
  // Apart from the timed load below, whose figures are the level's own.
  if (parsed->flags.count("--isolate") > 0 || !IsManifest(file)) {
    try {
      CheckLoadsInIsolation(file, conversion);
    } catch (const scene::LevelError& error) {
      err << "sandbox info: " << error.what() << "\n";
      return 1;
    }
  }
  using Clock = std::chrono::steady_clock;
  try {
    LoadFigures figures;
    const auto start = Clock::now();
    // The checks `sandbox run` makes, too: what info accepts, run accepts.
    const LoadedLevel loaded_level = LoadCheckedLevel(file, conversion, Isolation::kNever);
    const Level& level = loaded_level.level;
    const std::vector<sensors::MountedSensor>& sensors = loaded_level.sensors;
    const auto loaded = Clock::now();
    const scene::CollisionWorld world(level);
    const auto built = Clock::now();
    figures.level_s = std::chrono::duration<double>(loaded - start).count();
    figures.collision_world_s = std::chrono::duration<double>(built - loaded).count();
    figures.peak_memory_mib = PeakResidentMiB();
    figures.collision_objects = world.num_collision_objects();
    figures.merged_static_triangles = world.merged_static_triangles();
    const std::optional<TerrainFigures> terrain = TerrainOf(level);
    if (json) {
      PrintJson(level, sensors, figures, terrain, out);
    } else {
      PrintText(level, sensors, figures, terrain, out);
    }
    return 0;
  } catch (const scene::LevelError& error) {
    err << "sandbox info: " << error.what() << "\n";
    return 1;
  }
}

}  // namespace sandbox::app
