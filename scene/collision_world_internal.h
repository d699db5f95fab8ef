#pragma once
// Scene-internal, and for sensors/ (which may use Bullet): the inside of
// CollisionWorld. Includes Bullet; no public header includes this one.

#include <btBulletCollisionCommon.h>

#include <map>
#include <memory>
#include <thread>
#include <vector>

#include "scene/collision_world.h"
#include "scene/surface_ids.h"
#include "scene/terrain_tile.h"
#include "scene/triangle_bvh.h"

namespace sandbox::scene {

// Bullet's quantized BVH stores a part index in 10 bits and a triangle index
// in 21 bits: more crashes on the first ray.
constexpr std::size_t kMaxTrianglesPerPart = std::size_t{1} << 21;
constexpr int kMaxPartsPerShape = 1024;

inline btVector3 ToBullet(const Eigen::Vector3d& v) {
  return {static_cast<btScalar>(v.x()), static_cast<btScalar>(v.y()), static_cast<btScalar>(v.z())};
}

inline btTransform ToBulletTransform(const Eigen::Isometry3d& X, const Eigen::Vector3d& p_WO) {
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

// Vertex and index arrays of one mesh, read in place by Bullet.
struct MeshArrays {
  const std::vector<Eigen::Vector3f>* positions;
  const std::vector<std::uint32_t>* indices;
  float reflectivity{SurfaceEntry::kDefaultReflectivity};  // scene::MeshReflectivity
};

// One Bullet object: a shape over at most kMaxPartsPerShape mesh parts, and
// the ray caster's hierarchy over the same triangles (its own frame).
struct MeshObject {
  std::unique_ptr<btTriangleIndexVertexArray> mesh_interface;
  std::unique_ptr<btBvhTriangleMeshShape> shape;
  std::unique_ptr<btCollisionObject> object;
  std::shared_ptr<const TriangleBvh> bvh;
  Eigen::Isometry3d X_BO{Eigen::Isometry3d::Identity()};  // in its body's frame
  std::uint64_t tile{0};    // a terrain tile's key (TileId::key() + 1), 0 for the rest
  std::int32_t surface{0};  // its surface id (scene/surface_ids.h; also Bullet's user index 2)
  bool merged{false};       // its triangles are in CollisionWorld::Impl::merged_static too
  std::vector<float> reflectivity_of_part;  // by mesh part: what a lidar sees of it
};

// One hierarchy over the triangles of the static actors' objects (not the
// terrain tiles), corners as Bullet placed them with the floating origin at
// p_WO: a ray walks one tree instead of one per object, nearest first across
// them all (the objects of a game level overlap: those of the Quake 3 map of
// ../shared/assets, 61, cover each other's boxes). Leaf lanes name their
// triangle's part, surface_of_part its surface id (an actor's) and
// reflectivity_of_part what a lidar sees of it.
struct MergedStatic {
  std::shared_ptr<const TriangleBvh> bvh;
  std::vector<std::int32_t> surface_of_part;
  std::vector<float> reflectivity_of_part;
  std::vector<bool> holds_actor;  // by actor
  Eigen::Vector3d p_WO{Eigen::Vector3d::Zero()};
};

// A terrain tile's objects, built off the loop thread; the tile's arrays are
// what Bullet reads.
struct CollisionWorld::PreparedTile {
  std::shared_ptr<const TerrainTile> tile;
  std::vector<MeshObject> objects;
};

// A rigid piece of a robot's collision body: the triangles that mostly follow
// one node, in that node's frame at rest.
struct RobotPiece {
  int node{-1};
  std::vector<Eigen::Vector3f> positions;
  std::vector<std::uint32_t> indices;
};

// Bodies are the actors (0 .. A-1) and then the robots (A .. A+R-1); a Bullet
// object's user index is its body.
struct CollisionWorld::Impl {
  // Bullet wants a dispatcher to build a collision world; it is never used to
  // step anything. Nothing collides either, so no overlapping pairs are kept:
  // with Bullet's default pair cache, 4000 actors at one spot made 8 million
  // pairs, and removing them one by one took 36 s.
  btDefaultCollisionConfiguration configuration;
  btCollisionDispatcher dispatcher{&configuration};
  btNullPairCache pair_cache;
  btDbvtBroadphase broadphase{&pair_cache};
  btCollisionWorld world{&dispatcher, &broadphase, &configuration};
  std::vector<MeshObject> objects;
  std::vector<std::vector<int>> objects_of_body;  // indices into `objects`
  std::vector<Eigen::Isometry3d> X_W;             // pose of each body
  std::vector<bool> movable;                      // actors only
  int num_actors{0};
  int num_parts{0};
  int terrain_actor{-1};  // the body of the terrain tiles (Level::terrain_actor)
  std::map<std::uint64_t, std::shared_ptr<const TerrainTile>> tiles;  // by key + 1
  // Surface ids: the level's, and each tile's from the first time it came in
  // (by key + 1; kept when the tile leaves, so it comes back with its id).
  std::unique_ptr<SurfaceIds> surface_ids;
  std::map<std::uint64_t, std::int32_t> tile_surface;
  std::uint64_t surface_revision{0};
  // Robots: their models and rigid pieces (Bullet reads the pieces' arrays).
  std::vector<const RobotModel*> robot_models;
  std::vector<std::vector<std::unique_ptr<RobotPiece>>> robot_pieces;
  MergedStatic merged_static;  // its bvh is null when not worth it (MergeStatic)

  ~Impl() {
    for (MeshObject& object : objects) world.removeCollisionObject(object.object.get());
  }

  // Creates the objects of one body over `meshes` (split to Bullet's limits),
  // placed at X_BO in the body's frame; returns their indices in `objects`.
  // Their surface id is `surface`.
  std::vector<int> AddBody(int body, std::int32_t surface, const std::vector<MeshArrays>& meshes,
                           int group,
                           const Eigen::Isometry3d& X_BO = Eigen::Isometry3d::Identity()) {
    std::vector<int> added;
    for (MeshObject& object : MakeObjects(body, meshes, X_BO)) {
      object.surface = surface;
      object.object->setUserIndex2(surface);
      added.push_back(Add(std::move(object), group));
    }
    return added;
  }

  // Adds an object made by MakeObjects; returns its index in `objects`.
  int Add(MeshObject object, int group) {
    world.addCollisionObject(object.object.get(), group, static_cast<int>(kAllGroups));
    num_parts += object.mesh_interface->getNumSubParts();
    const int body = object.object->getUserIndex();
    objects_of_body[static_cast<std::size_t>(body)].push_back(static_cast<int>(objects.size()));
    objects.push_back(std::move(object));
    return static_cast<int>(objects.size()) - 1;
  }

  // Removes the objects of terrain tile `tile` (MeshObject::tile); false when none.
  bool RemoveTile(std::uint64_t tile) {
    bool removed = false;
    for (std::size_t i = objects.size(); i-- > 0;) {
      if (objects[i].tile != tile) continue;
      world.removeCollisionObject(objects[i].object.get());
      num_parts -= objects[i].mesh_interface->getNumSubParts();
      objects.erase(objects.begin() + std::ptrdiff_t(i));
      removed = true;
    }
    if (!removed) return false;
    for (std::vector<int>& list : objects_of_body) list.clear();
    for (std::size_t i = 0; i < objects.size(); ++i) {
      objects_of_body[static_cast<std::size_t>(objects[i].object->getUserIndex())].push_back(
          static_cast<int>(i));
    }
    return true;
  }

  // The objects over `meshes` (split to Bullet's limits), their BVHs built, not
  // yet in the world: any thread may make them.
  static std::vector<MeshObject> MakeObjects(int body, const std::vector<MeshArrays>& meshes,
                                             const Eigen::Isometry3d& X_BO) {
    std::vector<MeshObject> made;
    std::vector<btIndexedMesh> parts;
    std::vector<float> reflectivity;  // by part
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
        reflectivity.push_back(mesh.reflectivity);
      }
    }
    for (std::size_t first = 0; first < parts.size(); first += kMaxPartsPerShape) {
      MeshObject object;
      object.mesh_interface = std::make_unique<btTriangleIndexVertexArray>();
      const std::size_t end = std::min(parts.size(), first + kMaxPartsPerShape);
      std::vector<TriangleSoup> soups;
      object.reflectivity_of_part.assign(reflectivity.begin() + std::ptrdiff_t(first),
                                         reflectivity.begin() + std::ptrdiff_t(end));
      for (std::size_t p = first; p < end; ++p) {
        object.mesh_interface->addIndexedMesh(parts[p]);
        soups.push_back({reinterpret_cast<const Eigen::Vector3f*>(parts[p].m_vertexBase),
                         std::size_t(parts[p].m_numVertices),
                         reinterpret_cast<const std::uint32_t*>(parts[p].m_triangleIndexBase),
                         std::size_t(parts[p].m_numTriangles)});
      }
      // The ray caster's hierarchy, built beside Bullet's when large enough to
      // be worth a thread (both only read the arrays).
      std::size_t triangles = 0;
      for (const TriangleSoup& soup : soups) triangles += soup.num_triangles;
      auto build = [&object, &soups] {
        object.bvh = std::make_shared<const TriangleBvh>(BuildTriangleBvh(soups));
      };
      std::thread builder;
      if (triangles >= 20000) {
        builder = std::thread(build);
      } else {
        build();
      }
      object.shape = std::make_unique<btBvhTriangleMeshShape>(object.mesh_interface.get(), true);
      if (builder.joinable()) builder.join();
      object.object = std::make_unique<btCollisionObject>();
      object.object->setCollisionShape(object.shape.get());
      object.object->setUserIndex(body);
      object.X_BO = X_BO;
      made.push_back(std::move(object));
    }
    return made;
  }

  // Builds merged_static over the static actors' objects placed at p_WO when
  // there are two or more and at most kMaxMergedTriangles triangles in all.
  void MergeStatic(const Eigen::Vector3d& p_WO);
  static constexpr std::size_t kMaxMergedTriangles = std::size_t{1} << 20;

  void Place(int body, const Eigen::Vector3d& p_WO) {
    const Eigen::Isometry3d& X_WB = X_W[static_cast<std::size_t>(body)];
    for (int index : objects_of_body[static_cast<std::size_t>(body)]) {
      MeshObject& object = objects[static_cast<std::size_t>(index)];
      object.object->setWorldTransform(ToBulletTransform(X_WB * object.X_BO, p_WO));
      world.updateSingleAabb(object.object.get());
    }
  }
};

}  // namespace sandbox::scene
