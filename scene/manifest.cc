// Over 600 lines: one parser for every table of a level manifest, with its one reader.
#include "scene/manifest.h"

#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "scene/files.h"
#include "scene/robot_description.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

// Reads typed values out of one TOML table, naming file, line and context in
// every error, and rejects keys it was never asked about. Its verbs are
// SettingsReader's (settings.h): Text, Flag, Number, Whole, Numbers.
class TableReader {
 public:
  TableReader(const fs::path& file, const toml::table& table, std::string context)
      : file_(file), table_(table), context_(std::move(context)) {}

  [[noreturn]] void Fail(const toml::node* node, const std::string& what) const {
    const int line = node != nullptr ? static_cast<int>(node->source().begin.line)
                                     : static_cast<int>(table_.source().begin.line);
    std::ostringstream out;
    out << file_.string() << ":" << line << ": " << context_ << what;
    throw LevelError(out.str());
  }

  const toml::node* Find(const std::string& key) {
    known_.insert(key);
    return table_.get(key);
  }

  std::optional<std::string> Text(const std::string& key) {
    const toml::node* node = Find(key);
    if (node == nullptr) return std::nullopt;
    if (!node->is_string()) Fail(node, "'" + key + "' must be a string");
    return node->value<std::string>();
  }

  std::optional<bool> Flag(const std::string& key) {
    const toml::node* node = Find(key);
    if (node == nullptr) return std::nullopt;
    if (!node->is_boolean()) Fail(node, "'" + key + "' must be true or false");
    return node->value<bool>();
  }

  double Number(const toml::node* node, const std::string& key) const {
    if (!node->is_number()) Fail(node, "'" + key + "' must be a number");
    // Integers beyond 2^53 have no double of their own (toml++ gives none at all).
    if (const toml::value<std::int64_t>* integer = node->as_integer()) {
      constexpr std::int64_t kExact = std::int64_t(1) << 53;
      if (integer->get() > kExact || integer->get() < -kExact) {
        Fail(node, "'" + key + "' is " + std::to_string(integer->get()) +
                       ", beyond 2^53 (numbers that large lose their last digits)");
      }
      return double(integer->get());
    }
    const double value = node->as_floating_point()->get();
    if (!std::isfinite(value)) Fail(node, "'" + key + "' must be finite, got " + Format(value));
    return value;
  }

  // A whole number from `low` to `high`.
  std::optional<std::int64_t> Whole(const std::string& key, std::int64_t low, std::int64_t high) {
    const std::optional<double> value = Number(key);
    if (!value) return std::nullopt;
    if (!(*value >= double(low) && *value <= double(high)) || *value != std::floor(*value)) {
      Fail(Find(key), "'" + key + "' must be a whole number from " + std::to_string(low) + " to " +
                          std::to_string(high));
    }
    return std::int64_t(*value);
  }

  std::optional<double> Number(const std::string& key) {
    const toml::node* node = Find(key);
    if (node == nullptr) return std::nullopt;
    return Number(node, key);
  }

  // An array of exactly `n` finite numbers.
  std::optional<Eigen::VectorXd> Numbers(const std::string& key, int n) {
    const toml::node* node = Find(key);
    if (node == nullptr) return std::nullopt;
    const toml::array* array = node->as_array();
    if (array == nullptr || static_cast<int>(array->size()) != n) {
      Fail(node, "'" + key + "' must be an array of " + std::to_string(n) + " numbers");
    }
    Eigen::VectorXd out(n);
    for (int i = 0; i < n; ++i) out[i] = Number(array->get(static_cast<std::size_t>(i)), key);
    return out;
  }

  // Every key of the table must have been asked for; `table` names its kind
  // for ReportKeys (settings.h).
  void RejectUnknownKeys(const std::string& table) const {
    ReportKeys(table, known_);
    for (const auto& [key, value] : table_) {
      if (known_.count(std::string(key.str())) == 0) {
        Fail(&value, "unknown key '" + std::string(key.str()) + "'");
      }
    }
  }

