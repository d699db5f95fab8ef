#include "scene/manifest.h"

#include <toml++/toml.h>

#include <cmath>
#include <set>
#include <sstream>

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

// Reads typed values out of one TOML table, naming file, line and context in
// every error, and rejects keys it was never asked about.
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

  std::optional<std::string> String(const std::string& key) {
    const toml::node* node = Find(key);
    if (node == nullptr) return std::nullopt;
    if (!node->is_string()) Fail(node, "'" + key + "' must be a string");
    return node->value<std::string>();
  }

  std::optional<bool> Bool(const std::string& key) {
    const toml::node* node = Find(key);
    if (node == nullptr) return std::nullopt;
    if (!node->is_boolean()) Fail(node, "'" + key + "' must be true or false");
    return node->value<bool>();
  }

  double Number(const toml::node* node, const std::string& key) const {
    if (!node->is_number()) Fail(node, "'" + key + "' must be a number");
    const double value = *node->value<double>();
    if (!std::isfinite(value)) Fail(node, "'" + key + "' must be finite, got " + Format(value));
    return value;
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

  // Every key of the table must have been asked for.
  void RejectUnknownKeys() const {
    for (const auto& [key, value] : table_) {
      if (known_.count(std::string(key.str())) == 0) {
        Fail(&value, "unknown key '" + std::string(key.str()) + "'");
      }
    }
  }

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

ActorSpec ParseActor(const fs::path& file, const toml::table& table, int index) {
  ActorSpec actor;
  actor.line = static_cast<int>(table.source().begin.line);
  TableReader named(file, table, "actor " + std::to_string(index) + ": ");
  const std::optional<std::string> name = named.String("name");
  if (!name || name->empty()) named.Fail(nullptr, "'name' is required");
  actor.name = *name;
  TableReader read(file, table, "actor '" + actor.name + "': ");
  read.Find("name");

  // What to place: an asset file or a heightmap image.
  const std::optional<std::string> asset = read.String("file");
  const std::optional<std::string> heightmap = read.String("heightmap");
  if (asset.has_value() == heightmap.has_value()) {
    read.Fail(nullptr, "give exactly one of 'file' and 'heightmap'");
  }
  actor.is_heightmap = heightmap.has_value();
  actor.file = (file.parent_path() / (asset ? *asset : *heightmap)).lexically_normal();
  if (const auto size = read.Numbers("size", 3)) {
    if (!actor.is_heightmap) read.Fail(read.Find("size"), "'size' belongs to a heightmap");
    if ((size->array() <= 0.0).any()) read.Fail(read.Find("size"), "'size' must be positive");
    actor.heightmap_size_m = *size;
  } else if (actor.is_heightmap) {
    read.Fail(nullptr, "a heightmap needs 'size' = [x, y, height] in metres");
  }

  // Placement.
  if (const auto position = read.Numbers("position", 3)) actor.position_m = *position;
  const auto rpy = read.Numbers("rpy_deg", 3);
  const auto quaternion = read.Numbers("quaternion_wxyz", 4);
  if (rpy && quaternion) read.Fail(nullptr, "give either 'rpy_deg' or 'quaternion_wxyz', not both");
  if (rpy) {
    actor.rotation = Eigen::Quaterniond(RotationFromRollPitchYaw(
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
    actor.rotation = q.normalized();
  }
  if (const toml::node* scale = read.Find("scale")) {
    if (scale->is_array()) {
      actor.scale = *read.Numbers("scale", 3);
    } else {
      actor.scale.setConstant(read.Number(scale, "scale"));
    }
    if ((actor.scale.array() <= 0.0).any()) {
      read.Fail(scale,
                "'scale' must be positive, got " + TableReader::Format(actor.scale.minCoeff()));
    }
  }

  // How to read the asset when its file does not say.
  if (const auto up = read.String("up")) {
    actor.conversion.up = ParseUpAxis(*up);
    if (!actor.conversion.up) {
      read.Fail(read.Find("up"), "'up' must be one of x, -x, y, -y, z, -z, got '" + *up + "'");
    }
  }
  if (const auto unit = read.Number("unit_scale")) {
    if (*unit <= 0.0) read.Fail(read.Find("unit_scale"), "'unit_scale' must be positive");
    actor.conversion.unit_scale_m = *unit;
  }
  actor.collision = read.Bool("collision").value_or(true);
  actor.movable = read.Bool("movable").value_or(false);
  read.RejectUnknownKeys();
  return actor;
}

}  // namespace

LevelManifest ParseManifest(const fs::path& file) {
  toml::table root;
  try {
    root = toml::parse_file(file.string());
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
    if (const auto name = read.String("name")) manifest.name = *name;
    read.RejectUnknownKeys();
  }

  if (const toml::node* actors = top.Find("actor")) {
    const toml::array* array = actors->as_array();
    if (array == nullptr || !array->is_array_of_tables()) {
      top.Fail(actors, "'actor' must be an array of tables: [[actor]]");
    }
    std::set<std::string> names;
    int index = 0;
    for (const toml::node& node : *array) {
      const toml::table& table = *node.as_table();  // is_array_of_tables() holds
      ActorSpec actor = ParseActor(file, table, ++index);
      if (!names.insert(actor.name).second) {
        TableReader(file, table, "").Fail(nullptr, "duplicate actor name '" + actor.name + "'");
      }
      manifest.actors.push_back(std::move(actor));
    }
  }
  top.RejectUnknownKeys();
  if (manifest.actors.empty()) {
    throw LevelError(file.string() + ": the manifest places no actors (add [[actor]] tables)");
  }
  return manifest;
}

}  // namespace sandbox::scene
