#pragma once
// A level: the actors of the world with their meshes and materials, loaded once
// from a scene file or a TOML level manifest and converted to the world frame
// (Z up, metres). A Level is constant after loading; run-time placements of
// movable actors live in CollisionWorld.

#include <Eigen/Geometry>
#include <cstddef>
#include <filesystem>
#include <functional>
#include <map>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

#include "scene/load_limits.h"
#include "scene/mesh.h"
#include "scene/placement.h"
#include "scene/robot_model.h"
#include "scene/terrain_tile.h"
#include "scene/wind.h"

namespace sandbox::scene {

struct Actor {
  std::string name;                                       // unique in the level
  std::string source;                                     // the file (and node path) it came from
  Eigen::Isometry3d X_WA{Eigen::Isometry3d::Identity()};  // pose at load time
  bool collision{true};                                   // false: drawn but invisible to rays
  bool movable{false};  // true: may be placed from outside at run time
  // How cameras shade it, over its materials' own (heightmaps: terrain).
  std::optional<Surface> surface;
  // What a lidar sees of it (its intensity law, docs/reference/sensors.md);
  // none: derived from its materials' base colours (scene::SurfaceIds).
  std::optional<double> reflectivity;
  // Per material (by name), over `reflectivity`: what a lidar sees of the
  // triangles of that material (scene::MeshReflectivity).
  std::map<std::string, double> material_reflectivity;
  std::vector<Mesh> meshes;      // in frame A
  Eigen::AlignedBox3d bounds_W;  // exact bounds of the meshes at X_WA; empty without meshes

  std::size_t num_triangles() const;
  std::size_t num_vertices() const;
};

// The ground beyond the level, drawn by cameras out to the horizon with the
// Earth's curvature ([horizon] of a manifest), so that the world has no edge.
struct Horizon {
  double height_m{0.0};  // at the world origin; it falls away with distance
  Eigen::Vector3f rgb{0.42f, 0.47f, 0.33f};
  double visibility_m{0.0};    // the haze hides everything by this distance; 0: the renderer's
  Eigen::AlignedBox2d hole_W;  // the level's own ground (x, y), left open
};

struct Level {
  std::filesystem::path file;
  std::string name;
  std::vector<Actor> actors;
  std::vector<Material> materials;
  std::vector<EmbeddedTexture> textures;
  std::vector<RobotModel> robots;      // declared by [[robot]] tables of a manifest
  std::optional<TerrainSpec> terrain;  // elevation rasters streamed in tiles ([[terrain]])
  int terrain_actor{-1};               // the actor terrain tiles belong to (no meshes of its own)
  std::optional<Horizon> horizon;
  std::optional<WindSpec> wind;  // [wind]; none: still air
  std::vector<std::string> warnings;  // problems that were handled, e.g. dropped faces
  LoadLimits limits;                  // what it was loaded within (textures are decoded later)

  // Index of the actor (robot) called `name`, or -1.
  int FindActor(std::string_view name) const;
  int FindRobot(std::string_view name) const;
  std::size_t num_triangles() const;
  Eigen::AlignedBox3d bounds_W() const;
};

struct LoadOptions {
  AssetConversion conversion;  // a scene file's axes and unit, when it does not say them
  LoadLimits limits;           // a manifest's [level] table sets its own
  // Called before each file of the level is read, with the library that
  // reads it ("assimp", "GDAL and PROJ", "the manifest reader", ...).
  std::function<void(const std::filesystem::path& file, std::string_view reader)> on_file;
};

// Appends materials and textures to the level, renumbering the materials'
// texture references; returns the index the first material got.
int AppendMaterials(std::vector<Material> materials, std::vector<EmbeddedTexture> textures,
                    Level* level);

// Loads a level: a `.toml` file is a level manifest, anything else a scene file
// that assimp reads (or a Terragen .ter terrain), in which every node with
// meshes becomes an actor named after its node path. Only regular files are
// read. Throws LevelError, also for a level over its limits.
Level LoadLevel(const std::filesystem::path& file, const LoadOptions& options);
Level LoadLevel(const std::filesystem::path& file, const AssetConversion& conversion = {});

}  // namespace sandbox::scene