  const std::set<std::string>& asked() const { return known_; }

  static std::string Format(double value) {
    std::ostringstream out;
    out << value;
    return out.str();
  }

 private:
  const fs::path& file_;
  const toml::table& table_;
  std::string context_;
  std::set<std::string> known_;
};

// The required, non-empty `name` of the `index`-th table of `kind`.
std::string ParseName(const fs::path& file, const toml::table& table, const std::string& kind,
                      int index) {
  TableReader named(file, table, kind + " " + std::to_string(index) + ": ");
  const std::optional<std::string> name = named.Text("name");
  if (!name || name->empty()) named.Fail(nullptr, "'name' is required");
  return *name;
}

// An asset path relative to the manifest.
fs::path AssetPath(const fs::path& manifest, const std::string& relative) {
  return (manifest.parent_path() / relative).lexically_normal();
}

// position, rpy_deg | quaternion_wxyz, scale, up, unit_scale.
Placement ParsePlacement(TableReader& read) {
  Placement placement;
  if (const auto position = read.Numbers("position", 3)) placement.position_m = *position;
  const auto rpy = read.Numbers("rpy_deg", 3);
  const auto quaternion = read.Numbers("quaternion_wxyz", 4);
  if (rpy && quaternion) read.Fail(nullptr, "give either 'rpy_deg' or 'quaternion_wxyz', not both");
  if (rpy) {
    placement.rotation = Eigen::Quaterniond(RotationFromRollPitchYaw(
        (*rpy)[0] * kDegToRad, (*rpy)[1] * kDegToRad, (*rpy)[2] * kDegToRad));
  }
  if (quaternion) {
    const Eigen::Quaterniond q((*quaternion)[0], (*quaternion)[1], (*quaternion)[2],
                               (*quaternion)[3]);
    if (std::abs(q.norm() - 1.0) > 1e-3) {
      read.Fail(read.Find("quaternion_wxyz"),
                "'quaternion_wxyz' must be a unit quaternion, its norm is " +
                    TableReader::Format(q.norm()));
    }
    placement.rotation = q.normalized();
  }
  if (const toml::node* scale = read.Find("scale")) {
    if (scale->is_array()) {
      placement.scale = *read.Numbers("scale", 3);
    } else {
      placement.scale.setConstant(read.Number(scale, "scale"));
    }
    if ((placement.scale.array() <= 0.0).any()) {
      read.Fail(scale,
                "'scale' must be positive, got " + TableReader::Format(placement.scale.minCoeff()));
    }
  }
  // How to read the asset when its file does not say.
  if (const auto up = read.Text("up")) {
    placement.conversion.up = ParseUpAxis(*up);
    if (!placement.conversion.up) {
      read.Fail(read.Find("up"), "'up' must be one of x, -x, y, -y, z, -z, got '" + *up + "'");
    }
  }
  if (const auto unit = read.Number("unit_scale")) {
    if (*unit <= 0.0) read.Fail(read.Find("unit_scale"), "'unit_scale' must be positive");
    placement.conversion.unit_scale_m = *unit;
  }
  return placement;
}

