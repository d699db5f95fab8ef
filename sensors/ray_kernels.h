#pragma once
// The ray caster's kernels: the code that tests rays against triangles, once
// per instruction set. Internal to the caster (ray_caster.cc calls them).
//
// Each packet kernel is a source file built once per instruction set by
// CMake's sandbox_isa_kernel, in a namespace named after the set:
//   packet_walk4.cc   four rays a packet: sse2 (any x86-64; fused
//                     multiply-adds emulated where rounding could turn a
//                     decision) and fma (fused throughout, as Embree's);
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

// [a[i0], a[i1], b[i2], b[i3]].
template <int i0, int i1, int i2, int i3>
static inline __m128 Pick(__m128 a, __m128 b) {
  return _mm_shuffle_ps(a, b, _MM_SHUFFLE(i3, i2, i1, i0));
}

// The hits' normals of a band, unit and facing rays along `d`, in place; zero
// where nothing was hit. Four at a time: three loads turned into x, y and z
// by shuffles (and back for the stores), the reciprocal square root's
// estimate and one Newton step (within 2 ulps of 1 / sqrt), a product each.
static inline void FacingUnits(const std::int32_t* surface, std::size_t count,
                               const Eigen::Vector3f& d, Eigen::Vector3f* normal) {
  static_assert(sizeof(Eigen::Vector3f) == 3 * sizeof(float), "packed normals");
  const __m128 dx = _mm_set1_ps(d.x()), dy = _mm_set1_ps(d.y()), dz = _mm_set1_ps(d.z());
  const __m128 half = _mm_set1_ps(0.5f), three = _mm_set1_ps(3.0f);
  const __m128 sign = _mm_set1_ps(-0.0f), zero = _mm_setzero_ps();
  std::size_t i = 0;
  for (; i + 4 <= count; i += 4) {
    float* p = normal[i].data();
    // a = x0 y0 z0 x1, b = y1 z1 x2 y2, c = z2 x3 y3 z3
    const __m128 a = _mm_loadu_ps(p), b = _mm_loadu_ps(p + 4), c = _mm_loadu_ps(p + 8);
    const __m128 x = Pick<0, 3, 0, 2>(a, Pick<2, 2, 1, 1>(b, c));
    const __m128 y = Pick<0, 2, 0, 2>(Pick<1, 1, 0, 0>(a, b), Pick<3, 3, 2, 2>(b, c));
    const __m128 z = Pick<0, 2, 0, 3>(Pick<2, 2, 1, 1>(a, b), c);
    const __m128 n2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, x), _mm_mul_ps(y, y)), _mm_mul_ps(z, z));
    const __m128 r0 = _mm_rsqrt_ps(n2);
    // r = r0 (3 - n2 r0^2) / 2
    __m128 scale =
        _mm_mul_ps(_mm_mul_ps(half, r0), _mm_sub_ps(three, _mm_mul_ps(n2, _mm_mul_ps(r0, r0))));
    const __m128 along =
        _mm_add_ps(_mm_add_ps(_mm_mul_ps(x, dx), _mm_mul_ps(y, dy)), _mm_mul_ps(z, dz));
    scale = _mm_xor_ps(scale, _mm_and_ps(_mm_cmpgt_ps(along, zero), sign));
    const __m128i hit = _mm_xor_si128(
        _mm_cmpeq_epi32(_mm_loadu_si128(reinterpret_cast<const __m128i*>(surface + i)),
                        _mm_set1_epi32(RayHits::kNoHit)),
        _mm_set1_epi32(-1));
    const __m128 keep = _mm_castsi128_ps(hit);  // whatever a lane without a hit holds
    const __m128 ux = _mm_and_ps(_mm_mul_ps(x, scale), keep);
    const __m128 uy = _mm_and_ps(_mm_mul_ps(y, scale), keep);
    const __m128 uz = _mm_and_ps(_mm_mul_ps(z, scale), keep);
    _mm_storeu_ps(p, Pick<0, 2, 0, 2>(Pick<0, 0, 0, 0>(ux, uy), Pick<0, 0, 1, 1>(uz, ux)));
    _mm_storeu_ps(p + 4, Pick<0, 2, 0, 2>(Pick<1, 1, 1, 1>(uy, uz), Pick<2, 2, 2, 2>(ux, uy)));
    _mm_storeu_ps(p + 8, Pick<0, 2, 0, 2>(Pick<2, 2, 3, 3>(uz, ux), Pick<3, 3, 3, 3>(uy, uz)));
  }
  for (; i < count; ++i) {
    normal[i] = surface[i] == RayHits::kNoHit ? Eigen::Vector3f::Zero() : FacingUnit(normal[i], d);
  }
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
  Eigen::Vector3f* normal{nullptr};       // of RayHits::normal_W, unnormalised; null: none
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
namespace avx512 {
extern const RayKernel kKernel;
}

}  // namespace sandbox::sensors
