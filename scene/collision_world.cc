#include "scene/collision_world.h"

#include <btBulletCollisionCommon.h>

#include <algorithm>
#include <map>
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

// Vertex and index arrays of one mesh, read in place by Bullet.
struct MeshArrays {
  const std::vector<Eigen::Vector3f>* positions;
  const std::vector<std::uint32_t>* indices;
};

// One Bullet object: a shape over at most kMaxPartsPerShape mesh parts.
struct MeshObject {
  std::unique_ptr<btTriangleIndexVertexArray> mesh_interface;
  std::unique_ptr<btBvhTriangleMeshShape> shape;
  std::unique_ptr<btCollisionObject> object;
  Eigen::Isometry3d X_BO{Eigen::Isometry3d::Identity()};  // in its body's frame
};

// A rigid piece of a robot's collision body: the triangles that mostly follow
// one node, in that node's frame at rest.
struct RobotPiece {
  int node{-1};
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::uint32_t> indices;
};

// Ray callback that skips the bodies (actors or robots) of the world it is told.
struct ClosestHitIgnoring : btCollisionWorld::ClosestRayResultCallback {
  ClosestHitIgnoring(const btVector3& from, const btVector3& to, int ignore_a, int ignore_b)
      : ClosestRayResultCallback(from, to), ignore_first(ignore_a), ignore_second(ignore_b) {}
  bool needsCollision(btBroadphaseProxy* proxy) const override {
    const int body = static_cast<const btCollisionObject*>(proxy->m_clientObject)->getUserIndex();
    return body != ignore_first && body != ignore_second &&
           ClosestRayResultCallback::needsCollision(proxy);
  }
  int ignore_first;
  int ignore_second;
};

btTransform ToBulletTransform(const Eigen::Isometry3d& X, const Eigen::Vector3d& p_WO) {
  btTransform transform;
  transform.setOrigin(ToBullet(X.translation() - p_WO));
  const Eigen::Matrix3d& R = X.linear();
  transform.setBasis(btMatrix3x3(static_cast<btScalar>(R(0, 0)), static_cast<btScalar>(R(0, 1)),
                                 static_cast<btScalar>(R(0, 2)), static_cast<btScalar>(R(1, 0)),
                                 static_cast<btScalar>(R(1, 1)), static_cast<btScalar>(R(1, 2)),
                                 static_cast<btScalar>(R(2, 0)), static_cast<btScalar>(R(2, 1)),
                                 static_cast<btScalar>(R(2, 2))));
  return transform;
}

}  // namespace

// Bodies are the actors (0 .. A-1) and then the robots (A .. A+R-1); a Bullet
// object's user index is its body.
struct CollisionWorld::Impl {
  // Bullet wants a dispatcher to build a collision world; it is never used to
  // step anything.
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btDbvtBroadphase broadphase;
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
  std::vector<MeshObject> objects;
  std::vector<std::vector<int>> objects_of_body;  // indices into `objects`
  std::vector<Eigen::Isometry3d> X_W;             // pose of each body
  std::vector<bool> movable;                      // actors only
  int num_actors{0};
  int num_parts{0};
  // Robots: their models and rigid pieces (Bullet reads the pieces' arrays).
  std::vector<const RobotModel*> robot_models;
  std::vector<std::vector<std::unique_ptr<RobotPiece>>> robot_pieces;

  ~Impl() {
    for (MeshObject& object : objects) world.removeCollisionObject(object.object.get());
  }