ActorSpec ParseActor(const fs::path& file, const toml::table& table, int index) {
  ActorSpec actor;
  actor.line = static_cast<int>(table.source().begin.line);
  actor.name = ParseName(file, table, "actor", index);
  TableReader read(file, table, "actor '" + actor.name + "': ");
  read.Find("name");

  // What to place: an asset file or a heightmap image.
  const std::optional<std::string> asset = read.Text("file");
  const std::optional<std::string> heightmap = read.Text("heightmap");
  if (asset.has_value() == heightmap.has_value()) {
    read.Fail(nullptr, "give exactly one of 'file' and 'heightmap'");
  }
  actor.is_heightmap = heightmap.has_value();
  actor.file = AssetPath(file, asset ? *asset : *heightmap);
  if (const auto size = read.Numbers("size", 3)) {
    if (!actor.is_heightmap) read.Fail(read.Find("size"), "'size' belongs to a heightmap");
    if ((size->array() <= 0.0).any()) read.Fail(read.Find("size"), "'size' must be positive");
    actor.heightmap_size_m = *size;
  } else if (actor.is_heightmap) {
    read.Fail(nullptr, "a heightmap needs 'size' = [x, y, height] in metres");
  }
  actor.placement = ParsePlacement(read);
  actor.collision = read.Flag("collision").value_or(true);
  actor.movable = read.Flag("movable").value_or(false);
  if (const auto surface = read.Text("surface")) {
    const std::pair<const char*, Surface> kSurfaces[] = {
        {"plain", Surface::kPlain}, {"terrain", Surface::kTerrain}, {"water", Surface::kWater}};
    for (const auto& [name, value] : kSurfaces) {
      if (*surface == name) actor.surface = value;
    }
    if (!actor.surface) {
      read.Fail(read.Find("surface"),
                "'surface' must be \"plain\", \"terrain\" or \"water\", got '" + *surface + "'");
    }
  } else if (actor.is_heightmap) {
    actor.surface = Surface::kTerrain;
  }
  if (const auto reflectivity = read.Number("reflectivity")) {
    if (!(*reflectivity >= 0.0 && *reflectivity <= 1.0)) {
      read.Fail(read.Find("reflectivity"), "'reflectivity' must be 0 to 1");
    }
    actor.reflectivity = *reflectivity;
  }
  if (const toml::node* by_material = read.Find("material_reflectivity")) {
    if (!by_material->is_table()) {
      read.Fail(by_material, "'material_reflectivity' must be a table: { material = 0..1, ... }");
    }
    actor.material_reflectivity_line = static_cast<int>(by_material->source().begin.line);
    for (const auto& [key, value] : *by_material->as_table()) {
      const std::string material(key.str());
      const double r = read.Number(&value, "material_reflectivity." + material);
      if (!(r >= 0.0 && r <= 1.0)) {
        read.Fail(&value, "'material_reflectivity." + material + "' must be 0 to 1");
      }
      actor.material_reflectivity[material] = r;
    }
  }
  read.RejectUnknownKeys("[[actor]]");
  return actor;
}

// An array of axis names ("x", "-y", ...) as unit vectors.
std::vector<Eigen::Vector3d> ParseAxes(TableReader& read, const toml::node* node,
                                       const std::string& key) {
  const toml::array* array = node->as_array();
  if (array == nullptr || array->empty() || array->size() > 3) {
    read.Fail(node, "'" + key + "' must be an array of 1 to 3 axis names, e.g. [\"x\", \"y\"]");
  }
  std::vector<Eigen::Vector3d> axes;
  for (const toml::node& item : *array) {
    const std::optional<std::string> name = item.value<std::string>();
    const std::optional<UpAxis> axis = name ? ParseUpAxis(*name) : std::nullopt;
    if (!axis) read.Fail(&item, "'" + key + "' takes axis names x, -x, y, -y, z, -z");
    axes.push_back(AxisDirection(*axis));
  }
  return axes;
}

// Every key of `table` not in `skip`, as given, for another module to read.
SettingsTable ReadSettings(const fs::path& file, const toml::table& table, TableReader& read,
                           const std::set<std::string>& skip, const std::string& context) {
  SettingsTable settings;
  settings.file = file;
  settings.line = static_cast<int>(table.source().begin.line);
  settings.context = context;
  for (const auto& [key_view, value] : table) {
    const std::string key(key_view.str());
    if (skip.count(key) > 0) continue;
    settings.lines[key] = static_cast<int>(value.source().begin.line);
    if (value.is_boolean()) {
      settings.values[key] = *value.value<bool>();
    } else if (value.is_number()) {
      settings.values[key] = read.Number(&value, key);
    } else if (value.is_string()) {
      settings.values[key] = *value.value<std::string>();
    } else if (const toml::array* array = value.as_array();
               array != nullptr && !array->empty() &&
               array->is_homogeneous(toml::node_type::string)) {
      std::vector<std::string> texts;
      for (const toml::node& item : *array) texts.push_back(*item.value<std::string>());
      settings.values[key] = texts;
    } else if (array != nullptr) {
      std::vector<double> numbers;
      for (const toml::node& item : *array) numbers.push_back(read.Number(&item, key));
      settings.values[key] = numbers;
    } else {
      read.Fail(&value, "'" + key + "' must be a number, a string, true/false or an array");
    }
  }
  return settings;
}

