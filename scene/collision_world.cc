#include "scene/collision_world.h"

#include <btBulletCollisionCommon.h>

#include <stdexcept>
#include <string>
#include <vector>

#include "scene/check.h"

namespace sandbox::scene {
namespace {

// Bullet's quantized BVH stores a part index in 10 bits and a triangle index
// in 21 bits: more crashes on the first ray.
constexpr std::size_t kMaxTrianglesPerPart = std::size_t{1} << 21;
constexpr int kMaxPartsPerShape = 1024;

btVector3 ToBullet(const Eigen::Vector3d& v) {
  return {static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()), static_cast<btScalar>(v.z())};
}

Eigen::Vector3d FromBullet(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

// One Bullet object: a shape over at most kMaxPartsPerShape mesh parts.
struct MeshObject {
  std::unique_ptr<btTriangleIndexVertexArray> mesh_interface;
  std::unique_ptr<btBvhTriangleMeshShape> shape;
  std::unique_ptr<btCollisionObject> object;
  int actor{-1};
};

// Ray callback that skips one actor.
struct ClosestHitIgnoring : btCollisionWorld::ClosestRayResultCallback {
  ClosestHitIgnoring(const btVector3& from, const btVector3& to, int ignore)
      : ClosestRayResultCallback(from, to), ignore_actor(ignore) {}
  bool needsCollision(btBroadphaseProxy* proxy) const override {
    const auto* object = static_cast<const btCollisionObject*>(proxy->m_clientObject);
    return object->getUserIndex() != ignore_actor &&
           ClosestRayResultCallback::needsCollision(proxy);
  }
  int ignore_actor;
};

}  // namespace

struct CollisionWorld::Impl {
  // Bullet wants a dispatcher to build a collision world; it is never used to
  // step anything.
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
  std::vector<MeshObject> objects;
  std::vector<std::vector<int>> objects_of_actor;  // indices into `objects`
  std::vector<Eigen::Isometry3d> X_WA;
  std::vector<bool> movable;
  int num_parts{0};

  ~Impl() {
    for (MeshObject& object : objects) world.removeCollisionObject(object.object.get());
  }

  void Place(int actor, const Eigen::Vector3d& p_WO) {
    const Eigen::Isometry3d& X = X_WA[static_cast<std::size_t>(actor)];
    btTransform transform;
    transform.setOrigin(ToBullet(X.translation() - p_WO));
    const Eigen::Matrix3d& R = X.linear();
    transform.setBasis(btMatrix3x3(static_cast<btScalar>(R(0, 0)), static_cast<btScalar>(R(0, 1)),
                                   static_cast<btScalar>(R(0, 2)), static_cast<btScalar>(R(1, 0)),
                                   static_cast<btScalar>(R(1, 1)), static_cast<btScalar>(R(1, 2)),
                                   static_cast<btScalar>(R(2, 0)), static_cast<btScalar>(R(2, 1)),
                                   static_cast<btScalar>(R(2, 2))));
    for (int index : objects_of_actor[static_cast<std::size_t>(actor)]) {
      btCollisionObject* object = objects[static_cast<std::size_t>(index)].object.get();
      object->setWorldTransform(transform);
      world.updateSingleAabb(object);
    }
  }
};

CollisionWorld::CollisionWorld(const Level& level) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  const std::size_t num_actors = level.actors.size();
  w.objects_of_actor.resize(num_actors);
  w.movable.resize(num_actors);
  for (std::size_t a = 0; a < num_actors; ++a) {
    const Actor& actor = level.actors[a];
    w.X_WA.push_back(actor.X_WA);
    w.movable[a] = actor.movable;
    if (!actor.collision) continue;

    // Parts: each mesh, split into runs of at most kMaxTrianglesPerPart triangles.
    std::vector<btIndexedMesh> parts;
    for (const Mesh& mesh : actor.meshes) {
      for (std::size_t first = 0; first < mesh.num_triangles(); first += kMaxTrianglesPerPart) {
        btIndexedMesh part;
        part.m_numTriangles =
            static_cast<int>(std::min(kMaxTrianglesPerPart, mesh.num_triangles() - first));
        part.m_triangleIndexBase = reinterpret_cast<const unsigned char*>(&mesh.indices[3 * first]);
        part.m_triangleIndexStride = 3 * sizeof(std::uint32_t);
        part.m_indexType = PHY_INTEGER;
        part.m_numVertices = static_cast<int>(mesh.positions_A.size());
        part.m_vertexBase = reinterpret_cast<const unsigned char*>(mesh.positions_A.data());
        part.m_vertexStride = sizeof(Eigen::Vector3f);
        part.m_vertexType = PHY_FLOAT;
        parts.push_back(part);
      }
    }
    // Shapes: at most kMaxPartsPerShape parts each.
    const auto group = static_cast<int>(actor.movable ? kWorldMovable : kWorldStatic);
    for (std::size_t first = 0; first < parts.size(); first += kMaxPartsPerShape) {
      MeshObject object;
      object.actor = static_cast<int>(a);
      object.mesh_interface = std::make_unique<btTriangleIndexVertexArray>();
      const std::size_t end = std::min(parts.size(), first + kMaxPartsPerShape);
      for (std::size_t p = first; p < end; ++p) object.mesh_interface->addIndexedMesh(parts[p]);
      object.shape = std::make_unique<btBvhTriangleMeshShape>(object.mesh_interface.get(), true);
      object.object = std::make_unique<btCollisionObject>();
      object.object->setCollisionShape(object.shape.get());
      object.object->setUserIndex(static_cast<int>(a));
      w.world.addCollisionObject(object.object.get(), group, static_cast<int>(kAllGroups));
      w.num_parts += static_cast<int>(end - first);
      w.objects_of_actor[a].push_back(static_cast<int>(w.objects.size()));
      w.objects.push_back(std::move(object));
    }
    w.Place(static_cast<int>(a), p_WO_);
  }
}

