#pragma once
// The world's objects as the ray caster's kernels read them: internal to the
// caster (ray_caster.cc, ray_targets.cc and the kernels of ray_kernels.h).

#include <LinearMath/btTransform.h>

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "scene/collision_world.h"
#include "scene/triangle_bvh.h"
#include "sensors/ray_caster.h"

namespace sandbox::sensors {

constexpr int kStackInPlace = RayCaster::kStackInPlace;

// One Bullet object as a ray sees it: where it is and its own hierarchy.
struct Target {
  int body{-1};            // the actor, or num_actors + the robot (what RayFilter names)
  std::uint32_t group{0};  // the object's collision group (scene::kWorldStatic, ...)
  // The box around this object and the other objects of its body next to it
  // in the list (a robot's pieces): a packet that misses it skips them all.
  Eigen::Vector3f body_min{Eigen::Vector3f::Zero()}, body_max{Eigen::Vector3f::Zero()};
  Eigen::Vector3f aabb_min, aabb_max;  // in the Bullet frame (world minus origin)
  Eigen::Matrix3f R_LB;                // local from Bullet frame
  Eigen::Vector3f p_LB;
  btTransform X_BL;      // Bullet frame from local: where triangles are tested
  bool identity{false};  // X_BL is exactly the identity
  // The object's own hierarchy (local frame), and how far its boxes are grown
  // for the rounding of rays taken into that frame.
  const scene::TriangleBvh* bvh{nullptr};
  float box_margin{0.f};
  // What a hit on it reports (scene/surface_ids.h): the merged static
  // objects' target (scene::MergedStatic) has a surface per leaf part
  // (SurfaceOf); any other, its one surface.
  std::int32_t surface{0};
  const std::int32_t* surface_of_part{nullptr};
  int SurfaceOf(int part) const {
    return surface_of_part != nullptr ? surface_of_part[part] : surface;
  }
  // What a lidar sees of each part (scene::MeshReflectivity: a part is one
  // mesh, of one material); read at a hit only.
  const float* reflectivity_of_part{nullptr};
  float ReflectivityOf(int part) const {
    return reflectivity_of_part != nullptr ? reflectivity_of_part[part]
                                           : scene::SurfaceEntry::kDefaultReflectivity;
  }
};

inline Eigen::Vector3f ToEigen(const btVector3& v) {
  return {float(v.x()), float(v.y()), float(v.z())};
}

// The corners of triangle i of a leaf of the target's own hierarchy, in the
// Bullet frame as Bullet places them. (Internal linkage: each kernel's copy
// is built for its set.)
static inline void LeafCorners(const Target& target, const scene::TriangleBvh::Leaves& leaf, int i,
                               Eigen::Vector3f corner[3]) {
  for (int k = 0; k < 3; ++k) {
    const Eigen::Vector3f p(leaf.corner[3 * k][i], leaf.corner[3 * k + 1][i],
                            leaf.corner[3 * k + 2][i]);
    corner[k] = target.identity ? p : ToEigen(target.X_BL * btVector3(p.x(), p.y(), p.z()));
  }
}

// Every object of the world, in the world's order (a body's objects next to
// each other), with the boxes around each run of one body's objects.
std::vector<Target> CollectTargets(const scene::CollisionWorld& world);

// The target of the world's merged static objects (scene::MergedStatic),
// placed for the world's origin now.
Target MergedTarget(const scene::CollisionWorld& world);

}  // namespace sandbox::sensors