// A [[robot.sensor]] or [[robot.camera]] table: name, type, mount, placement
// and rate here; the type and every other key are the sensor's or camera's
// own, checked by sensors/ (sensors/render/ for cameras).
SensorSpec ParseSensor(const fs::path& file, const toml::table& table, int index,
                       const std::string& kind) {
  SensorSpec sensor;
  sensor.name = ParseName(file, table, kind, index);
  TableReader read(file, table, kind + " '" + sensor.name + "': ");
  read.Find("name");
  const std::optional<std::string> type = read.Text("type");
  if (!type) read.Fail(nullptr, "'type' is required");
  sensor.type = *type;
  const int type_line = static_cast<int>(read.Find("type")->source().begin.line);
  sensor.mount = read.Text("mount").value_or("");
  const Placement placement = ParsePlacement(read);
  if (!placement.scale.isOnes() || placement.conversion.up || placement.conversion.unit_scale_m) {
    read.Fail(nullptr, "a sensor takes position and rpy_deg or quaternion_wxyz only");
  }
  sensor.X_MS = placement.pose();
  if (const auto channel = read.Text("channel")) {
    if (kind == "camera") read.Fail(read.Find("channel"), "a camera publishes no channel");
    if (channel->empty() || channel->find_first_of(" \t\n") != std::string::npos) {
      read.Fail(read.Find("channel"),
                "'channel' must be a name without spaces, got '" + *channel + "'");
    }
    sensor.channel = *channel;
  }
  if (const auto rate = read.Number("rate_hz")) {
    if (*rate <= 0.0) read.Fail(read.Find("rate_hz"), "'rate_hz' must be positive");
    sensor.rate_hz = *rate;
  }
  // The rest, as given.
  sensor.settings = ReadSettings(file, table, read,
                                 {"name", "type", "mount", "position", "rpy_deg", "rate_hz",
                                  "channel", "quaternion_wxyz", "scale", "up", "unit_scale"},
                                 kind + " '" + sensor.name + "'");
  sensor.settings.lines["type"] = type_line;  // for the message of an unknown type
  // The keys of every type (a placement's scale, up and unit_scale are refused above).
  std::set<std::string> common = read.asked();
  for (const char* refused : {"scale", "up", "unit_scale"}) common.erase(refused);
  ReportKeys("[[robot." + kind + "]]", common);
  return sensor;
}

