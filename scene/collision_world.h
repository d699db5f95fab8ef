#pragma once
// The Bullet collision world of a level, used only for queries: physics
// stepping is never used (no stepSimulation, no masses, nothing integrates).
// Every transform comes from the level file or from outside (SetActorPose).
//
// Precision: Bullet is the float build. Positions cross this interface in
// double and are taken relative to a floating origin (SetOrigin) before they
// reach Bullet, so queries near the origin keep sub-millimetre precision
// however far the world extends (see docs/reference/levels.md).
//
// Threads: one thread (the loop thread) owns the world; CastRay uses
// btCollisionWorld::rayTest, which is not safe to call from several threads.

#include <Eigen/Geometry>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "scene/level.h"
#include "scene/robot_state.h"
#include "scene/surface_ids.h"

namespace sandbox::scene {

struct TerrainTile;

// Collision channels; a ray's mask selects which it sees.
enum CollisionGroup : std::uint32_t {
  kWorldStatic = 1u << 0,
  kWorldMovable = 1u << 1,
  kRobot = 1u << 2,
  kAllGroups = kWorldStatic | kWorldMovable | kRobot,
};

struct RayHit {
  Eigen::Vector3d point_W;
  Eigen::Vector3d normal_W;  // unit, facing the ray
  double distance_m{0.0};    // from the ray's start
  int actor{-1};             // index into Level::actors, or -1 when a robot was hit
  int robot{-1};             // index into Level::robots, or -1 when an actor was hit
  std::int32_t surface{0};   // its surface id (scene/surface_ids.h)
};

class CollisionWorld {
 public:
  // Builds triangle-mesh shapes (quantized BVH) for every actor with collision
  // on: movable actors in kWorldMovable, the rest in kWorldStatic; and for every
  // robot with collision on, in kRobot, posed at its spawn pose with bones at
  // rest. Actor meshes are referenced, not copied: `level` must outlive the
  // world. Meshes are split to respect Bullet's limits (2^21 triangles a part,
  // 1024 parts a shape).
  explicit CollisionWorld(const Level& level);
  ~CollisionWorld();
  CollisionWorld(const CollisionWorld&) = delete;
  CollisionWorld& operator=(const CollisionWorld&) = delete;

  // The first hit on the segment from `from_W` to `to_W` among objects whose
  // group is in `group_mask`, skipping actor `ignore_actor` and robot
  // `ignore_robot` (-1: none; a robot's own sensors ignore the robot).
  std::optional<RayHit> CastRay(const Eigen::Vector3d& from_W, const Eigen::Vector3d& to_W,
                                std::uint32_t group_mask = kAllGroups, int ignore_actor = -1,
                                int ignore_robot = -1) const;

  // Places a movable actor. Throws std::invalid_argument for an unknown index,
  // a static actor or a non-finite pose (the previous pose stays).
  void SetActorPose(int actor, const Eigen::Isometry3d& X_WA);
  // The same by actor name; std::invalid_argument names an unknown actor.
  void SetActorPose(std::string_view actor, const Eigen::Isometry3d& X_WA);
  const Eigen::Isometry3d& actor_pose(int actor) const;

  // Moves robot `robot`'s collision body to the state's pose and bones. The
  // body is the skin cut into rigid pieces, one per node that carries most of
  // a triangle's weight, each moved with its node: exact for link-mesh robots,
  // within blend zones of a skin off the rendered surface by about the blend
  // width times the joint angle (bench_robots prints the figure for the wing).
  // `state` must belong to that robot.
  void UpdateRobot(int robot, const RobotState& state);

  // Moves the floating origin to `p_WO` (world coordinates kept in double).
  void SetOrigin(const Eigen::Vector3d& p_WO);
  const Eigen::Vector3d& origin() const { return p_WO_; }

  // Terrain tiles (scene/terrain_streamer.h): a tile's objects are made by
  // PrepareTile on any thread (building their BVH takes milliseconds), then
  // added between ticks by AddTile (microseconds). They belong to the level's
  // terrain actor (Level::terrain_actor): rays report it. AddTile throws
  // std::logic_error when the level has no terrain.
  struct PreparedTile;
  static std::shared_ptr<PreparedTile> PrepareTile(std::shared_ptr<const TerrainTile> tile);
  void AddTile(std::shared_ptr<PreparedTile> tile);
  bool RemoveTile(std::uint64_t key);  // false when no such tile is in
  int num_tiles() const;

  // What rays report they hit (scene/surface_ids.h): the level's ids, and the
  // table of every surface in the world now, the level's and then the terrain
  // tiles in (a tile keeps the id it first came in with). The table changes
  // when tiles come or go, and surface_revision() with it.
  const SurfaceIds& surface_ids() const;
  std::vector<SurfaceEntry> SurfaceTable() const;
  std::uint64_t surface_revision() const;

  int num_collision_objects() const;
  int num_parts() const;  // Bullet mesh parts over all shapes
  // The static actors' triangles that rays walk in one hierarchy, or 0 when
  // each object walks its own (fewer than two static objects, or over 2^20
  // static triangles: then rays are slower).
  std::size_t merged_static_triangles() const;

  // A number no other world of this process has, and one counting the
  // changes to its placements and origin: together they name the world's
  // state (a ray caster keeps what it derived from one state until it changes).
  std::uint64_t instance() const { return instance_; }
  std::uint64_t revision() const { return revision_; }

  // The Bullet objects inside, for sensors/ (scene/collision_world_internal.h).
  struct Impl;
  const Impl& internals() const { return *impl_; }

 private:
  std::unique_ptr<Impl> impl_;
  std::vector<std::string> actor_names_;
  Eigen::Vector3d p_WO_{Eigen::Vector3d::Zero()};
  std::uint64_t instance_{0}, revision_{0};
};

}  // namespace sandbox::scene
