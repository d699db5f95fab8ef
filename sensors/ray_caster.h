#pragma once
// Batched ray casting over the Bullet world, split over worker threads.
// Thread-safe by construction: every ray walks each object's own hierarchy
// (scene::TriangleBvh, one over all static actors where the scene merged them:
// scene::MergedStatic) read-only, with its own stack; nothing of Bullet's
// mutable query state (btCollisionWorld::rayTest) is used. The kernels that
// test rays against triangles are built per instruction set (ray_kernels.h).
//
// Hits are watertight (docs/reference/sensors.md, "Grazing and origin rules"): each
// triangle is tested in the Bullet frame with its corners placed as Bullet
// places them; a ray through a shared edge hits one of the two triangles, a
// ray lying in a triangle's plane does not hit it, and a ray whose origin lies
// on a triangle hits it at distance 0.

#include <Eigen/Core>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <thread>
#include <vector>

#include "scene/collision_world.h"
#include "sensors/worker_pool.h"

namespace sandbox::sensors {

// Rays relative to a batch origin in the world frame: ray i starts at
// origin_W + start[i] and runs along the unit direction[i] for length_m[i].
// Float offsets from a double origin keep precision far from the world origin.
struct RayBatch {
  Eigen::Vector3d origin_W{Eigen::Vector3d::Zero()};
  std::vector<Eigen::Vector3f> start;
  std::vector<Eigen::Vector3f> direction;  // unit
  std::vector<float> length_m;

  std::size_t size() const { return start.size(); }
  void Resize(std::size_t n);
};

// A block of a batch whose rays run parallel and start on a regular grid (a
// face scan's face): ray (r, c), r < rows, c < cols, is the batch's ray
// first + r * cols + c; it starts at the batch's origin plus its start, which
// is corner_W + c * step_u_W + r * step_v_W (to float rounding), and runs
// along the block's one direction for its one length (the block's own: the
// structured kernel does not read the batch's direction and length of these
// rays, so a caller may leave them unset). The steps are perpendicular to the
// direction.
struct RayGrid {
  std::size_t first{0};
  int rows{0}, cols{0};
  Eigen::Vector3d corner_W{Eigen::Vector3d::Zero()};
  Eigen::Vector3d step_u_W{Eigen::Vector3d::UnitX()}, step_v_W{Eigen::Vector3d::UnitY()};
  Eigen::Vector3f direction{Eigen::Vector3f::UnitZ()};  // unit
  float length_m{1.0f};
  // Where CastGrids() writes this block's results, rows * cols entries each
  // (ray (r, c) at r * cols + c; `normal_W` read only with normals asked
  // for), instead of into its RayHits, whose entries for the block are then
  // left as they were (and the RayHits not even sized when every block has
  // its own): a caller that keeps results elsewhere (the face scanner's
  // faces) saves a copy. All null: into the RayHits.
  struct Into {
    float* distance_m{nullptr};
    std::int32_t* surface{nullptr};
    Eigen::Vector3f* normal_W{nullptr};
  } into;
};

// What rays may see.
struct RayFilter {
  std::uint32_t group_mask{scene::kAllGroups};
  int ignore_actor{-1};
  int ignore_robot{-1};  // a robot's own sensors set this to the robot
};

// One entry per ray: its distance and the surface id of what it hit
// (scene/surface_ids.h: the world's SurfaceTable() names it). A ray that hits
// nothing has distance_m = length_m and surface = 0 (kNoHit). A ray that meets
// two surfaces at one distance reports the lower id, in every kernel.
struct RayHits {
  static constexpr std::int32_t kNoHit = scene::SurfaceIds::kNothing;
  std::vector<float> distance_m;
  std::vector<Eigen::Vector3f> normal_W;  // unit, facing the ray; zero without a hit
  std::vector<std::int32_t> surface;
  // With with_reflectivity (Cast() only): what a lidar sees of the hit
  // triangle's mesh (scene::MeshReflectivity), 0 to 1; 0 without a hit.
  std::vector<float> reflectivity;
  bool with_reflectivity{false};
  // False: normal_W is left as it was, not read (a caller that needs no
  // normals saves a square root and a division a hit, and 12 bytes a ray).
  bool with_normals{true};

  std::size_t size() const { return surface.size(); }
};

// What one block of a CastGrids() call took, its rows and seconds.
struct BlockCost {
  int rows{0};
  double seconds{0.0};
};

class RayCaster {
 public:
  // Starts `threads` - 1 worker threads (0: one per core); the calling thread
  // is the last worker.
  explicit RayCaster(int threads = 0);
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  // Casts every ray of `rays`. The world must not change during the call.
  // Call from one thread at a time (the loop thread).
  void Cast(const scene::CollisionWorld& world, const RayBatch& rays, const RayFilter& filter,
            RayHits* hits);

  // Cast() for a batch made of grids (every ray in exactly one block), by the
  // structured kernel: per band of rows, the triangles inside the band's box
  // are found once and each is tested against exactly the rays its shadow on
  // the grid covers, with Cast()'s own per-ray test. Same hits as Cast():
  // the same rays hit, at the same distances (Cast()'s arithmetic; see
  // docs/reference/sensors.md for the one difference a tie can make) when the batch's
  // rays run along their block's direction for its length. Throws
  // std::invalid_argument when the blocks do not cover the batch in order,
  // a block's direction is not unit or its length not positive, a block's
  // `into` lacks the distances, surfaces or (with normals) normals, or hits
  // ask for reflectivity.
  void CastGrids(const scene::CollisionWorld& world, const RayBatch& rays,
                 const std::vector<RayGrid>& grids, const RayFilter& filter, RayHits* hits);

  int threads() const { return pool_.threads(); }
  // Entries a BVH walk keeps on its own stack before it grows on the heap
  // (a deeper tree costs an allocation per walk, never a dropped node).
  static constexpr int kStackInPlace = 32;
  // The packet kernel in use: "avx512" (sixteen rays a packet in Cast(),
  // sixteen triangle-ray pairs a test in CastGrids(); the FMA kernel's
  // arithmetic), "avx2" (eight rays and pairs, the same arithmetic, on
  // CPUs with AVX2 but not AVX-512), "fma" (the CPU's fused multiply-add
  // unit, four rays) or "sse2" (fused operations emulated where they
  // decide). The widest the CPU runs, unless SANDBOX_RAY_KERNEL names
  // another. All give the same hits.
  static const char* kernel();
  // Rays cast since construction (frame statistics).
  std::int64_t rays_cast() const { return rays_cast_; }

  // Runs job(k) for k = 0 .. count-1 over this caster's threads (the
  // caller's too); returns when all are done. A job must not use this caster
  // (the loop runs whole sensors so, each on a one-thread caster of its own).
  void RunParallel(int count, const std::function<void(int)>& job);

 private:
  WorkerPool pool_;
  std::int64_t rays_cast_{0};
  // The world's objects as the kernels read them, kept for one state of one
  // world (scene::CollisionWorld::instance() and revision()).
  struct Targets;
  std::unique_ptr<Targets> targets_;
  const Targets& TargetsOf(const scene::CollisionWorld& world);
  // What each block of the last CastGrids() call took: the next call over
  // the same blocks splits and orders its bands by it.
  std::vector<BlockCost> grid_costs_;
};

}  // namespace sandbox::sensors