RobotSpec ParseRobot(const fs::path& file, const toml::table& table, int index) {
  RobotSpec robot;
  robot.line = static_cast<int>(table.source().begin.line);
  robot.name = ParseName(file, table, "robot", index);
  TableReader read(file, table, "robot '" + robot.name + "': ");
  read.Find("name");
  const std::optional<std::string> model = read.Text("file");
  const std::optional<std::string> description = read.Text("description");
  if (model && description)
    read.Fail(read.Find("description"), "give 'file' or 'description', not both");
  if (!model && !description)
    read.Fail(nullptr, "'file' (a model) or 'description' (URDF, SDF) is required");
  robot.file = AssetPath(file, model ? *model : *description);
  if (description && !IsRobotDescription(robot.file)) {
    read.Fail(
        read.Find("description"),
        "'description' must be a robot description (.urdf, .sdf), got '" + *description + "'");
  }
  robot.placement = ParsePlacement(read);
  robot.collision = read.Flag("collision").value_or(true);

  // The bone map and how each bone's rotation is given.
  if (const toml::node* bones = read.Find("bones")) {
    const toml::array* array = bones->as_array();
    if (array == nullptr) read.Fail(bones, "'bones' must be an array of bone names");
    std::set<std::string> seen;
    for (const toml::node& item : *array) {
      const std::optional<std::string> name = item.value<std::string>();
      if (!name || name->empty()) read.Fail(&item, "'bones' must be an array of bone names");
      if (!seen.insert(*name).second) read.Fail(&item, "bone '" + *name + "' is listed twice");
      robot.bones.push_back(*name);
    }
  }
  const std::string rotation = read.Text("rotation").value_or("quaternion");
  if (rotation == "angles") {
    robot.rotation = BoneRotation::kAngles;
  } else if (rotation != "quaternion") {
    read.Fail(read.Find("rotation"),
              "'rotation' must be \"quaternion\" or \"angles\", got '" + rotation + "'");
  }
  if (const toml::node* axes = read.Find("angle_axes")) {
    if (robot.rotation != BoneRotation::kAngles) {
      read.Fail(axes, "'angle_axes' needs rotation = \"angles\"");
    }
    robot.angle_axes = ParseAxes(read, axes, "angle_axes");
  } else if (robot.rotation == BoneRotation::kAngles) {
    read.Fail(nullptr, "rotation = \"angles\" needs 'angle_axes', e.g. [\"x\", \"y\"]");
  }
  if (const toml::node* overrides = read.Find("bone_axes")) {
    if (!overrides->is_table()) read.Fail(overrides, "'bone_axes' must be a table: bone = [axes]");
    if (robot.rotation != BoneRotation::kAngles) {
      read.Fail(overrides, "'bone_axes' needs rotation = \"angles\"");
    }
    for (const auto& [key, value] : *overrides->as_table()) {
      const std::string bone(key.str());
      if (std::find(robot.bones.begin(), robot.bones.end(), bone) == robot.bones.end()) {
        read.Fail(&value, "'bone_axes' names '" + bone + "', which is not in 'bones'");
      }
      robot.bone_axes[bone] = ParseAxes(read, &value, "bone_axes." + bone);
    }
  }
  // Sensors and cameras: mounted, named, typed; their own settings as given.
  for (const std::string key : {"sensor", "camera"}) {
    const toml::node* tables = read.Find(key);
    if (tables == nullptr) continue;
    const toml::array* array = tables->as_array();
    if (array == nullptr || !array->is_array_of_tables()) {
      read.Fail(tables, "'" + key + "' must be an array of tables: [[robot." + key + "]]");
    }
    std::set<std::string> names;
    int table_index = 0;
    for (const toml::node& item : *array) {
      SensorSpec spec = ParseSensor(file, *item.as_table(), ++table_index, key);
      if (!names.insert(spec.name).second) {
        TableReader(file, *item.as_table(), "")
            .Fail(nullptr, "duplicate " + key + " name '" + spec.name + "'");
      }
      (key == "sensor" ? robot.sensors : robot.cameras).push_back(std::move(spec));
    }
  }
  if (const toml::node* bridge = read.Find("bridge")) {
    if (!bridge->is_table()) read.Fail(bridge, "'bridge' must be a table: [robot.bridge]");
    TableReader bridge_read(file, *bridge->as_table(), "robot '" + robot.name + "' bridge: ");
    robot.bridge = ReadSettings(file, *bridge->as_table(), bridge_read, {},
                                "robot '" + robot.name + "' bridge");
  }
  read.RejectUnknownKeys("[[robot]]");
  return robot;
}

// One or more file names: a string or an array of strings.
std::vector<fs::path> ParseFiles(const fs::path& file, TableReader& read, const std::string& key) {
  std::vector<fs::path> files;
  const toml::node* node = read.Find(key);
  if (node == nullptr) return files;
  if (node->is_string()) return {AssetPath(file, *node->value<std::string>())};
  const toml::array* array = node->as_array();
  if (array == nullptr) read.Fail(node, "'" + key + "' must be a file name or an array of them");
  for (const toml::node& item : *array) {
    if (!item.is_string()) read.Fail(&item, "'" + key + "' must hold file names (strings)");
    files.push_back(AssetPath(file, *item.value<std::string>()));
  }
  return files;
}