CollisionWorld::~CollisionWorld() = default;

std::optional<RayHit> CollisionWorld::CastRay(const Eigen::Vector3d& from_W,
                                              const Eigen::Vector3d& to_W, std::uint32_t group_mask,
                                              int ignore_actor) const {
  const btVector3 from = ToBullet(from_W - p_WO_);
  const btVector3 to = ToBullet(to_W - p_WO_);
  ClosestHitIgnoring callback(from, to, ignore_actor);
  callback.m_collisionFilterGroup = static_cast<int>(kAllGroups);
  callback.m_collisionFilterMask = static_cast<int>(group_mask);
  impl_->world.rayTest(from, to, callback);
  if (!callback.hasHit()) return std::nullopt;
  RayHit hit;
  const double fraction = callback.m_closestHitFraction;
  hit.point_W = from_W + fraction * (to_W - from_W);
  hit.distance_m = fraction * (to_W - from_W).norm();
  hit.normal_W = FromBullet(callback.m_hitNormalWorld).normalized();
  if (hit.normal_W.dot(to_W - from_W) > 0.0) hit.normal_W = -hit.normal_W;
  hit.actor = callback.m_collisionObject->getUserIndex();
  return hit;
}

void CollisionWorld::SetActorPose(int actor, const Eigen::Isometry3d& X_WA) {
  if (actor < 0 || actor >= static_cast<int>(impl_->X_WA.size())) {
    throw std::invalid_argument("CollisionWorld::SetActorPose(): no actor " +
                                std::to_string(actor));
  }
  if (!impl_->movable[static_cast<std::size_t>(actor)]) {
    throw std::invalid_argument("CollisionWorld::SetActorPose(): actor " + std::to_string(actor) +
                                " is not movable");
  }
  if (!X_WA.matrix().allFinite()) {
    throw std::invalid_argument("CollisionWorld::SetActorPose(): non-finite pose");
  }
  impl_->X_WA[static_cast<std::size_t>(actor)] = X_WA;
  impl_->Place(actor, p_WO_);
}

const Eigen::Isometry3d& CollisionWorld::actor_pose(int actor) const {
  SANDBOX_CHECK(actor >= 0 && actor < static_cast<int>(impl_->X_WA.size()));
  return impl_->X_WA[static_cast<std::size_t>(actor)];
}

void CollisionWorld::SetOrigin(const Eigen::Vector3d& p_WO) {
  p_WO_ = p_WO;
  for (std::size_t a = 0; a < impl_->X_WA.size(); ++a) impl_->Place(static_cast<int>(a), p_WO_);
}

int CollisionWorld::num_collision_objects() const {
  return static_cast<int>(impl_->objects.size());
}

int CollisionWorld::num_parts() const { return impl_->num_parts; }

}  // namespace sandbox::scene
