#pragma once
// Surface ids: what a camera pixel or a ray sample shows, one vocabulary for
// segmentation images and ray sensors (docs/reference/sensors.md, "What a
// sample hit"). 0 is nothing (the sky, a ray that hit nothing); then one id
// per actor (1 + its index), one for the ground beyond the level (the
// horizon, drawn only), one per bone group of each robot (a bone of its bone
// map with the nodes below it that are not bones themselves), and after those
// the terrain tiles, numbered as they first come in (CollisionWorld). The
// level's ids depend on the level alone, so every camera and sensor of a run
// agrees.

#include <algorithm>
#include <cstdint>
#include <string>
#include <vector>

#include "scene/level.h"

namespace sandbox::scene {

struct SurfaceEntry {
  std::int32_t id{0};
  std::string kind;        // "actor", "horizon", "robot" (its root bone group), "bone" or "tile"
  std::string name;        // the actor's, "horizon", "robot/bone" or "terrain/<tile>"
  int actor{-1};           // the actor (a tile: the terrain actor), or -1
  int robot{-1};           // the robot, or -1
  std::string robot_name;  // its name, or ""
  int bone{-1};            // the robot's bone map entry, or -1
  std::string bone_name;   // that bone's name, or ""
  // What a lidar sees of it, 0 to 1 (docs/reference/sensors.md, "Intensity"):
  // an actor's MeshReflectivity averaged over its triangles (a hit takes its
  // own mesh's: RayHits::reflectivity); a robot's DerivedReflectivity of its
  // meshes; a tile's its terrain actor's.
  static constexpr float kDefaultReflectivity = 0.5f;
  float reflectivity{kDefaultReflectivity};
};

// A material's reflectivity: the luminance of its base colour (linear light,
// Rec. 709 weights), halved when a texture modulates the colour (a texture's
// mean is taken as mid-grey: it is not decoded at load).
float MaterialReflectivity(const Material& material);

// What a lidar sees of a mesh of `actor`: its material's entry in the
// actor's material_reflectivity, else the actor's reflectivity, else
// MaterialReflectivity of its material (a mesh without one: the default
// material's).
float MeshReflectivity(const Actor& actor, const Mesh& mesh,
                       const std::vector<Material>& materials);

// A surface's reflectivity from its meshes' materials: MaterialReflectivity
// averaged over the triangles; 0.5 without meshes.
float DerivedReflectivity(const std::vector<const Mesh*>& meshes,
                          const std::vector<Material>& materials);

class SurfaceIds {
 public:
  explicit SurfaceIds(const Level& level);

  static constexpr std::int32_t kNothing = 0;
  std::int32_t actor(int actor_index) const { return 1 + actor_index; }
  std::int32_t horizon() const { return horizon_; }
  // The id of bone `bone` (an index into the bone map) of level robot `robot`.
  std::int32_t bone(int robot, int bone) const { return robot_base_[std::size_t(robot)] + bone; }
  // The first id after the level's: terrain tiles are numbered from it.
  std::int32_t first_tile() const { return end_; }
  // The level's entries, by id (entries()[id - 1]).
  const std::vector<SurfaceEntry>& entries() const { return entries_; }
  // The entry of a level id, or null (nothing, a tile, out of range).
  const SurfaceEntry* Find(std::int32_t id) const;
  // The reflectivity of surface `id` (nothing and the horizon: 0; a terrain
  // tile: its terrain actor's). Inline: the lidar asks once a beam.
  float reflectivity(std::int32_t id) const {
    return id < end_ ? reflectivity_[std::size_t(std::max(id, 0))] : tile_reflectivity_;
  }
  // "id,kind,name" lines with a header, as written beside segmentation images.
  std::string Csv() const;

 private:
  std::int32_t horizon_{0}, end_{0};
  std::vector<std::int32_t> robot_base_;
  std::vector<SurfaceEntry> entries_;
  std::vector<float> reflectivity_;
  float tile_reflectivity_{SurfaceEntry::kDefaultReflectivity};
};

// For each node of `model`, its bone group's bone map entry: its own bone,
// else its nearest ancestor's; 0 (the root) when none.
std::vector<int> BoneGroupOfNodes(const RobotModel& model);

// For each triangle of mesh `mesh` of `model`, the bone map entry of its bone
// group: that of the node carrying most of the triangle's weight
// (DominantNodePerTriangle); 0 (the root) when none.
std::vector<std::uint32_t> BoneGroupPerTriangle(const RobotModel& model, int mesh);

}  // namespace sandbox::scene