TerrainSpec ParseTerrain(const fs::path& file, const toml::table& table, int index) {
  TerrainSpec terrain;
  terrain.line = static_cast<int>(table.source().begin.line);
  terrain.name = ParseName(file, table, "terrain", index);
  TableReader read(file, table, "terrain '" + terrain.name + "': ");
  read.Find("name");
  terrain.elevation = ParseFiles(file, read, "elevation");
  if (terrain.elevation.empty()) {
    read.Fail(nullptr, "'elevation' is required: the elevation raster(s), e.g. a GeoTIFF");
  }
  terrain.imagery = ParseFiles(file, read, "imagery");
  const auto anchor = read.Numbers("anchor", 3);
  if (!anchor) {
    read.Fail(nullptr,
              "'anchor' is required: [latitude_deg, longitude_deg, height_m] of the world origin");
  }
  if (std::abs((*anchor)[0]) > 90.0 || std::abs((*anchor)[1]) > 180.0) {
    read.Fail(read.Find("anchor"), "'anchor' latitude must be within +-90 and longitude +-180");
  }
  // The anchor is near the ground: between the deepest trench and the edge of space.
  if (!(std::abs((*anchor)[2]) <= kMaxHeightAboveEllipsoid_m ||
        ((*anchor)[2] > 0 && (*anchor)[2] <= kMaxAnchorHeight_m))) {
    read.Fail(read.Find("anchor"), "'anchor' height must be from -" +
                                       std::to_string(int(kMaxHeightAboveEllipsoid_m)) + " to " +
                                       std::to_string(int(kMaxAnchorHeight_m)) + " m");
  }
  terrain.anchor = {(*anchor)[0], (*anchor)[1], (*anchor)[2]};
  auto whole = [&](const char* key, int low, int high, int* value) {
    if (const auto set = read.Whole(key, low, high)) *value = int(*set);
  };
  whole("tile_samples", 2, 4096, &terrain.tile_samples);
  whole("coarse_factor", 1, 64, &terrain.coarse_factor);
  whole("texture_px", 2, 4096, &terrain.texture_px);
  if (terrain.tile_samples % terrain.coarse_factor != 0) {
    read.Fail(read.Find("coarse_factor"), "'tile_samples' must be a multiple of 'coarse_factor'");
  }
  auto positive = [&](const char* key, double* value, bool zero_ok, double most) {
    if (const auto set = read.Number(key)) {
      if (*set < 0.0 || (*set == 0.0 && !zero_ok)) {
        read.Fail(read.Find(key), std::string("'") + key + "' must be positive");
      }
      if (!(*set <= most)) {
        read.Fail(read.Find(key), std::string("'") + key + "' must be at most " +
                                      std::to_string(std::int64_t(most)));
      }
      *value = *set;
    }
  };
  positive("collision_radius_m", &terrain.collision_radius_m, false, kMaxTerrainRadius_m);
  positive("view_radius_m", &terrain.view_radius_m, false, kMaxTerrainRadius_m);
  positive("prefetch_s", &terrain.prefetch_s, true, 3600.0);
  if (terrain.view_radius_m < terrain.collision_radius_m) {
    read.Fail(read.Find("view_radius_m"), "'view_radius_m' must not be below 'collision_radius_m'");
  }
  if (const auto cache = read.Text("cache")) terrain.cache = AssetPath(file, *cache);
  read.RejectUnknownKeys("[[terrain]]");
  return terrain;
}

