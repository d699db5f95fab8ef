#include "sensors/ray_targets.h"

#include <algorithm>
#include <stdexcept>

#include "scene/collision_world_internal.h"

namespace sandbox::sensors {
namespace {

// The margin of a target's boxes: a few thousand ulps of the coordinates
// involved (the boxes' and the placement's).
float BoxMargin(const scene::TriangleBvh& bvh, const Eigen::Vector3f& p_LB,
                const Eigen::Vector3f& p_BL) {
  const float scale = std::max({bvh.lower.cwiseAbs().maxCoeff(), bvh.upper.cwiseAbs().maxCoeff(),
                                p_LB.cwiseAbs().maxCoeff(), p_BL.cwiseAbs().maxCoeff()});
  return 1e-5f * scale + 1e-6f;
}

}  // namespace

// The merged target's corners are where Bullet placed them at the origin it
// was built at: a whole-metre shift moves them as a translation.
Target MergedTarget(const scene::CollisionWorld& world) {
  const scene::MergedStatic& merged = world.internals().merged_static;
  Target t;
  t.body = -2;  // none: each lane's surface is SurfaceOf its part
  t.group = scene::kWorldStatic;
  t.bvh = merged.bvh.get();
  t.surface_of_part = merged.surface_of_part.data();
  t.reflectivity_of_part = merged.reflectivity_of_part.data();
  const btVector3 offset = scene::ToBullet(merged.p_WO - world.origin());
  t.X_BL.setIdentity();
  t.X_BL.setOrigin(offset);
  t.identity = offset == btVector3(0, 0, 0);
  t.R_LB.setIdentity();
  t.p_LB = -ToEigen(offset);
  t.box_margin = BoxMargin(*t.bvh, t.p_LB, ToEigen(offset));
  t.aabb_min = t.bvh->lower - t.p_LB - Eigen::Vector3f::Constant(t.box_margin);
  t.aabb_max = t.bvh->upper - t.p_LB + Eigen::Vector3f::Constant(t.box_margin);
  t.body_min = t.aabb_min, t.body_max = t.aabb_max;
  return t;
}

std::vector<Target> CollectTargets(const scene::CollisionWorld& world) {
  const scene::CollisionWorld::Impl& w = world.internals();
  std::vector<Target> targets;
  for (const scene::MeshObject& object : w.objects) {
    const btCollisionObject& o = *object.object;
    Target t;
    t.body = o.getUserIndex();
    t.surface = object.surface;
    t.reflectivity_of_part = object.reflectivity_of_part.data();
    t.group = static_cast<std::uint32_t>(o.getBroadphaseHandle()->m_collisionFilterGroup);
    t.aabb_min = ToEigen(o.getBroadphaseHandle()->m_aabbMin);
    t.aabb_max = ToEigen(o.getBroadphaseHandle()->m_aabbMax);
    const btTransform& X = o.getWorldTransform();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) t.R_LB(c, r) = float(X.getBasis()[r][c]);
    }
    t.X_BL = X;
    t.identity = X.getBasis() == btMatrix3x3::getIdentity() && X.getOrigin() == btVector3(0, 0, 0);
    t.p_LB = -(t.R_LB * ToEigen(X.getOrigin()));
    t.bvh = object.bvh.get();
    if (t.bvh == nullptr)
      throw std::logic_error("CollectTargets(): an object without its hierarchy");
    t.box_margin = BoxMargin(*t.bvh, t.p_LB, ToEigen(X.getOrigin()));
    targets.push_back(std::move(t));
  }
  for (std::size_t first = 0, end = 0; first < targets.size(); first = end) {
    Eigen::Vector3f lo = targets[first].aabb_min, hi = targets[first].aabb_max;
    for (end = first + 1; end < targets.size() && targets[end].body == targets[first].body; ++end) {
      lo = lo.cwiseMin(targets[end].aabb_min), hi = hi.cwiseMax(targets[end].aabb_max);
    }
    for (std::size_t t = first; t < end; ++t) targets[t].body_min = lo, targets[t].body_max = hi;
  }
  return targets;
}

}  // namespace sandbox::sensors
