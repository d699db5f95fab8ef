#include "scene/level.h"

#include <map>
#include <numeric>
#include <set>
#include <sstream>

#include "scene/asset_import.h"
#include "scene/files.h"
#include "scene/heightmap.h"
#include "scene/manifest.h"
#include "scene/robot_description.h"
#include "scene/terrain_source.h"

namespace sandbox::scene {
namespace {

namespace fs = std::filesystem;

void ComputeBounds(Actor* actor) {
  actor->bounds_W.setEmpty();
  for (const Mesh& mesh : actor->meshes) {
    for (const Eigen::Vector3f& p_A : mesh.positions_A) {
      actor->bounds_W.extend(actor->X_WA * p_A.cast<double>());
    }
  }
}

// Appends an asset's materials, textures and warnings to the level's,
// renumbering the material references of its meshes.
void AdoptMaterialsAndWarnings(ImportedAsset* asset, Level* level) {
  const int material_base =
      AppendMaterials(std::move(asset->materials), std::move(asset->textures), level);
  for (ImportedNode& node : asset->nodes) {
    for (Mesh& mesh : node.meshes) {
      if (mesh.material >= 0) mesh.material += material_base;
    }
  }
  for (std::string& warning : asset->warnings) level->warnings.push_back(std::move(warning));
}

// The level's triangles so far against its limit.
void CheckTriangles(const fs::path& file, const Level& level) {
  std::size_t triangles = level.num_triangles();
  for (const RobotModel& robot : level.robots) triangles += robot.num_triangles();
  LoadLimits::Check(file, "the level has " + std::to_string(triangles) + " triangles", triangles,
                    level.limits.max_triangles, "max_triangles");
}

// Every material `material_reflectivity` names is one of the actor's.
void CheckMaterialNames(const fs::path& file, const ActorSpec& spec, const Actor& actor,
                        const std::vector<Material>& materials) {
  std::set<std::string> names;
  for (const Mesh& mesh : actor.meshes) {
    if (mesh.material >= 0 && std::size_t(mesh.material) < materials.size()) {
      names.insert(materials[std::size_t(mesh.material)].name);
    }
  }
  for (const auto& [name, value] : spec.material_reflectivity) {
    if (names.count(name) != 0) continue;
    std::string have;
    for (const std::string& n : names) have += (have.empty() ? "'" : ", '") + n + "'";
    throw LevelError(file.string() + ":" + std::to_string(spec.material_reflectivity_line) +
                     ": actor '" + spec.name + "': 'material_reflectivity' names '" + name +
                     "', which is not a material of " + spec.file.filename().string() + " (" +
                     (have.empty() ? "it has none" : "it has " + have) + ")");
  }
}

void Reading(const LoadOptions& options, const fs::path& file, std::string_view reader) {
  if (options.on_file) options.on_file(file, reader);
}

// What makes two [[actor]] tables read the same: the file and how it is read.
std::string AssetKey(const ActorSpec& spec) {
  std::ostringstream key;
  key.precision(17);
  key << spec.file.string() << '\n';
  if (spec.is_heightmap) {
    key << "heightmap " << spec.heightmap_size_m.transpose();
  } else {
    const AssetConversion& c = spec.placement.conversion;
    key << (c.up ? ToString(*c.up) : "-") << ' ' << c.unit_scale_m.value_or(0.0);
  }
  return key.str();
}

// A scene file as a level: one actor per node with meshes, posed at the
// node's rigid transform.
Level LoadSceneFile(const fs::path& file, const LoadOptions& options) {
  Reading(options, file, AssetReader(file));
  ImportedAsset asset = ImportAsset(file, options.conversion, options.limits);
  Level level;
  level.file = file;
  level.name = file.stem().string();
  level.limits = options.limits;
  AdoptMaterialsAndWarnings(&asset, &level);
  for (ImportedNode& node : asset.nodes) {
    Actor actor;
    actor.name = node.path;
    actor.source = file.string() + ":" + node.path;
    actor.X_WA = RigidPart(node.X_RN);  // scale and shear stay in the mesh
    const Eigen::Affine3d X_AN = actor.X_WA.inverse() * node.X_RN;
    for (Mesh& mesh : node.meshes) {
      TransformMesh(X_AN, &mesh);
      actor.meshes.push_back(std::move(mesh));
    }
    level.actors.push_back(std::move(actor));
  }
  return level;
}

// A robot description as a level: the robot alone, at the origin, named
// after the file.
Level LoadDescriptionFile(const fs::path& file, const LoadOptions& options) {
  Level level;
  level.file = file;
  level.name = file.stem().string();
  level.limits = options.limits;
  RobotSpec spec;
  spec.name = level.name;
  spec.file = file;
  level.robots.push_back(LoadRobotModel(spec, file, &level, options.on_file));
  return level;
}

// A manifest as a level: one actor per [[actor]], all of its asset's nodes
// merged into it, scaled in the asset root frame and then placed.
Level LoadManifest(const fs::path& file, const LoadOptions& options) {
  Reading(options, file, "the manifest reader");
  const LevelManifest manifest = ParseManifest(file);
  Level level;
  level.file = file;
  level.name = manifest.name;
  level.limits = manifest.limits;
  // An asset placed many times is read once, and its materials are shared.
  std::map<std::string, ImportedAsset> read_once;
  for (const ActorSpec& spec : manifest.actors) {
    auto read = read_once.find(AssetKey(spec));
    if (read == read_once.end()) {
      ImportedAsset asset;
      Reading(options, spec.file,
              spec.is_heightmap ? "the heightmap reader (libpng)" : AssetReader(spec.file));
      try {
        asset = spec.is_heightmap
                    ? ImportHeightmapImage(spec.file, spec.heightmap_size_m, level.limits)
                    : ImportAsset(spec.file, spec.placement.conversion, level.limits);
      } catch (const LevelError& error) {
        throw LevelError(file.string() + ":" + std::to_string(spec.line) + ": actor '" + spec.name +
                         "': " + error.what());
      }
      AdoptMaterialsAndWarnings(&asset, &level);
      read = read_once.emplace(AssetKey(spec), std::move(asset)).first;
    }
    const ImportedAsset& asset = read->second;
    Actor actor;
    actor.name = spec.name;
    actor.source = spec.file.string();
    actor.collision = spec.collision;
    actor.movable = spec.movable;
    actor.surface = spec.surface;
    actor.reflectivity = spec.reflectivity;
    actor.material_reflectivity = spec.material_reflectivity;
    actor.X_WA = spec.placement.pose();
    for (const ImportedNode& node : asset.nodes) {
      const Eigen::Affine3d X_AN = Eigen::Scaling(spec.placement.scale) * node.X_RN;
      for (const Mesh& mesh : node.meshes) {
        actor.meshes.push_back(mesh);
        TransformMesh(X_AN, &actor.meshes.back());
      }
    }
    CheckMaterialNames(file, spec, actor, level.materials);
    level.actors.push_back(std::move(actor));
    CheckTriangles(spec.file, level);
  }
  if (manifest.terrain) {
    // The rasters are opened and checked here; their tiles are read while running.
    const TerrainSpec& spec = *manifest.terrain;
    if (level.FindActor(spec.name) >= 0) {
      throw LevelError(file.string() + ":" + std::to_string(spec.line) + ": terrain '" + spec.name +
                       "': an [[actor]] has that name too");
    }
    const TerrainSource source(
        spec, [&options](const fs::path& raster) { Reading(options, raster, "GDAL and PROJ"); });
    for (const std::string& problem : source.problems()) level.warnings.push_back(problem);
    source.CheckBudgets();
    Actor actor;
    actor.name = spec.name;
    actor.source = spec.elevation.front().string();
    level.terrain_actor = static_cast<int>(level.actors.size());
    level.actors.push_back(std::move(actor));
    level.terrain = spec;
    if (manifest.horizon) {
      level.horizon.emplace();
      level.horizon->hole_W = source.InnerFootprint_W();
    }
  }
  if (manifest.horizon) {
    if (!level.horizon) level.horizon.emplace();
    level.horizon->height_m = manifest.horizon->height_m;
    level.horizon->rgb = manifest.horizon->rgb;
    level.horizon->visibility_m = manifest.horizon->visibility_m;
  }
  level.wind = manifest.wind;
  for (const RobotSpec& spec : manifest.robots) {
    level.robots.push_back(LoadRobotModel(spec, file, &level, options.on_file));
    CheckTriangles(spec.file, level);
  }
  return level;
}

}  // namespace

int AppendMaterials(std::vector<Material> materials, std::vector<EmbeddedTexture> textures,
                    Level* level) {
  const int material_base = static_cast<int>(level->materials.size());
  const int texture_base = static_cast<int>(level->textures.size());
  for (Material& material : materials) {
    if (material.base_color_texture_embedded >= 0) {
      material.base_color_texture_embedded += texture_base;
    }
    if (material.lightmap_texture_embedded >= 0) material.lightmap_texture_embedded += texture_base;
    if (material.normal_texture_embedded >= 0) material.normal_texture_embedded += texture_base;
    level->materials.push_back(std::move(material));
  }
  for (EmbeddedTexture& texture : textures) level->textures.push_back(std::move(texture));
  return material_base;
}

std::size_t Actor::num_triangles() const {
  return std::accumulate(meshes.begin(), meshes.end(), std::size_t{0},
                         [](std::size_t sum, const Mesh& m) { return sum + m.num_triangles(); });
}

std::size_t Actor::num_vertices() const {
  return std::accumulate(meshes.begin(), meshes.end(), std::size_t{0},
                         [](std::size_t sum, const Mesh& m) { return sum + m.positions_A.size(); });
}

int Level::FindActor(std::string_view actor_name) const {
  for (std::size_t i = 0; i < actors.size(); ++i) {
    if (actors[i].name == actor_name) return static_cast<int>(i);
  }
  return -1;
}

int Level::FindRobot(std::string_view robot_name) const {
  for (std::size_t i = 0; i < robots.size(); ++i) {
    if (robots[i].name == robot_name) return static_cast<int>(i);
  }
  return -1;
}

std::size_t Level::num_triangles() const {
  return std::accumulate(actors.begin(), actors.end(), std::size_t{0},
                         [](std::size_t sum, const Actor& a) { return sum + a.num_triangles(); });
}

Eigen::AlignedBox3d Level::bounds_W() const {
  Eigen::AlignedBox3d bounds;
  for (const Actor& actor : actors) {
    if (!actor.bounds_W.isEmpty()) bounds.extend(actor.bounds_W);
  }
  return bounds;
}

Level LoadLevel(const fs::path& file, const LoadOptions& options) {
  if (const std::string problem = RegularFileProblem(file); !problem.empty()) {
    throw LevelError(file.string() + ": " + problem);
  }
  Level level = LowerExtension(file) == ".toml" ? LoadManifest(file, options)
                : IsRobotDescription(file)      ? LoadDescriptionFile(file, options)
                                                : LoadSceneFile(file, options);
  CheckTriangles(file, level);
  for (Actor& actor : level.actors) ComputeBounds(&actor);
  if (level.horizon && level.horizon->hole_W.isEmpty() && !level.bounds_W().isEmpty()) {
    // Without rasters, the level's own ground is what its static actors cover.
    Eigen::AlignedBox2d hole;
    for (const Actor& actor : level.actors) {
      if (!actor.movable && !actor.bounds_W.isEmpty()) {
        hole.extend(actor.bounds_W.min().head<2>()).extend(actor.bounds_W.max().head<2>());
      }
    }
    level.horizon->hole_W = hole;
  }
  return level;
}

Level LoadLevel(const fs::path& file, const AssetConversion& conversion) {
  LoadOptions options;
  options.conversion = conversion;
  return LoadLevel(file, options);
}

}  // namespace sandbox::scene