// Every table of the array `key` ([[key]]), parsed by `parse`, with unique names.
template <typename Spec, typename Parse>
std::vector<Spec> ParseTables(const fs::path& file, TableReader& top, const std::string& key,
                              Parse parse) {
  std::vector<Spec> specs;
  const toml::node* node = top.Find(key);
  if (node == nullptr) return specs;
  const toml::array* array = node->as_array();
  if (array == nullptr || !array->is_array_of_tables()) {
    top.Fail(node, "'" + key + "' must be an array of tables: [[" + key + "]]");
  }
  std::map<std::string, int> first_lines;  // name -> line of its table
  int index = 0;
  for (const toml::node& item : *array) {
    const toml::table& table = *item.as_table();  // is_array_of_tables() holds
    Spec spec = parse(file, table, ++index);
    const auto [first, fresh] = first_lines.emplace(spec.name, int(table.source().begin.line));
    if (!fresh) {
      TableReader(file, table, "")
          .Fail(nullptr, "duplicate " + key + " name '" + spec.name + "': the [[" + key +
                             "]] on line " + std::to_string(first->second) + " has it too");
    }
    specs.push_back(std::move(spec));
  }
  return specs;
}

}  // namespace

LevelManifest ParseManifest(const fs::path& file) {
  if (const std::string problem = RegularFileProblem(file); !problem.empty()) {
    throw LevelError(file.string() + ": " + problem);
  }
  if (FileBytes(file) > kMaxManifestBytes) {
    throw LevelError(file.string() + ": " + std::to_string(FileBytes(file) >> 20) +
                     " MB is no level manifest (they are a few KB; at most 16 MB are read)");
  }
  std::ifstream in(file, std::ios::binary);
  std::string text(FileBytes(file), '\0');
  if (!in.read(text.data(), std::streamsize(text.size()))) {
    throw LevelError(file.string() + ": cannot be read");
  }
  return ParseManifestText(text, file);
}

SettingsTable ParseSettingsText(const std::string& text, const std::string& origin,
                                const std::string& context) {
  // As an inline table, whose keys TOML separates by commas on one line.
  toml::table root;
  try {
    root = toml::parse("settings = {" + text + "}", origin);
  } catch (const toml::parse_error& error) {
    throw LevelError(origin + ": TOML syntax error: " + std::string(error.description()) +
                     " (expected key = value, key = value)");
  }
  const toml::node* node = root.get("settings");
  const toml::table* table = node != nullptr ? node->as_table() : nullptr;
  if (table == nullptr || root.size() != 1) {
    throw LevelError(origin + ": expected key = value, key = value");
  }
  const fs::path file(origin);  // TableReader keeps a reference to it
  TableReader read(file, *table, context + ": ");
  return ReadSettings(file, *table, read, {}, context);
}

