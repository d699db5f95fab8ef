#include "scene/collision_world.h"

#include <algorithm>
#include <atomic>
#include <map>
#include <stdexcept>
#include <string>
#include <vector>

#include "scene/check.h"
#include "scene/collision_world_internal.h"

namespace sandbox::scene {
namespace {

// A mesh's vertices at the state's pose, in frame B (linear-blend skinning
// in double, as RobotState::Update does for the drawn meshes).
std::vector<Eigen::Vector3f> RestPositions(const RobotModel& model, const RobotState& rest,
                                           const SkinnedMesh& mesh) {
  std::vector<Eigen::Vector3f> out(mesh.bind.positions_A.size());
  for (std::size_t v = 0; v < out.size(); ++v) {
    Eigen::Matrix4d M = Eigen::Matrix4d::Zero();
    for (std::uint32_t i = mesh.influence_begin[v]; i < mesh.influence_begin[v + 1]; ++i) {
      const SkinJoint& joint = model.joints[mesh.influence_joint[i]];
      M += mesh.influence_weight[i] *
           (rest.node_poses_B()[static_cast<std::size_t>(joint.node)] * joint.offset).matrix();
    }
    out[v] = (M.topLeftCorner<3, 3>() * mesh.bind.positions_A[v].cast<double>() +
              M.topRightCorner<3, 1>())
                 .cast<float>();
  }
  return out;
}

Eigen::Vector3d FromBullet(const btVector3& v) { return {v.x(), v.y(), v.z()}; }

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

}  // namespace

CollisionWorld::CollisionWorld(const Level& level) : impl_(std::make_unique<Impl>()) {
  static std::atomic<std::uint64_t> instances{0};
  instance_ = ++instances;
  Impl& w = *impl_;
  w.broadphase.m_deferedcollide = true;  // no overlap search when objects are added
  w.num_actors = static_cast<int>(level.actors.size());
  w.terrain_actor = level.terrain_actor;
  w.surface_ids = std::make_unique<SurfaceIds>(level);
  w.objects_of_body.resize(level.actors.size() + level.robots.size());
  for (std::size_t a = 0; a < level.actors.size(); ++a) {
    const Actor& actor = level.actors[a];
    w.X_W.push_back(actor.X_WA);
    w.movable.push_back(actor.movable);
    actor_names_.push_back(actor.name);
    if (!actor.collision) continue;
    std::vector<MeshArrays> meshes;
    for (const Mesh& mesh : actor.meshes) {
      meshes.push_back(
          {&mesh.positions_A, &mesh.indices, MeshReflectivity(actor, mesh, level.materials)});
    }
    w.AddBody(static_cast<int>(a), w.surface_ids->actor(static_cast<int>(a)), meshes,
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
    const bool own = !model.collision_meshes.empty();   // else the drawn meshes
    const std::vector<SkinnedMesh>& meshes = own ? model.collision_meshes : model.meshes;
    for (std::size_t m = 0; m < meshes.size(); ++m) {
      const std::vector<int> node_of = DominantNodePerTriangle(model, meshes[m]);
      const std::vector<std::uint32_t>& indices = meshes[m].bind.indices;
      const std::vector<Eigen::Vector3f> rest_B =
          own ? RestPositions(model, rest, meshes[m]) : rest.positions_B(static_cast<int>(m));
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
    const std::vector<int> bone_of_node = BoneGroupOfNodes(model);
    for (auto& [node, piece] : pieces) {
      const int bone = node >= 0 ? bone_of_node[static_cast<std::size_t>(node)] : 0;
      const std::int32_t surface = w.surface_ids->bone(static_cast<int>(r), bone);
      w.AddBody(body, surface,
                {{&piece->positions, &piece->indices, w.surface_ids->reflectivity(surface)}},
                static_cast<int>(kRobot),
                RigidPart(rest.node_poses_B()[static_cast<std::size_t>(node)]));
      w.robot_pieces[r].push_back(std::move(piece));
    }
    w.Place(body, p_WO_);
  }
  w.MergeStatic(p_WO_);
}

void CollisionWorld::Impl::MergeStatic(const Eigen::Vector3d& p_WO) {
  std::vector<MeshObject*> statics;
  std::size_t triangles = 0;
  for (MeshObject& object : objects) {
    const int group = object.object->getBroadphaseHandle()->m_collisionFilterGroup;
    if (object.tile != 0 || group != static_cast<int>(kWorldStatic)) continue;
    statics.push_back(&object);
    for (int p = 0; p < object.mesh_interface->getNumSubParts(); ++p) {
      triangles += std::size_t(object.mesh_interface->getIndexedMeshArray()[p].m_numTriangles);
    }
  }
  if (statics.size() < 2 || triangles > kMaxMergedTriangles) return;
  // Each part's corners placed as Bullet places them (its float transform).
  std::vector<std::vector<Eigen::Vector3f>> positions;
  std::vector<TriangleSoup> soups;
  merged_static.holds_actor.assign(std::size_t(num_actors), false);
  for (MeshObject* object : statics) {
    const btTransform& X = object->object->getWorldTransform();
    const int body = object->object->getUserIndex();
    const IndexedMeshArray& parts = object->mesh_interface->getIndexedMeshArray();
    for (int k = 0; k < parts.size(); ++k) {
      const btIndexedMesh& part = parts[k];
      std::vector<Eigen::Vector3f>& placed =
          positions.emplace_back(std::size_t(part.m_numVertices));
      const auto* in = reinterpret_cast<const Eigen::Vector3f*>(part.m_vertexBase);
      for (std::size_t v = 0; v < placed.size(); ++v) {
        const btVector3 p = X * btVector3(in[v].x(), in[v].y(), in[v].z());
        placed[v] = {p.x(), p.y(), p.z()};
      }
      soups.push_back({placed.data(), placed.size(),
                       reinterpret_cast<const std::uint32_t*>(part.m_triangleIndexBase),
                       std::size_t(part.m_numTriangles)});
      merged_static.surface_of_part.push_back(object->surface);
      merged_static.reflectivity_of_part.push_back(object->reflectivity_of_part[std::size_t(k)]);
    }
    merged_static.holds_actor[std::size_t(body)] = true;
    object->merged = true;
  }
  merged_static.bvh = std::make_shared<const TriangleBvh>(BuildTriangleBvh(soups));
  merged_static.p_WO = p_WO;
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
  hit.surface = callback.m_collisionObject->getUserIndex2();
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
  ++revision_;
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
  ++revision_;
}

void CollisionWorld::SetOrigin(const Eigen::Vector3d& p_WO) {
  p_WO_ = p_WO;
  for (std::size_t b = 0; b < impl_->X_W.size(); ++b) impl_->Place(static_cast<int>(b), p_WO_);
  ++revision_;
}

std::shared_ptr<CollisionWorld::PreparedTile> CollisionWorld::PrepareTile(
    std::shared_ptr<const TerrainTile> tile) {
  auto prepared = std::make_shared<PreparedTile>();
  const Eigen::Isometry3d X_AT(Eigen::Translation3d(tile->origin_W));
  prepared->objects = Impl::MakeObjects(-1, {{&tile->positions, &tile->indices}}, X_AT);
  for (MeshObject& object : prepared->objects) object.tile = tile->id.key() + 1;
  prepared->tile = std::move(tile);
  return prepared;
}

void CollisionWorld::AddTile(std::shared_ptr<PreparedTile> tile) {
  Impl& w = *impl_;
  if (w.terrain_actor < 0)
    throw std::logic_error("CollisionWorld::AddTile(): the level has no terrain");
  const std::uint64_t key = tile->tile->id.key();
  RemoveTile(key);
  auto [known, is_new] = w.tile_surface.try_emplace(key + 1, 0);
  if (is_new) {
    known->second = w.surface_ids->first_tile() + std::int32_t(w.tile_surface.size()) - 1;
  }
  for (MeshObject& object : tile->objects) {
    object.object->setUserIndex(w.terrain_actor);
    object.object->setUserIndex2(known->second);
    object.surface = known->second;
    std::fill(object.reflectivity_of_part.begin(), object.reflectivity_of_part.end(),
              w.surface_ids->reflectivity(known->second));
    w.Add(std::move(object), static_cast<int>(kWorldStatic));
  }
  w.tiles[key + 1] = tile->tile;
  w.Place(w.terrain_actor, p_WO_);
  ++revision_;
  ++w.surface_revision;
}

bool CollisionWorld::RemoveTile(std::uint64_t key) {
  if (!impl_->RemoveTile(key + 1)) return false;
  impl_->tiles.erase(key + 1);
  ++revision_;
  ++impl_->surface_revision;
  return true;
}

const SurfaceIds& CollisionWorld::surface_ids() const { return *impl_->surface_ids; }

std::vector<SurfaceEntry> CollisionWorld::SurfaceTable() const {
  const Impl& w = *impl_;
  std::vector<SurfaceEntry> table = w.surface_ids->entries();
  for (const auto& [key_1, tile] : w.tiles) {
    const TileId& id = tile->id;
    SurfaceEntry entry;
    entry.id = w.tile_surface.at(key_1);
    entry.kind = "tile";
    entry.name = "terrain/" + std::to_string(id.file) + "/" + std::to_string(id.tx) + "," +
                 std::to_string(id.ty);
    entry.actor = w.terrain_actor;
    entry.reflectivity = w.surface_ids->reflectivity(entry.id);
    table.push_back(std::move(entry));
  }
  return table;
}

std::uint64_t CollisionWorld::surface_revision() const { return impl_->surface_revision; }

int CollisionWorld::num_tiles() const { return static_cast<int>(impl_->tiles.size()); }

int CollisionWorld::num_collision_objects() const {
  return static_cast<int>(impl_->objects.size());
}

int CollisionWorld::num_parts() const { return impl_->num_parts; }

std::size_t CollisionWorld::merged_static_triangles() const {
  const std::shared_ptr<const TriangleBvh>& bvh = impl_->merged_static.bvh;
  std::size_t triangles = 0;
  if (bvh != nullptr) {
    for (const TriangleBvh::Leaves& leaf : bvh->leaves) triangles += std::size_t(leaf.count);
  }
  return triangles;
}

}  // namespace sandbox::scene
