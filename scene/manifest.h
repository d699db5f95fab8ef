#pragma once
// The TOML level manifest (docs/reference/levels.md is the reference). Parsing only:
// values are checked here, files are read by the level loader.

#include <Eigen/Geometry>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/load_limits.h"
#include "scene/placement.h"
#include "scene/robot_model.h"
#include "scene/settings.h"
#include "scene/terrain_tile.h"
#include "scene/wind.h"

namespace sandbox::scene {

// One [[actor]] table: an asset file or a heightmap image placed in the world.
struct ActorSpec {
  std::string name;
  std::filesystem::path file;  // resolved against the manifest's folder
  bool is_heightmap{false};    // `heightmap = ...` instead of `file = ...`
  Eigen::Vector3d heightmap_size_m{Eigen::Vector3d::Zero()};
  Placement placement;
  bool collision{true};
  bool movable{false};
  std::optional<Surface> surface;      // `surface = "plain" | "terrain" | "water"`
  std::optional<double> reflectivity;  // `reflectivity = 0..1` (the lidar's intensity)
  // `material_reflectivity = { name = 0..1, ... }`: by material name, and the line.
  std::map<std::string, double> material_reflectivity;
  int material_reflectivity_line{0};
  int line{0};  // where the table starts, for messages
};

// The [horizon] table: the ground beyond the level, drawn to the horizon.
struct HorizonSpec {
  double height_m{0.0};
  Eigen::Vector3f rgb{0.42f, 0.47f, 0.33f};
  double visibility_m{0.0};  // 0: the renderer's own haze distance
};

struct LevelManifest {
  std::filesystem::path file;
  std::string name;
  LoadLimits limits;  // the defaults, or what [level] sets
  std::vector<ActorSpec> actors;
  std::vector<RobotSpec> robots;
  std::optional<TerrainSpec> terrain;  // [[terrain]] (at most one)
  std::optional<HorizonSpec> horizon;  // [horizon]
  std::optional<WindSpec> wind;        // [wind]
};

// The largest manifest read (a manifest is a few KB; this is no LoadLimits key).
constexpr std::uint64_t kMaxManifestBytes = 16u << 20;

// Throws LevelError "file:line: what" for a TOML syntax error, an unknown key,
// a wrong type, a missing or duplicate name, a negative scale, a non-finite
// number or one beyond 2^53, a non-unit quaternion or an inconsistent bone
// declaration; and "file: what" for a file that is not a regular file or is
// larger than kMaxManifestBytes.
LevelManifest ParseManifest(const std::filesystem::path& file);
// The same for manifest text that `file` would hold (asset paths resolve
// against its folder; nothing is read).
LevelManifest ParseManifestText(std::string_view text, const std::filesystem::path& file);

// A table's keys given as TOML on one line, "key = value, key = value" (a
// command line's sensor settings), as a manifest table's own would be kept:
// `origin` stands for the file in messages ("--lidar"), `context` for the
// table ("lidar"). Throws LevelError for a syntax error or a value that is not
// a number, a string, true/false or an array.
SettingsTable ParseSettingsText(const std::string& text, const std::string& origin,
                                const std::string& context);

}  // namespace sandbox::scene
