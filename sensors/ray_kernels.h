#pragma once
// The ray caster's kernels: the code that tests rays against triangles, once
// per instruction set. Internal to the caster (ray_caster.cc calls them).
//
// Each packet kernel is a source file built once per instruction set by
// CMake's sandbox_isa_kernel, in a namespace named after the set:
//   packet_walk4.cc   four rays a packet: sse2 (any x86-64; fused
//                     multiply-adds emulated where rounding could turn a
//                     decision) and fma (fused throughout, as Embree's);
//   packet_walk8.cc   eight rays a packet: avx2 (fused, as fma);
//   packet_walk16.cc  sixteen rays a packet: avx512 (fused, as fma).
// All give the same hits (docs/reference/sensors.md). RayCaster::kernel()
// names the one in use; SANDBOX_RAY_KERNEL picks another.

#include <immintrin.h>

#include <Eigen/Core>
#include <cmath>
#include <cstdint>
#include <vector>

#include "sensors/ray_caster.h"
#include "sensors/ray_targets.h"

// A kernel's per-triangle steps, inlined into its walk whatever the
// compiler's count of their callers (an out-of-line call passes the lanes
// through memory).
#define SANDBOX_KERNEL_INLINE inline __attribute__((always_inline))

namespace sandbox::sensors {

// Whether the ray, up to t, meets the triangle's own bounding box (with two
// ulps of slack on the distances). A hit the edge test admits within its
// rounding tolerance but that lies outside the triangle's box is no hit: a ray
// passing a hair outside an outer edge misses, as a watertight caster's box
// test has it. A direction component of exactly 0 counts as an
// infinitesimally positive one (Embree's convention): a ray running along the
// box's upper bound on that axis leaves the box at once, along its lower bound
// stays in it; of two surfaces that abut there without sharing an edge, the
// ray meets exactly one.
constexpr float kHuge = 1e30f;

// The unit normal along `normal` facing a ray along `direction` (one square
// root and one division).
static inline Eigen::Vector3f FacingUnit(const Eigen::Vector3f& normal,
                                         const Eigen::Vector3f& direction) {
  const float scale = 1.0f / std::sqrt(normal.squaredNorm());
  return normal * (normal.dot(direction) > 0.0f ? -scale : scale);
}

// Ray r's result: its distance, the surface hit and, when asked for, its
// reflectivity and the unit normal facing the ray (zero without a hit).
static inline void WriteHit(std::size_t r, float t, int surface, float reflectivity,
                            const Eigen::Vector3f& normal, const Eigen::Vector3f& direction,
                            RayHits* hits) {
  hits->distance_m[r] = t;
  hits->surface[r] = surface;
  if (hits->with_reflectivity) {
    hits->reflectivity[r] = surface == RayHits::kNoHit ? 0.f : reflectivity;
  }
  if (!hits->with_normals) return;
  if (surface == RayHits::kNoHit) {
    hits->normal_W[r].setZero();
    return;
  }
  hits->normal_W[r] = FacingUnit(normal, direction);
}

// The rays of a band of rows of one grid block (RayGrid), as the structured
// kernel reads them: origins in the Bullet frame and results, indexed by cell
// (a band's ray from its first).
struct GridBand {
  __m128 dx, dy, dz;                      // the block's direction
  __m128 ox, oy, oz;                      // the batch origin (a ray starts at it plus its start)
  const Eigen::Vector3f* start{nullptr};  // the cells' rays' starts
  float* t_max{nullptr};                  // their entries of RayHits::distance_m
  std::int32_t* surface{nullptr};         // of RayHits::surface
  Eigen::Vector3f* normal{nullptr};       // of RayHits::normal_W (unit, facing); null: none
  // Triangle-ray pairs waiting for a test (HitPairs), in lanes' order.
  struct Pairs {
    static constexpr int kCapacity = 64;
    int count{0};
    alignas(16) float corner[9][kCapacity];  // x, y, z of corner 0, 1, 2
    alignas(16) float near[kCapacity];
    int cell[kCapacity], surface[kCapacity];
  } pairs;

  // Queues the triangle with these corners against ray `cell`; tests the
  // queue when full (test: HitPairs of the kernel in use).
  template <typename Test>
  void Add(const Eigen::Vector3f corner[3], int surface_id, int cell_index, float near_depth,
           Test test) {
    const int k = pairs.count++;
    for (int j = 0; j < 3; ++j) {
      for (int a = 0; a < 3; ++a) pairs.corner[3 * j + a][k] = corner[j][a];
    }
    pairs.near[k] = near_depth;
    pairs.cell[k] = cell_index;
    pairs.surface[k] = surface_id;
    if (pairs.count == Pairs::kCapacity) test(this);
  }
};

// Calls walk(target) for each of `targets` whose box the packet meets
// (meets(min, max): a mask of the lanes that enter the box, 0 for none). A
// run of one body's objects (a robot's pieces) is skipped whole when the
// packet misses the box around them. (Internal linkage: each kernel's copy
// is built for its set.)
template <typename Meets, typename Walk>
static inline void WalkTargetsMet(const Target* const* targets, std::size_t num_targets,
                                  Meets&& meets, Walk&& walk) {
  for (std::size_t t = 0; t < num_targets;) {
    std::size_t run_end = t + 1;
    while (run_end < num_targets && targets[run_end]->body == targets[t]->body) ++run_end;
    if (run_end - t > 2 && meets(targets[t]->body_min, targets[t]->body_max) == 0) {
      t = run_end;
      continue;
    }
    for (; t < run_end; ++t) {
      if (meets(targets[t]->aabb_min, targets[t]->aabb_max) != 0) walk(*targets[t]);
    }
  }
}

// One build of a packet kernel: its name and its two entry points.
struct RayKernel {
  const char* name;
  // Cast()'s rays [first, end) of `rays` (ray r starts at origin_B +
  // start[r], Bullet frame) against `targets` (a body's objects next to each
  // other), into `hits`.
  void (*cast_rays)(const RayBatch& rays, const Eigen::Vector3f& origin_B, std::size_t first,
                    std::size_t end, const Target* const* targets, std::size_t num_targets,
                    RayHits* hits);
  // The pairs queued in a grid band (GridBand::Pairs: a triangle and a ray
  // each), tested, a pair a lane; then none are left.
  void (*hit_pairs)(GridBand* band);
};

// Each build's, defined in its namespace by the source built for it.
namespace sse2 {
extern const RayKernel kKernel;
}
namespace fma {
extern const RayKernel kKernel;
}
namespace avx2 {
extern const RayKernel kKernel;
}
namespace avx512 {
extern const RayKernel kKernel;
}

}  // namespace sandbox::sensors