  // Creates the objects of one body over `meshes` (split to Bullet's limits),
  // placed at X_BO in the body's frame; returns their indices in `objects`.
  std::vector<int> AddBody(int body, const std::vector<MeshArrays>& meshes, int group,
                           const Eigen::Isometry3d& X_BO = Eigen::Isometry3d::Identity()) {
    std::vector<int> added;
    std::vector<btIndexedMesh> parts;
    for (const MeshArrays& mesh : meshes) {
      const std::size_t triangles = mesh.indices->size() / 3;
      for (std::size_t first = 0; first < triangles; first += kMaxTrianglesPerPart) {
        btIndexedMesh part;
        part.m_numTriangles = static_cast<int>(std::min(kMaxTrianglesPerPart, triangles - first));
        part.m_triangleIndexBase =
            reinterpret_cast<const unsigned char*>(&(*mesh.indices)[3 * first]);
        part.m_triangleIndexStride = 3 * sizeof(std::uint32_t);
        part.m_indexType = PHY_INTEGER;
        part.m_numVertices = static_cast<int>(mesh.positions->size());
        part.m_vertexBase = reinterpret_cast<const unsigned char*>(mesh.positions->data());
        part.m_vertexStride = sizeof(Eigen::Vector3f);
        part.m_vertexType = PHY_FLOAT;
        parts.push_back(part);
      }
    }
    for (std::size_t first = 0; first < parts.size(); first += kMaxPartsPerShape) {
      MeshObject object;
      object.mesh_interface = std::make_unique<btTriangleIndexVertexArray>();
      const std::size_t end = std::min(parts.size(), first + kMaxPartsPerShape);
      for (std::size_t p = first; p < end; ++p) object.mesh_interface->addIndexedMesh(parts[p]);
      object.shape = std::make_unique<btBvhTriangleMeshShape>(object.mesh_interface.get(), true);
      object.object = std::make_unique<btCollisionObject>();
      object.object->setCollisionShape(object.shape.get());
      object.object->setUserIndex(body);
      object.X_BO = X_BO;
      world.addCollisionObject(object.object.get(), group, static_cast<int>(kAllGroups));
      num_parts += static_cast<int>(end - first);
      objects_of_body[static_cast<std::size_t>(body)].push_back(static_cast<int>(objects.size()));
      added.push_back(static_cast<int>(objects.size()));
      objects.push_back(std::move(object));
    }
    return added;
  }

  void Place(int body, const Eigen::Vector3d& p_WO) {
    const Eigen::Isometry3d& X_WB = X_W[static_cast<std::size_t>(body)];
    for (int index : objects_of_body[static_cast<std::size_t>(body)]) {
      MeshObject& object = objects[static_cast<std::size_t>(index)];
      object.object->setWorldTransform(ToBulletTransform(X_WB * object.X_BO, p_WO));
      world.updateSingleAabb(object.object.get());
    }
  }
};

CollisionWorld::CollisionWorld(const Level& level) : impl_(std::make_unique<Impl>()) {
  Impl& w = *impl_;
  w.num_actors = static_cast<int>(level.actors.size());
  w.objects_of_body.resize(level.actors.size() + level.robots.size());
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    const Actor& actor = level.actors[a];
    w.X_W.push_back(actor.X_WA);
    w.movable.push_back(actor.movable);
    actor_names_.push_back(actor.name);
    if (!actor.collision) continue;
    std::vector<MeshArrays> meshes;
    for (const Mesh& mesh : actor.meshes) meshes.push_back({&mesh.positions_A, &mesh.indices});
    w.AddBody(static_cast<int>(a), meshes,
              static_cast<int>(actor.movable ? kWorldMovable : kWorldStatic));
    w.Place(static_cast<int>(a), p_WO_);
  }
  // Robots: the skin cut into rigid pieces, one per dominant node, each
  // moved with its node (a transform per tick, no BVH work).
  for (std::size_t r = 0; r < level.robots.size(); ++r) {
    const RobotModel& model = level.robots[r];
    const RobotState rest(model);
    w.robot_models.push_back(&model);
    w.X_W.push_back(rest.pose());
    w.robot_pieces.emplace_back();
    if (!model.collision) continue;
    std::map<int, std::unique_ptr<RobotPiece>> pieces;  // by node
    for (std::size_t m = 0; m < model.meshes.size(); ++m) {
      const std::vector<int> node_of = DominantNodePerTriangle(model, static_cast<int>(m));
      const std::vector<std::uint32_t>& indices = model.meshes[m].bind.indices;
      const auto& rest_B = rest.positions_B(static_cast<int>(m));
      for (std::size_t t = 0; t < node_of.size(); ++t) {
        auto& piece = pieces[node_of[t]];
        if (!piece) piece = std::make_unique<RobotPiece>(), piece->node = node_of[t];
        const Eigen::Isometry3d X_PB =
            RigidPart(rest.node_poses_B()[static_cast<std::size_t>(node_of[t])]).inverse();
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3d p_B = rest_B[indices[3 * t + std::size_t(k)]].cast<double>();
          piece->indices.push_back(static_cast<std::uint32_t>(piece->positions.size()));
          piece->positions.push_back((X_PB * p_B).cast<float>());
        }
      }
    }
    const int body = w.num_actors + static_cast<int>(r);
    for (auto& [node, piece] : pieces) {
      w.AddBody(body, {{&piece->positions, &piece->indices}}, static_cast<int>(kRobot),
                RigidPart(rest.node_poses_B()[static_cast<std::size_t>(node)]));
      w.robot_pieces[r].push_back(std::move(piece));
    }
    w.Place(body, p_WO_);
  }
}