LevelManifest ParseManifestText(std::string_view text, const fs::path& file) {
  toml::table root;
  try {
    root = toml::parse(text, file.string());
  } catch (const toml::parse_error& error) {
    std::ostringstream out;
    out << file.string() << ":" << error.source().begin.line
        << ": TOML syntax error: " << error.description();
    throw LevelError(out.str());
  }
  LevelManifest manifest;
  manifest.file = file;
  manifest.name = file.stem().string();
  TableReader top(file, root, "");

  if (const toml::node* level = top.Find("level")) {
    if (!level->is_table()) top.Fail(level, "'level' must be a table: [level]");
    TableReader read(file, *level->as_table(), "[level]: ");
    if (const auto name = read.Text("name")) manifest.name = *name;
    // What loading the level may take (scene/load_limits.h).
    LoadLimits& limits = manifest.limits;
    constexpr std::int64_t kHuge = std::int64_t(1) << 50;
    for (const auto& [key, value] :
         {std::pair<const char*, std::uint64_t*>{"max_file_mb", &limits.max_file_mb},
          {"max_heightmap_samples", &limits.max_heightmap_samples},
          {"max_texture_pixels", &limits.max_texture_pixels},
          {"max_triangles", &limits.max_triangles},
          {"max_import_mb", &limits.max_import_mb},
          {"max_import_s", &limits.max_import_s},
          {"max_terrain_tiles", &limits.max_terrain_tiles},
          {"max_terrain_mb", &limits.max_terrain_mb},
          {"max_tile_samples", &limits.max_tile_samples},
          {"max_imagery_window_px", &limits.max_imagery_window_px}}) {
      if (const auto set = read.Whole(key, 0, kHuge)) *value = std::uint64_t(*set);
    }
    read.RejectUnknownKeys("[level]");
  }

  manifest.actors = ParseTables<ActorSpec>(file, top, "actor", ParseActor);
  manifest.robots = ParseTables<RobotSpec>(file, top, "robot", ParseRobot);
  const std::vector<TerrainSpec> terrains =
      ParseTables<TerrainSpec>(file, top, "terrain", ParseTerrain);
  if (terrains.size() > 1) {
    TableReader(file, root, "")
        .Fail(top.Find("terrain"),
              "one [[terrain]] table per level (list several rasters in its "
              "'elevation' instead)");
  }
  if (!terrains.empty()) {
    manifest.terrain = terrains.front();
    manifest.terrain->limits = manifest.limits;
  }
  if (const toml::node* horizon = top.Find("horizon")) {
    if (!horizon->is_table()) top.Fail(horizon, "'horizon' must be a table: [horizon]");
    TableReader read(file, *horizon->as_table(), "[horizon]: ");
    HorizonSpec spec;
    if (const auto height = read.Number("height_m")) spec.height_m = *height;
    if (const auto rgb = read.Numbers("rgb", 3)) {
      if ((rgb->array() < 0.0).any() || (rgb->array() > 1.0).any()) {
        read.Fail(read.Find("rgb"), "'rgb' values must be within 0 and 1");
      }
      spec.rgb = rgb->cast<float>();
    }
    if (const auto visibility = read.Number("visibility_m")) {
      if (!(*visibility >= 1.0))
        read.Fail(read.Find("visibility_m"), "'visibility_m' must be at least 1 m");
      spec.visibility_m = *visibility;
    }
    read.RejectUnknownKeys("[horizon]");
    manifest.horizon = spec;
  }
  if (const toml::node* wind = top.Find("wind")) {
    if (!wind->is_table()) top.Fail(wind, "'wind' must be a table: [wind]");
    TableReader read(file, *wind->as_table(), "[wind]: ");
    WindSpec spec;
    if (const auto velocity = read.Numbers("velocity", 3)) spec.velocity = *velocity;
    spec.shear_velocity = spec.velocity;
    const auto shear = read.Numbers("shear_velocity", 3);
    const auto bottom = read.Number("shear_bottom_m");
    const auto top_m = read.Number("shear_top_m");
    if (shear || bottom || top_m) {
      if (!(shear && bottom && top_m)) {
        read.Fail(nullptr, "a shear layer takes shear_velocity, shear_bottom_m and shear_top_m");
      }
      if (!(*top_m > *bottom)) {
        read.Fail(read.Find("shear_top_m"), "'shear_top_m' must be above 'shear_bottom_m'");
      }
      spec.shear_velocity = *shear, spec.shear_bottom_m = *bottom, spec.shear_top_m = *top_m;
    }
    if (const auto sigma = read.Number("gust_sigma_m_s")) {
      if (*sigma < 0.0)
        read.Fail(read.Find("gust_sigma_m_s"), "'gust_sigma_m_s' must be zero or positive");
      spec.gust_sigma_m_s = *sigma;
    }
    if (const auto length = read.Number("gust_length_m")) {
      if (!(*length > 0.0))
        read.Fail(read.Find("gust_length_m"), "'gust_length_m' must be positive");
      spec.gust_length_m = *length;
    }
    if (const auto seed = read.Whole("seed", 0, std::int64_t(1) << 53)) spec.seed = *seed;
    read.RejectUnknownKeys("[wind]");
    manifest.wind = spec;
  }
  top.RejectUnknownKeys("(the file's top level)");
  if (manifest.actors.empty() && manifest.robots.empty() && !manifest.terrain) {
    throw LevelError(
        file.string() +
        ": the manifest places nothing (add [[actor]], [[robot]] or [[terrain]] tables)");
  }
  return manifest;
}

}  // namespace sandbox::scene