CollisionWorld::~CollisionWorld() = default;

std::optional<RayHit> CollisionWorld::CastRay(const Eigen::Vector3d& from_W,
                                              const Eigen::Vector3d& to_W, std::uint32_t group_mask,
                                              int ignore_actor, int ignore_robot) const {
  const btVector3 from = ToBullet(from_W - p_WO_);
  const btVector3 to = ToBullet(to_W - p_WO_);
  ClosestHitIgnoring callback(from, to, ignore_actor < 0 ? -1 : ignore_actor,
                              ignore_robot < 0 ? -1 : impl_->num_actors + ignore_robot);
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
  const int body = callback.m_collisionObject->getUserIndex();
  if (body < impl_->num_actors) {
    hit.actor = body;
  } else {
    hit.robot = body - impl_->num_actors;
  }
  return hit;
}

void CollisionWorld::SetActorPose(int actor, const Eigen::Isometry3d& X_WA) {
  if (actor < 0 || actor >= impl_->num_actors) {
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
  impl_->X_W[static_cast<std::size_t>(actor)] = X_WA;
  impl_->Place(actor, p_WO_);
}

void CollisionWorld::SetActorPose(std::string_view actor, const Eigen::Isometry3d& X_WA) {
  for (int a = 0; a < impl_->num_actors; ++a) {
    if (actor_names_[static_cast<std::size_t>(a)] == actor) return SetActorPose(a, X_WA);
  }
  throw std::invalid_argument("CollisionWorld::SetActorPose(): no actor '" + std::string(actor) +
                              "'");
}

const Eigen::Isometry3d& CollisionWorld::actor_pose(int actor) const {
  SANDBOX_CHECK(actor >= 0 && actor < impl_->num_actors);
  return impl_->X_W[static_cast<std::size_t>(actor)];
}

void CollisionWorld::UpdateRobot(int robot, const RobotState& state) {
  Impl& w = *impl_;
  SANDBOX_CHECK(robot >= 0 && robot < static_cast<int>(w.robot_models.size()));
  SANDBOX_CHECK(&state.model() == w.robot_models[static_cast<std::size_t>(robot)]);
  const int body = w.num_actors + robot;
  w.X_W[static_cast<std::size_t>(body)] = state.pose();
  const auto& pieces = w.robot_pieces[static_cast<std::size_t>(robot)];
  const std::vector<int>& objects = w.objects_of_body[static_cast<std::size_t>(body)];
  // Objects were added piece by piece, one object per piece.
  for (std::size_t p = 0; p < pieces.size(); ++p) {
    w.objects[static_cast<std::size_t>(objects[p])].X_BO =
        RigidPart(state.node_poses_B()[static_cast<std::size_t>(pieces[p]->node)]);
  }
  w.Place(body, p_WO_);
}

void CollisionWorld::SetOrigin(const Eigen::Vector3d& p_WO) {
  p_WO_ = p_WO;
  for (std::size_t b = 0; b < impl_->X_W.size(); ++b) impl_->Place(static_cast<int>(b), p_WO_);
}

int CollisionWorld::num_collision_objects() const {
  return static_cast<int>(impl_->objects.size());
}

int CollisionWorld::num_parts() const { return impl_->num_parts; }

}  // namespace sandbox::scene
