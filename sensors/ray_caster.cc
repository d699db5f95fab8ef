// Over 600 lines: the caster and its packet walks are one unit until issue 38 splits
// them into per-instruction-set kernels.
#include "sensors/ray_caster.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <stdexcept>
#include <string>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include "scene/collision_world_internal.h"
#include "sensors/walk_stack.h"

namespace sandbox::sensors {
namespace {

constexpr int kRaysPerChunk = 256;
constexpr int kStackInPlace = RayCaster::kStackInPlace;

// One Bullet object as a ray sees it: where it is, its BVH nodes and triangles.
struct Target {
  int body{-1};
  std::uint32_t group{0};  // the object's collision group (scene::kWorldStatic, ...)
  // The box around this object and the other objects of its body next to it
  // in the list (a robot's pieces): a packet that misses it skips them all.
  Eigen::Vector3f body_min{Eigen::Vector3f::Zero()}, body_max{Eigen::Vector3f::Zero()};
  Eigen::Vector3f aabb_min, aabb_max;  // in the Bullet frame (world minus origin)
  Eigen::Matrix3f R_LB;                // local from Bullet frame
  Eigen::Vector3f p_LB;
  btTransform X_BL;      // Bullet frame from local: where triangles are tested
  bool identity{false};  // X_BL is exactly the identity
  const btQuantizedBvhNode* nodes{nullptr};
  Eigen::Vector3f bvh_min, quantization;  // quantized = (local - bvh_min) * quantization
  // The object's own hierarchy (local frame), and how far its boxes are grown
  // for the rounding of rays taken into that frame.
  const scene::TriangleBvh* bvh{nullptr};
  float box_margin{0.f};
  // The merged static objects' target (scene::MergedStatic) has a body per
  // leaf part (BodyOf); any other, its one body.
  const std::int32_t* body_of_part{nullptr};
  int BodyOf(int part) const { return body_of_part != nullptr ? body_of_part[part] : body; }
  struct Part {
    const unsigned char* vertices;
    int vertex_stride;
    const unsigned char* indices;
    int index_stride;
  };
  std::vector<Part> parts;
};

Eigen::Vector3f ToEigen(const btVector3& v) { return {float(v.x()), float(v.y()), float(v.z())}; }

// The margin of a target's boxes: a few thousand ulps of the coordinates
// involved (the boxes' and the placement's).
float BoxMargin(const scene::TriangleBvh& bvh, const Eigen::Vector3f& p_LB,
                const Eigen::Vector3f& p_BL) {
  const float scale = std::max({bvh.lower.cwiseAbs().maxCoeff(), bvh.upper.cwiseAbs().maxCoeff(),
                                p_LB.cwiseAbs().maxCoeff(), p_BL.cwiseAbs().maxCoeff()});
  return 1e-5f * scale + 1e-6f;
}

// The target of the world's merged static objects, placed for the world's
// origin now (its corners are where Bullet placed them at the origin it was
// built at: a whole-metre shift moves them as a translation).
Target MergedTarget(const scene::CollisionWorld& world) {
  const scene::MergedStatic& merged = world.internals().merged_static;
  Target t;
  t.body = -2;  // none: each lane's is BodyOf its part
  t.group = scene::kWorldStatic;
  t.bvh = merged.bvh.get();
  t.body_of_part = merged.body_of_part.data();
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

// Every object of the world, in the world's order (a body's objects next to
// each other), with the boxes around each run of one body's objects.
std::vector<Target> CollectTargets(const scene::CollisionWorld& world) {
  const scene::CollisionWorld::Impl& w = world.internals();
  std::vector<Target> targets;
  for (const scene::MeshObject& object : w.objects) {
    const btCollisionObject& o = *object.object;
    Target t;
    t.body = o.getUserIndex();
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
    btQuantizedBvh* bvh = object.shape->getOptimizedBvh();
    t.nodes = &bvh->getQuantizedNodeArray()[0];
    // Quantization from the two ends of the range: one quantum apart would
    // lose the scale to float rounding.
    const unsigned short zero[3] = {0, 0, 0}, top[3] = {65534, 65534, 65534};
    t.bvh_min = ToEigen(bvh->unQuantize(zero));
    t.quantization = 65534.0f * (ToEigen(bvh->unQuantize(top)) - t.bvh_min).cwiseInverse();
    t.bvh = object.bvh.get();
    if (t.bvh == nullptr) throw std::logic_error("RayCaster: an object without its hierarchy");
    t.box_margin = BoxMargin(*t.bvh, t.p_LB, ToEigen(X.getOrigin()));
    const IndexedMeshArray& meshes = object.mesh_interface->getIndexedMeshArray();
    for (int m = 0; m < meshes.size(); ++m) {
      t.parts.push_back({meshes[m].m_vertexBase, meshes[m].m_vertexStride,
                         meshes[m].m_triangleIndexBase, meshes[m].m_triangleIndexStride});
    }
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

// Entry distance of a ray into a quantized box (grown by one quantum against
// rounding), or +inf when it misses or enters beyond t_max.
inline float EnterBox(const btQuantizedBvhNode& node, const Eigen::Vector3f& qo,
                      const Eigen::Vector3f& inverse, float t_max) {
  float t_enter = 0.0f, t_exit = t_max;
  for (int k = 0; k < 3; ++k) {
    const float t1 = (float(node.m_quantizedAabbMin[k]) - 1.0f - qo[k]) * inverse[k];
    const float t2 = (float(node.m_quantizedAabbMax[k]) + 1.0f - qo[k]) * inverse[k];
    t_enter = std::max(t_enter, std::min(t1, t2));
    t_exit = std::min(t_exit, std::max(t1, t2));
  }
  return t_enter <= t_exit ? t_enter : std::numeric_limits<float>::infinity();
}

// A triangle's corners in the Bullet frame, transformed as Bullet transforms
// points (so that any caster fed Bullet's world triangles sees the same ones).
inline void Corners(const Target& target, int part_id, int triangle, Eigen::Vector3f corner[3]) {
  const Target::Part& part = target.parts[static_cast<std::size_t>(part_id)];
  const auto* index = reinterpret_cast<const std::uint32_t*>(
      part.indices + std::ptrdiff_t(triangle) * part.index_stride);
  for (int k = 0; k < 3; ++k) {
    const auto* p = reinterpret_cast<const float*>(part.vertices +
                                                   std::ptrdiff_t(index[k]) * part.vertex_stride);
    if (target.identity) {
      corner[k] = Eigen::Vector3f(p[0], p[1], p[2]);
    } else {
      corner[k] = ToEigen(target.X_BL * btVector3(p[0], p[1], p[2]));
    }
  }
}

// The triangle normal from its edges (e0 + e1 + e2 = 0), each component
// from whichever of e0 x e1 and e1 x e2 suffers less cancellation.
inline Eigen::Vector3f StableNormal(const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                                    const Eigen::Vector3f& c) {
  const float ab_x = a.z() * b.y(), ab_y = a.x() * b.z(), ab_z = a.y() * b.x();
  const float bc_x = b.z() * c.y(), bc_y = b.x() * c.z(), bc_z = b.y() * c.x();
  return {std::abs(ab_x) < std::abs(bc_x) ? a.y() * b.z() - ab_x : b.y() * c.z() - bc_x,
          std::abs(ab_y) < std::abs(bc_y) ? a.z() * b.x() - ab_y : b.z() * c.x() - bc_y,
          std::abs(ab_z) < std::abs(bc_z) ? a.x() * b.y() - ab_z : b.x() * c.y() - bc_z};
}

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

inline bool MeetsCornerBox(const Eigen::Vector3f corner[3], const Eigen::Vector3f& o,
                           const Eigen::Vector3f& d, float t) {
  float t_enter = 0.0f, t_exit = t;
  for (int k = 0; k < 3; ++k) {
    const float lo = std::min({corner[0][k], corner[1][k], corner[2][k]});
    const float hi = std::max({corner[0][k], corner[1][k], corner[2][k]});
    // A zero component counts as an infinitesimally positive one.
    const float inverse = d[k] == 0.0f ? kHuge : 1.0f / d[k];
    const float t1 = (lo - o[k]) * inverse, t2 = (hi - o[k]) * inverse;
    t_enter = std::max(t_enter, std::min(t1, t2));
    t_exit = std::min(t_exit, std::max(t1, t2));
  }
  constexpr float kSlack = 2.0f * std::numeric_limits<float>::epsilon();
  return t_enter * (1.0f - kSlack) <= t_exit * (1.0f + kSlack);
}

// The watertight ray-triangle test (docs/reference/sensors.md, "Grazing and origin
// rules"): corners relative to the ray origin, a signed edge function per edge
// (the same value, negated, for the neighbour sharing the edge), both faces.
// A ray parallel to the plane (in it or not) misses; one whose origin lies on
// the triangle hits at 0. Updates t_max and the normal on a closer hit.
inline bool HitTriangle(const Target& target, int part_id, int triangle, const Eigen::Vector3f& o,
                        const Eigen::Vector3f& d, float* t_max, Eigen::Vector3f* normal) {
  Eigen::Vector3f corner[3];
  Corners(target, part_id, triangle, corner);
  const Eigen::Vector3f v0 = corner[0] - o, v1 = corner[1] - o, v2 = corner[2] - o;
  const Eigen::Vector3f e0 = v2 - v0, e1 = v0 - v1, e2 = v1 - v2;
  const float u = e0.cross(v2 + v0).dot(d);
  const float v = e1.cross(v0 + v1).dot(d);
  const float w = e2.cross(v1 + v2).dot(d);
  const float eps = std::numeric_limits<float>::epsilon() * std::abs(u + v + w);
  const bool inside = std::min({u, v, w}) >= -eps || std::max({u, v, w}) <= eps;
  if (!inside) return false;
  const Eigen::Vector3f n = StableNormal(e0, e1, e2);
  const float den = 2.0f * n.dot(d);
  if (den == 0.0f) return false;
  const float t = 2.0f * v0.dot(n) / den;
  if (!(t >= 0.0f && t < *t_max)) return false;
  if (!MeetsCornerBox(corner, o, d, t)) return false;
  *t_max = t;
  *normal = n;
  return true;
}

// Nearest-first walk of one object's quantized BVH, shortening the ray at
// every hit. Returns true when the object holds a hit closer than *t_max.
bool WalkTarget(const Target& target, const Eigen::Vector3f& o_B, const Eigen::Vector3f& d_B,
                float* t_max, Eigen::Vector3f* normal_B) {
  const Eigen::Vector3f o = target.R_LB * o_B + target.p_LB;
  const Eigen::Vector3f d = target.R_LB * d_B;
  const Eigen::Vector3f qo = (o - target.bvh_min).cwiseProduct(target.quantization);
  Eigen::Vector3f inverse;
  for (int k = 0; k < 3; ++k) {
    const float qd = d[k] * target.quantization[k];
    inverse[k] = 1.0f / (std::abs(qd) > 1e-30f ? qd : std::copysign(1e-30f, qd));
  }
  struct Entry {
    int node;
    float t_enter;
  };
  WalkStack<Entry, kStackInPlace> stack;
  bool hit = false;
  const btQuantizedBvhNode* nodes = target.nodes;
  if (EnterBox(nodes[0], qo, inverse, *t_max) <= *t_max) stack.Push({0, 0.0f});
  while (!stack.empty()) {
    const Entry entry = stack.Pop();
    if (entry.t_enter > *t_max) continue;
    const btQuantizedBvhNode& node = nodes[entry.node];
    if (node.isLeafNode()) {
      const int packed = node.m_escapeIndexOrTriangleIndex;
      hit |= HitTriangle(target, packed >> 21, packed & ((1 << 21) - 1), o_B, d_B, t_max, normal_B);
      continue;
    }
    const int left = entry.node + 1;
    const int right = left + (nodes[left].isLeafNode() ? 1 : nodes[left].getEscapeIndex());
    const float t_left = EnterBox(nodes[left], qo, inverse, *t_max);
    const float t_right = EnterBox(nodes[right], qo, inverse, *t_max);
    // Push the far child first so that the near one is walked first.
    const bool left_first = t_left <= t_right;
    const Entry near_child = left_first ? Entry{left, t_left} : Entry{right, t_right};
    const Entry far_child = left_first ? Entry{right, t_right} : Entry{left, t_left};
    if (std::isfinite(far_child.t_enter)) stack.Push(far_child);
    if (std::isfinite(near_child.t_enter)) stack.Push(near_child);
  }
  return hit;
}

// Sizes `hits` for n rays (normals only when asked for).
void SizeHits(std::size_t n, RayHits* hits) {
  hits->distance_m.resize(n);
  hits->normal_W.resize(hits->with_normals ? n : 0);
  hits->body.resize(n);
}

// Whether a filter lets rays see an object.
struct Visible {
  const RayFilter& filter;
  int num_actors;
  bool operator()(const Target& t) const {
    return (t.group & filter.group_mask) != 0 &&
           !(filter.ignore_actor >= 0 && t.body == filter.ignore_actor) &&
           !(filter.ignore_robot >= 0 && t.body == num_actors + filter.ignore_robot);
  }
};

// Ray r's result: its distance, the body hit and, when asked for, the unit
// normal facing the ray (zero without a hit).
inline void WriteHit(std::size_t r, float t, int body, const Eigen::Vector3f& normal,
                     const Eigen::Vector3f& direction, RayHits* hits) {
  hits->distance_m[r] = t;
  hits->body[r] = body;
  if (!hits->with_normals) return;
  if (body == RayHits::kNoHit) {
    hits->normal_W[r].setZero();
    return;
  }
  const Eigen::Vector3f unit = normal.normalized();
  hits->normal_W[r] = unit.dot(direction) > 0.0f ? -unit : unit;
}

// Whether the ray enters an axis-aligned box before t_max.
inline bool RayMeetsBox(const Eigen::Vector3f& o, const Eigen::Vector3f& inverse_d,
                        const Eigen::Vector3f& lo, const Eigen::Vector3f& hi, float t_max) {
  float t_enter = 0.0f, t_exit = t_max;
  for (int k = 0; k < 3; ++k) {
    const float t1 = (lo[k] - o[k]) * inverse_d[k], t2 = (hi[k] - o[k]) * inverse_d[k];
    t_enter = std::max(t_enter, std::min(t1, t2));
    t_exit = std::min(t_exit, std::max(t1, t2));
  }
  return t_enter <= t_exit;
}

#if defined(__SSE2__)
// Four rays walked together (SSE2): a node is visited when any of them
// enters it, and every test is done for the four at once. Rays of a sensor
// are coherent (neighbouring beams or grid points), so the four mostly agree.
struct Packet {
  __m128 ox, oy, oz, dx, dy, dz;  // Bullet frame
  __m128 t_max;                   // per lane
  __m128 active;                  // all bits set in lanes that hold a ray
  int body[4];
  Eigen::Vector3f normal[4];  // in the Bullet frame, unnormalised
};

inline __m128 AwayFromZero(__m128 x) {
  const __m128 sign = _mm_and_ps(x, _mm_set1_ps(-0.0f));
  const __m128 magnitude = _mm_max_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), x), _mm_set1_ps(1e-30f));
  return _mm_or_ps(magnitude, sign);
}

inline __m128 Mul(__m128 a, __m128 b) { return _mm_mul_ps(a, b); }
inline __m128 Add(__m128 a, __m128 b) { return _mm_add_ps(a, b); }
inline __m128 Sub(__m128 a, __m128 b) { return _mm_sub_ps(a, b); }

struct Vec4 {  // a vector per lane
  __m128 x, y, z;
};
inline Vec4 Sub(const Vec4& a, const Vec4& b) {
  return {Sub(a.x, b.x), Sub(a.y, b.y), Sub(a.z, b.z)};
}
inline Vec4 Add(const Vec4& a, const Vec4& b) {
  return {Add(a.x, b.x), Add(a.y, b.y), Add(a.z, b.z)};
}
inline __m128 Abs(__m128 x) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), x); }
inline __m128 L1(const Vec4& a) { return Add(Add(Abs(a.x), Abs(a.y)), Abs(a.z)); }
// The lanes whose bits are set in `bits` (a movemask), all bits set.
inline __m128 LaneMask(int bits) {
  const __m128i bit = _mm_setr_epi32(1, 2, 4, 8);
  return _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(bits), bit), bit));
}
inline __m128 Select(__m128 mask, __m128 a, __m128 b) {
  return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
// MeetsCornerBox, per lane, for the boxes [low, high] around each lane's corners.
inline __m128 MeetsCornerBox4(const Vec4& low, const Vec4& high, const Vec4& o, const Vec4& d,
                              __m128 t) {
  const __m128 origin[3] = {o.x, o.y, o.z}, direction[3] = {d.x, d.y, d.z};
  const __m128 lo[3] = {low.x, low.y, low.z}, hi[3] = {high.x, high.y, high.z};
  __m128 t_enter = _mm_setzero_ps(), t_exit = t;
  for (int k = 0; k < 3; ++k) {
    // A zero component counts as an infinitesimally positive one.
    const __m128 zero = _mm_cmpeq_ps(direction[k], _mm_setzero_ps());
    const __m128 inverse =
        Select(zero, _mm_set1_ps(kHuge), _mm_div_ps(_mm_set1_ps(1.0f), direction[k]));
    const __m128 t1 = Mul(Sub(lo[k], origin[k]), inverse);
    const __m128 t2 = Mul(Sub(hi[k], origin[k]), inverse);
    t_enter = _mm_max_ps(t_enter, _mm_min_ps(t1, t2));
    t_exit = _mm_min_ps(t_exit, _mm_max_ps(t1, t2));
  }
  const float slack = 2.0f * std::numeric_limits<float>::epsilon();
  return _mm_cmple_ps(Mul(t_enter, _mm_set1_ps(1.0f - slack)),
                      Mul(t_exit, _mm_set1_ps(1.0f + slack)));
}

// The rays of a band of rows of one grid block (RayGrid), as the structured
// kernel reads them: origins in the Bullet frame and results, indexed by cell
// (a band's ray from its first).
struct GridBand {
  __m128 dx, dy, dz;                      // the block's direction
  __m128 ox, oy, oz;                      // the batch origin (a ray starts at it plus its start)
  const Eigen::Vector3f* start{nullptr};  // the cells' rays' starts
  float* t_max{nullptr};                  // their entries of RayHits::distance_m
  std::int32_t* body{nullptr};            // of RayHits::body
  Eigen::Vector3f* normal{nullptr};       // unnormalised, or null: none asked for
  std::vector<Eigen::Vector3f> normals;   // their storage
  // Triangle-ray pairs waiting for a test (HitPairs), in lanes' order.
  struct Pairs {
    static constexpr int kCapacity = 64;
    int count{0};
    alignas(16) float corner[9][kCapacity];  // x, y, z of corner 0, 1, 2
    alignas(16) float near[kCapacity];
    int cell[kCapacity], body[kCapacity];
  } pairs;

  // Queues the triangle with these corners against ray `cell`; tests the
  // queue when full (test: HitPairs of the kernel in use).
  template <typename Test>
  void Add(const Eigen::Vector3f corner[3], int body_id, int cell_index, float near_depth,
           Test test) {
    const int k = pairs.count++;
    for (int j = 0; j < 3; ++j) {
      for (int a = 0; a < 3; ++a) pairs.corner[3 * j + a][k] = corner[j][a];
    }
    pairs.near[k] = near_depth;
    pairs.cell[k] = cell_index;
    pairs.body[k] = body_id;
    if (pairs.count == Pairs::kCapacity) test(this);
  }
};

// The packet's BVH walk and triangle test (sensors/packet_walk.inc), compiled twice:
// for any SSE2 CPU, in plain arithmetic redone fused (emulated) where
// rounding could turn a decision; and for CPUs with an FMA unit, fused
// throughout. Fused multiply-adds are what Embree's kernels use on such CPUs,
// the reference the grazing rules are matched to; both give the same results
// but for the emulation's rare double rounding (see FusedMulAdd).
namespace sse2_kernel {
// a b + c (or a b - c) rounded once: the product of two floats is exact in
// double, so only the sum rounds, to double and then to float (a double
// rounding that differs from a single one needs a tie at float precision
// after rounding to double: about once in 2^29 operations).
inline __m128 FusedMulAdd(__m128 a, __m128 b, __m128 c, bool subtract) {
  const __m128d a_lo = _mm_cvtps_pd(a), b_lo = _mm_cvtps_pd(b), c_lo = _mm_cvtps_pd(c);
  const __m128d a_hi = _mm_cvtps_pd(_mm_movehl_ps(a, a)), b_hi = _mm_cvtps_pd(_mm_movehl_ps(b, b));
  const __m128d c_hi = _mm_cvtps_pd(_mm_movehl_ps(c, c));
  const __m128d lo = subtract ? _mm_sub_pd(_mm_mul_pd(a_lo, b_lo), c_lo)
                              : _mm_add_pd(_mm_mul_pd(a_lo, b_lo), c_lo);
  const __m128d hi = subtract ? _mm_sub_pd(_mm_mul_pd(a_hi, b_hi), c_hi)
                              : _mm_add_pd(_mm_mul_pd(a_hi, b_hi), c_hi);
  return _mm_movelh_ps(_mm_cvtpd_ps(lo), _mm_cvtpd_ps(hi));
}
constexpr bool kPlainFirst = true;
#define SANDBOX_KERNEL_TARGET
#include "sensors/packet_walk.inc"
#undef SANDBOX_KERNEL_TARGET
}  // namespace sse2_kernel

namespace fma_kernel {
__attribute__((target("fma"))) inline __m128 FusedMulAdd(__m128 a, __m128 b, __m128 c,
                                                         bool subtract) {
  return subtract ? _mm_fmsub_ps(a, b, c) : _mm_fmadd_ps(a, b, c);
}
constexpr bool kPlainFirst = false;
#define SANDBOX_KERNEL_TARGET __attribute__((target("fma")))
#include "sensors/packet_walk.inc"
#undef SANDBOX_KERNEL_TARGET
}  // namespace fma_kernel

namespace avx512_kernel {
#include "sensors/packet_walk16.inc"
}  // namespace avx512_kernel

// The FMA kernel where the CPU has the unit, unless SANDBOX_RAY_KERNEL=sse2
// asks for the portable one; Cast()'s packets of sixteen rays (and the
// structured kernels' sixteen pairs a test) where it has AVX-512 too, unless
// SANDBOX_RAY_KERNEL=fma or sse2 asks for packets of four (tests run each;
// the results are the same).
const bool kHasFma = [] {
  const char* kernel = std::getenv("SANDBOX_RAY_KERNEL");
  return __builtin_cpu_supports("fma") && !(kernel != nullptr && std::string(kernel) == "sse2");
}();
const bool kHasAvx512 = [] {
  const char* kernel = std::getenv("SANDBOX_RAY_KERNEL");
  return kHasFma && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512dq") &&
         !(kernel != nullptr && std::string(kernel) == "fma");
}();

// The object's own hierarchy (every object has one: CollectTargets).
inline void WalkWide4(const Target& target, Packet* packet) {
  if (kHasFma) {
    fma_kernel::WalkWide4(target, packet);
  } else {
    sse2_kernel::WalkWide4(target, packet);
  }
}

inline void HitPairs(GridBand* band) {
  if (kHasAvx512) {
    avx512_kernel::HitPairs16(band);
  } else if (kHasFma) {
    fma_kernel::HitPairs(band);
  } else {
    sse2_kernel::HitPairs(band);
  }
}

// The span [from, to] of columns that the triangle with corners at columns
// u[k], rows v[k] covers within `margin` rows of row y: the extent of its
// intersection with the strip [y - margin, y + margin]. False when it misses it.
inline bool RowSpan(const float u[3], const float v[3], float y, float margin, float* from,
                    float* to) {
  const float low = y - margin, high = y + margin;
  float lo = kHuge, hi = -kHuge;
  for (int i = 0; i < 3; ++i) {
    if (v[i] >= low && v[i] <= high) lo = std::min(lo, u[i]), hi = std::max(hi, u[i]);
    const int j = i == 2 ? 0 : i + 1;
    if (v[i] == v[j]) continue;
    for (const float line : {low, high}) {
      if ((line - v[i]) * (line - v[j]) > 0.0f) continue;  // the edge does not cross it
      const float t = std::clamp((line - v[i]) / (v[j] - v[i]), 0.0f, 1.0f);
      const float x = u[i] + t * (u[j] - u[i]);
      lo = std::min(lo, x), hi = std::max(hi, x);
    }
  }
  *from = lo, *to = hi;
  return lo <= hi;
}

// The least whole number >= x and >= 0 (at most `cap`), and the greatest
// <= x and <= top (-1 below 0): float to int without libm.
inline int CeilNotBelowZero(float x, int cap) {
  if (!(x > 0.0f)) return 0;
  if (x >= float(cap)) return cap;
  const int whole = int(x);
  return whole + (float(whole) < x ? 1 : 0);
}
inline int FloorNotAbove(float x, int top) {
  if (!(x >= 0.0f)) return -1;
  return x >= float(top) ? top : int(x);
}

// A band's grid coordinates of Bullet-frame points, in float: columns, rows
// and depth along the rays of p - corner; margins in metres and in cells.
struct BandFrame {
  BandFrame(const Eigen::Vector3d& corner_B, const Eigen::Vector3d& to_column,
            const Eigen::Vector3d& to_row, const Eigen::Vector3d& direction, double margin_m,
            double columns_m, double rows_m)
      : margin(float(margin_m)), margin_columns(float(columns_m)), margin_rows(float(rows_m)) {
    const Eigen::Vector3d* axes[3] = {&to_column, &to_row, &direction};
    for (int k = 0; k < 3; ++k) {
      corner[k] = _mm_set1_ps(float(corner_B[k]));
      for (int w = 0; w < 3; ++w) axis[w][k] = _mm_set1_ps(float((*axes[w])[k]));
    }
  }
  // Coordinate w (0 column, 1 row, 2 depth) of the points x, y, z (relative to corner).
  __m128 Along(int w, __m128 x, __m128 y, __m128 z) const {
    return Add(Add(Mul(x, axis[w][0]), Mul(y, axis[w][1])), Mul(z, axis[w][2]));
  }
  __m128 corner[3];
  __m128 axis[3][3];
  float margin, margin_columns, margin_rows;
};

// Up to four linear coordinates of points (a band's columns, rows and depths)
// as seen from one object's own hierarchy: over a node box [lo, hi] (the
// object's frame), coordinate w spans w0 + sum_k (p_k * a_k) over its corners;
// `margin` widens that, and it must meet [0, limit] (in a whole number, in
// `integral` lanes).
struct GridCull {
  __m128 positive[3], negative[3];  // per axis k: the weights a_k, split by sign
  __m128 w0, margin, limit, integral;

  // From per-coordinate lanes (coordinates a lane; integral: the first two).
  static GridCull Of(const float positive[3][4], const float negative[3][4], const float w0[4],
                     const float margin[4], const float limit[4], bool integral_first_two) {
    GridCull cull;
    for (int k = 0; k < 3; ++k) {
      cull.positive[k] = _mm_loadu_ps(positive[k]);
      cull.negative[k] = _mm_loadu_ps(negative[k]);
    }
    cull.w0 = _mm_loadu_ps(w0);
    cull.margin = _mm_loadu_ps(margin);
    cull.limit = _mm_loadu_ps(limit);
    cull.integral =
        _mm_castsi128_ps(integral_first_two ? _mm_setr_epi32(-1, -1, 0, 0) : _mm_setzero_si128());
    return cull;
  }
};

// An object's placement X_BL in the Bullet frame, in double.
void ObjectFrame(const Target& target, Eigen::Matrix3d* R_BL, Eigen::Vector3d* p_BL) {
  const btTransform& X_BL = target.X_BL;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) (*R_BL)(r, c) = double(X_BL.getBasis()[r][c]);
  }
  *p_BL = Eigen::Vector3d(X_BL.getOrigin().x(), X_BL.getOrigin().y(), X_BL.getOrigin().z());
}

// The cull for coordinates w = (X_BL p - origin) . axes[w] (p in the
// object's frame) that must lie in [0, limit[w]] to within margin[w]; lanes
// beyond `count` always pass. w is linear in p, and the slack covers the
// boxes' growth for the change of frame and the rounding of the sums.
GridCull CullForWide(const Target& target, const Eigen::Vector3d& origin,
                     const Eigen::Vector3d* const axes[], int count, const double limit[],
                     const double margin[], bool integral_first_two) {
  Eigen::Matrix3d R_BL;
  Eigen::Vector3d p_BL;
  ObjectFrame(target, &R_BL, &p_BL);
  const double extent =
      std::max(target.bvh->lower.cwiseAbs().maxCoeff(), target.bvh->upper.cwiseAbs().maxCoeff());
  alignas(16) float positive[3][4] = {}, negative[3][4] = {}, w0[4] = {}, slack[4] = {};
  alignas(16) float top[4] = {};
  for (int w = 0; w < count; ++w) {
    const Eigen::Vector3d a = R_BL.transpose() * *axes[w];
    w0[w] = float((p_BL - origin).dot(*axes[w]));
    top[w] = float(limit[w]);
    const double weight = a.cwiseAbs().sum();
    for (int k = 0; k < 3; ++k) {
      positive[k][w] = float(std::max(a[k], 0.0));
      negative[k][w] = float(std::min(a[k], 0.0));
    }
    const double reach = std::abs(w0[w]) + weight * extent;
    slack[w] = float(margin[w] + weight * target.box_margin + 1e-6 * reach);
  }
  return GridCull::Of(positive, negative, w0, slack, top, integral_first_two);
}

// Whether child c of one of the object's own nodes reaches a grid point in
// columns and rows and the rays' span in depth.
inline bool ChildMeetsGrid(const scene::TriangleBvh::Node& node, int c, const GridCull& cull) {
  __m128 from = cull.w0, to = cull.w0;
  for (int k = 0; k < 3; ++k) {
    const __m128 lower = _mm_set1_ps(node.lower[k][c]), upper = _mm_set1_ps(node.upper[k][c]);
    from = Add(from, Add(Mul(lower, cull.positive[k]), Mul(upper, cull.negative[k])));
    to = Add(to, Add(Mul(upper, cull.positive[k]), Mul(lower, cull.negative[k])));
  }
  const __m128 low = _mm_max_ps(Sub(from, cull.margin), _mm_setzero_ps());
  const __m128 high = _mm_min_ps(Add(to, cull.margin), cull.limit);
  const __m128 whole = _mm_cvtepi32_ps(_mm_cvttps_epi32(high));
  return _mm_movemask_ps(_mm_cmpge_ps(Select(cull.integral, whole, high), low)) == 0xF;
}

// Calls visit(corners, body) (the Bullet frame, as Corners() places them) for
// each triangle of `target` in a leaf of its own hierarchy whose box meets the grid.
template <typename Visit>
void ForEachTriangleOverGridWide(const Target& target, const GridCull& cull, Visit&& visit) {
  const scene::TriangleBvh& bvh = *target.bvh;
  if (bvh.root == scene::TriangleBvh::kEmpty) return;
  WalkStack<std::int32_t, kStackInPlace> stack;
  stack.Push(bvh.root);
  while (!stack.empty()) {
    const std::int32_t ref = stack.Pop();
    if (ref < 0) {
      const scene::TriangleBvh::Leaves& leaf = bvh.leaves[std::size_t(-1 - ref)];
      for (int i = 0; i < leaf.count; ++i) {
        Eigen::Vector3f corners[3];
        for (int k = 0; k < 3; ++k) {
          const Eigen::Vector3f p(leaf.corner[3 * k][i], leaf.corner[3 * k + 1][i],
                                  leaf.corner[3 * k + 2][i]);
          corners[k] = target.identity ? p : ToEigen(target.X_BL * btVector3(p.x(), p.y(), p.z()));
        }
        visit(corners, target.BodyOf(leaf.part[i]));
      }
      continue;
    }
    const scene::TriangleBvh::Node& node = bvh.nodes[std::size_t(ref)];
    for (int c = scene::TriangleBvh::kWidth - 1; c >= 0; --c) {
      if (node.child[c] != scene::TriangleBvh::kEmpty && ChildMeetsGrid(node, c, cull)) {
        stack.Push(node.child[c]);
      }
    }
  }
}

// Lanes whose rays enter an axis-aligned box (Bullet frame) before their t_max.
inline int PacketMeetsBox(const Packet& packet, const __m128 inverse[3],
                          const Eigen::Vector3f& box_min, const Eigen::Vector3f& box_max) {
  const __m128 o[3] = {packet.ox, packet.oy, packet.oz};
  __m128 t_enter = _mm_setzero_ps(), t_exit = packet.t_max;
  for (int k = 0; k < 3; ++k) {
    const __m128 t1 = Mul(Sub(_mm_set1_ps(box_min[k]), o[k]), inverse[k]);
    const __m128 t2 = Mul(Sub(_mm_set1_ps(box_max[k]), o[k]), inverse[k]);
    t_enter = _mm_max_ps(t_enter, _mm_min_ps(t1, t2));
    t_exit = _mm_min_ps(t_exit, _mm_max_ps(t1, t2));
  }
  return _mm_movemask_ps(_mm_and_ps(packet.active, _mm_cmple_ps(t_enter, t_exit)));
}
#endif

}  // namespace

struct RayCaster::Targets {
  std::uint64_t instance{0}, revision{0};
  std::vector<Target> all;
  // The merged static objects' target and every other, or empty when the
  // world has no merged objects (scene::MergedStatic).
  std::vector<Target> merged;
  const std::vector<bool>* merged_actors{nullptr};  // by actor: in the merged target

  // The kernels that walk the objects' own hierarchies read `merged` unless
  // the filter leaves out one of its actors.
  const std::vector<Target>& For(const RayFilter& filter) const {
    const bool ignores_merged = filter.ignore_actor >= 0 && merged_actors != nullptr &&
                                std::size_t(filter.ignore_actor) < merged_actors->size() &&
                                (*merged_actors)[std::size_t(filter.ignore_actor)];
    return merged.empty() || ignores_merged ? all : merged;
  }
};

const char* RayCaster::kernel() {
#if defined(__SSE2__)
  return kHasAvx512 ? "avx512" : kHasFma ? "fma" : "sse2";
#else
  return "scalar";
#endif
}

void RayBatch::Resize(std::size_t n) {
  start.resize(n);
  direction.resize(n);
  length_m.resize(n);
}

RayCaster::RayCaster(int threads) : pool_(threads) {}

RayCaster::~RayCaster() = default;

void RayCaster::RunParallel(int count, const std::function<void(int)>& job) {
  pool_.RunParallel(count, job);
}

const RayCaster::Targets& RayCaster::TargetsOf(const scene::CollisionWorld& world) {
  if (!targets_) targets_ = std::make_unique<Targets>();
  if (targets_->instance != world.instance() || targets_->revision != world.revision()) {
    targets_->all = CollectTargets(world);
    targets_->merged.clear();
    const scene::CollisionWorld::Impl& w = world.internals();
    if (w.merged_static.bvh != nullptr) {
      targets_->merged.push_back(MergedTarget(world));
      for (std::size_t i = 0; i < w.objects.size(); ++i) {
        if (!w.objects[i].merged) targets_->merged.push_back(targets_->all[i]);
      }
      targets_->merged_actors = &w.merged_static.holds_actor;
    }
    targets_->instance = world.instance();
    targets_->revision = world.revision();
  }
  return *targets_;
}

void RayCaster::Cast(const scene::CollisionWorld& world, const RayBatch& rays,
                     const RayFilter& filter, RayHits* hits) {
  const std::size_t n = rays.size();
  rays_cast_ += std::int64_t(n);
  SizeHits(n, hits);
  if (n == 0) return;
  // The batch in Bullet's frame (world minus the floating origin).
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  // (Without SSE2 the rays walk Bullet's trees, which the merged target has not.)
#if defined(__SSE2__)
  const std::vector<Target>& all_targets = TargetsOf(world).For(filter);
#else
  const std::vector<Target>& all_targets = TargetsOf(world).all;
#endif
  const Visible wanted{filter, world.internals().num_actors};
  // The objects the rays may see; when they are a few bodies (a packet
  // tests each body's box, then each object's), every chunk takes them all.
  std::vector<const Target*> seen;
  int bodies_seen = 0;
  for (const Target& target : all_targets) {
    if (!wanted(target)) continue;
    bodies_seen += seen.empty() || seen.back()->body != target.body;
    seen.push_back(&target);
  }
  constexpr int kFewBodies = 8;

  const std::function<void(int)> job = [&](int chunk) {
    const std::size_t first = std::size_t(chunk) * kRaysPerChunk;
    const std::size_t end = std::min(n, first + kRaysPerChunk);
    const Target* const* targets = seen.data();
    std::size_t num_targets = seen.size();
    const Target* targets_here[64];
    std::vector<const Target*> many;
    if (bodies_seen > kFewBodies) {
      // Only the objects whose bounds meet this chunk's rays' bounds.
      Eigen::Vector3f chunk_min = Eigen::Vector3f::Constant(std::numeric_limits<float>::max());
      Eigen::Vector3f chunk_max = -chunk_min;
      for (std::size_t r = first; r < end; ++r) {
        const Eigen::Vector3f a = origin_B + rays.start[r];
        const Eigen::Vector3f b = a + rays.length_m[r] * rays.direction[r];
        chunk_min = chunk_min.cwiseMin(a.cwiseMin(b));
        chunk_max = chunk_max.cwiseMax(a.cwiseMax(b));
      }
      std::size_t count = 0;
      for (const Target* target : seen) {
        if ((target->aabb_min.array() > chunk_max.array()).any() ||
            (target->aabb_max.array() < chunk_min.array()).any()) {
          continue;
        }
        if (count < 64) {
          targets_here[count++] = target;
        } else {
          if (many.empty()) many.assign(targets_here, targets_here + 64);
          many.push_back(target);
        }
      }
      targets = many.empty() ? targets_here : many.data();
      num_targets = many.empty() ? count : many.size();
    }
    std::size_t i = first;
#if defined(__SSE2__)
    if (kHasAvx512) {
      avx512_kernel::CastRays16(rays, origin_B, first, end, targets, num_targets, hits);
      i = end;
    }
    // Four rays at a time; the last packet of the batch may be partly empty.
    for (; i < end; i += 4) {
      alignas(16) float lane[7][4];
      alignas(16) std::uint32_t active[4];
      for (int l = 0; l < 4; ++l) {
        const std::size_t r = std::min(i + std::size_t(l), end - 1);
        const Eigen::Vector3f o = origin_B + rays.start[r];
        lane[0][l] = o.x(), lane[1][l] = o.y(), lane[2][l] = o.z();
        lane[3][l] = rays.direction[r].x(), lane[4][l] = rays.direction[r].y();
        lane[5][l] = rays.direction[r].z(), lane[6][l] = rays.length_m[r];
        active[l] = i + std::size_t(l) < end ? 0xFFFFFFFFu : 0u;
      }
      Packet packet;
      packet.ox = _mm_load_ps(lane[0]), packet.oy = _mm_load_ps(lane[1]);
      packet.oz = _mm_load_ps(lane[2]), packet.dx = _mm_load_ps(lane[3]);
      packet.dy = _mm_load_ps(lane[4]), packet.dz = _mm_load_ps(lane[5]);
      packet.t_max = _mm_load_ps(lane[6]);
      packet.active = _mm_load_ps(reinterpret_cast<const float*>(active));
      const __m128 inverse[3] = {_mm_div_ps(_mm_set1_ps(1.0f), AwayFromZero(packet.dx)),
                                 _mm_div_ps(_mm_set1_ps(1.0f), AwayFromZero(packet.dy)),
                                 _mm_div_ps(_mm_set1_ps(1.0f), AwayFromZero(packet.dz))};
      for (int l = 0; l < 4; ++l) packet.body[l] = RayHits::kNoHit;
      for (std::size_t t = 0; t < num_targets;) {
        // A run of one body's objects (a robot's pieces): skipped whole when
        // the packet misses the box around them.
        std::size_t run_end = t + 1;
        while (run_end < num_targets && targets[run_end]->body == targets[t]->body) ++run_end;
        if (run_end - t > 2 &&
            PacketMeetsBox(packet, inverse, targets[t]->body_min, targets[t]->body_max) == 0) {
          t = run_end;
          continue;
        }
        for (; t < run_end; ++t) {
          const Target& target = *targets[t];
          if (PacketMeetsBox(packet, inverse, target.aabb_min, target.aabb_max) != 0) {
            WalkWide4(target, &packet);
          }
        }
      }
      alignas(16) float t_max[4];
      _mm_store_ps(t_max, packet.t_max);
      for (int l = 0; l < 4 && i + std::size_t(l) < end; ++l) {
        const std::size_t r = i + std::size_t(l);
        WriteHit(r, t_max[l], packet.body[l], packet.normal[l], rays.direction[r], hits);
      }
    }
#endif
    for (; i < end; ++i) {
      const Eigen::Vector3f o = origin_B + rays.start[i];
      const Eigen::Vector3f& d = rays.direction[i];
      const Eigen::Vector3f inverse_d = d.unaryExpr(
          [](float x) { return 1.0f / (std::abs(x) > 1e-30f ? x : std::copysign(1e-30f, x)); });
      float t_max = rays.length_m[i];
      int body = RayHits::kNoHit;
      Eigen::Vector3f normal = Eigen::Vector3f::Zero();
      for (std::size_t t = 0; t < num_targets; ++t) {
        const Target& target = *targets[t];
        if (!RayMeetsBox(o, inverse_d, target.aabb_min, target.aabb_max, t_max)) continue;
        if (WalkTarget(target, o, d, &t_max, &normal)) body = target.body;
      }
      WriteHit(i, t_max, body, normal, d, hits);
    }
  };
  RunParallel(static_cast<int>((n + kRaysPerChunk - 1) / kRaysPerChunk), job);
}

void RayCaster::CastGrids(const scene::CollisionWorld& world, const RayBatch& rays,
                          const std::vector<RayGrid>& grids, const RayFilter& filter,
                          RayHits* hits) {
  const std::size_t n = rays.size();
  std::size_t next = 0;
  for (const RayGrid& grid : grids) {
    if (grid.first != next || grid.rows < 0 || grid.cols <= 0 ||
        grid.first + std::size_t(grid.rows) * std::size_t(grid.cols) > n) {
      throw std::invalid_argument("RayCaster::CastGrids(): the blocks do not cover the batch's " +
                                  std::to_string(n) + " rays in order");
    }
    next = grid.first + std::size_t(grid.rows) * std::size_t(grid.cols);
    if (!(std::abs(grid.direction.norm() - 1.0f) < 1e-5f) ||
        !(std::isfinite(grid.length_m) && grid.length_m > 0.0f)) {
      throw std::invalid_argument(
          "RayCaster::CastGrids(): a block's direction must be unit and its length positive");
    }
  }
  if (next != n) {
    throw std::invalid_argument("RayCaster::CastGrids(): the blocks cover " + std::to_string(next) +
                                " of the batch's " + std::to_string(n) + " rays");
  }
#if !defined(__SSE2__)
  // Cast() reads the batch's directions and lengths: they must be the blocks'.
  for (const RayGrid& grid : grids) {
    for (std::size_t i = grid.first; i < grid.first + std::size_t(grid.rows) * grid.cols; ++i) {
      if (rays.direction[i] != grid.direction || rays.length_m[i] != grid.length_m) {
        throw std::invalid_argument("RayCaster::CastGrids(): ray " + std::to_string(i) +
                                    " differs in direction or length from its block");
      }
    }
  }
  Cast(world, rays, filter, hits);
#else
  rays_cast_ += std::int64_t(n);
  SizeHits(n, hits);
  if (n == 0) return;
  const Eigen::Vector3f origin_B = (rays.origin_W - world.origin()).cast<float>();
  const std::vector<Target>& all_targets = TargetsOf(world).For(filter);
  const Visible wanted{filter, world.internals().num_actors};
  // Bands of rows, each a chunk of work (each band walks the BVH from its
  // root, so fewer is less work; at least four rows each). Without a history:
  // four a thread over all blocks. After a call over the same blocks (a
  // scanner's next scan), by what each block took then: a block gets as many
  // bands as it took threads' shares of the total (rounded up), and the
  // costliest bands are taken first, so that the threads end together.
  struct Band {
    const RayGrid* grid;
    int block, row_begin, row_end;
    double cost;
  };
  std::vector<Band> bands;
  bool known = threads() > 1 && grid_costs_.size() == grids.size();
  double total = 0.0;
  for (std::size_t b = 0; known && b < grids.size(); ++b) {
    known = grid_costs_[b].rows == grids[b].rows;
    total += grid_costs_[b].seconds;
  }
  known = known && total > 0.0;
  const int even_split = (4 * threads() + int(grids.size()) - 1) / std::max(1, int(grids.size()));
  for (std::size_t b = 0; b < grids.size(); ++b) {
    const RayGrid& grid = grids[b];
    const double cost = known ? grid_costs_[b].seconds : 1.0;
    const int split = known ? int(std::ceil(cost / (total / threads()))) : even_split;
    const int rows_per_band = std::max(4, (grid.rows + split - 1) / std::max(1, split));
    for (int r = 0; r < grid.rows; r += rows_per_band) {
      const int end = std::min(grid.rows, r + rows_per_band);
      bands.push_back({&grid, int(b), r, end, cost * (end - r) / std::max(1, grid.rows)});
    }
  }
  if (known) {
    std::stable_sort(bands.begin(), bands.end(),
                     [](const Band& a, const Band& b) { return a.cost > b.cost; });
  }
  std::vector<double> band_seconds(bands.size(), 0.0);

  const std::function<void(int)> job = [&](int band_index) {
    const auto started = std::chrono::steady_clock::now();
    const Band& this_band = bands[std::size_t(band_index)];
    const RayGrid& grid = *this_band.grid;
    const int row_begin = this_band.row_begin;
    const int rows = this_band.row_end - row_begin, cols = grid.cols;
    const std::size_t first = grid.first + std::size_t(row_begin) * std::size_t(cols);
    const std::size_t count = std::size_t(rows) * std::size_t(cols);
    const Eigen::Vector3f d = grid.direction;
    const float length = grid.length_m;
    thread_local GridBand band;
    band.dx = _mm_set1_ps(d.x()), band.dy = _mm_set1_ps(d.y()), band.dz = _mm_set1_ps(d.z());
    band.ox = _mm_set1_ps(origin_B.x()), band.oy = _mm_set1_ps(origin_B.y());
    band.oz = _mm_set1_ps(origin_B.z());
    band.start = rays.start.data() + first;
    band.t_max = hits->distance_m.data() + first;
    band.body = hits->body.data() + first;
    std::fill(band.t_max, band.t_max + count, length);
    std::fill(band.body, band.body + count, RayHits::kNoHit);
    band.normal = nullptr;
    if (hits->with_normals) {
      band.normals.resize(count);
      band.normal = band.normals.data();
    }
    band.pairs.count = 0;
    // The band's grid in the Bullet frame, in double: a point's column is
    // (p - corner) . to_column, its row (p - corner) . to_row, its depth
    // along the rays (p - corner) . direction. The margin covers the float
    // rounding of the rays' origins and of the triangle test's tolerance.
    const Eigen::Vector3d corner = grid.corner_W - world.origin() + row_begin * grid.step_v_W;
    const double step_u = grid.step_u_W.norm(), step_v = grid.step_v_W.norm();
    const Eigen::Vector3d to_column = grid.step_u_W / (step_u * step_u);
    const Eigen::Vector3d to_row = grid.step_v_W / (step_v * step_v);
    const Eigen::Vector3d direction = d.cast<double>();
    const double margin =
        1e-5 * (corner.norm() + cols * step_u + rows * step_v + double(length)) + 1e-5;
    const double margin_columns = margin / step_u, margin_rows = margin / step_v;
    const BandFrame frame(corner, to_column, to_row, direction, margin, margin_columns,
                          margin_rows);
    Eigen::AlignedBox3d box;
    for (const double u : {-margin_columns, cols - 1 + margin_columns}) {
      for (const double v : {-margin_rows, rows - 1 + margin_rows}) {
        for (const double s : {-margin, double(length) + margin}) {
          box.extend(corner + u * grid.step_u_W + v * grid.step_v_W + s * direction);
        }
      }
    }
    const Eigen::Vector3f box_min = (box.min().array() - margin).cast<float>();
    const Eigen::Vector3f box_max = (box.max().array() + margin).cast<float>();
    // Per lane (column, row, depth): the margins, and the bounds of the
    // cells' columns and rows and of the rays' depths (the fourth lane: none).
    const __m128 lane_margins =
        _mm_setr_ps(frame.margin_columns, frame.margin_rows, frame.margin, 0.0f);
    const __m128 cap = _mm_setr_ps(float(cols), float(rows), kHuge, kHuge);
    const __m128 top = _mm_setr_ps(float(cols - 1), float(rows - 1), length, kHuge);
    for (const Target& target : all_targets) {
      if (!wanted(target) || (target.aabb_min.array() > box_max.array()).any() ||
          (target.aabb_max.array() < box_min.array()).any()) {
        continue;
      }
      const Eigen::Vector3d* axes[3] = {&to_column, &to_row, &direction};
      const double limit[3] = {double(cols - 1), double(rows - 1), double(length)};
      const double margins[3] = {margin_columns, margin_rows, margin};
      const GridCull cull = CullForWide(target, corner, axes, 3, limit, margins, true);
      ForEachTriangleOverGridWide(target, cull, [&](const Eigen::Vector3f* corners, int body) {
        // Columns u, rows v and depths s of the corners (SSE, a lane each).
        const __m128 x =
            Sub(_mm_setr_ps(corners[0].x(), corners[1].x(), corners[2].x(), corners[2].x()),
                frame.corner[0]);
        const __m128 y =
            Sub(_mm_setr_ps(corners[0].y(), corners[1].y(), corners[2].y(), corners[2].y()),
                frame.corner[1]);
        const __m128 z =
            Sub(_mm_setr_ps(corners[0].z(), corners[1].z(), corners[2].z(), corners[2].z()),
                frame.corner[2]);
        const __m128 column = frame.Along(0, x, y, z), row = frame.Along(1, x, y, z);
        // A corner a vector (column, row, depth, depth), then their least and
        // greatest coordinates, widened by the margins.
        __m128 p0 = column, p1 = row, p2 = frame.Along(2, x, y, z), p3 = p2;
        _MM_TRANSPOSE4_PS(p0, p1, p2, p3);
        const __m128 low = Sub(_mm_min_ps(_mm_min_ps(p0, p1), p2), lane_margins);
        const __m128 high = Add(_mm_max_ps(_mm_max_ps(p0, p1), p2), lane_margins);
        // The columns, rows and depths within the grid that it spans, if any:
        // from the least whole column and row at or above `span_from`, to the
        // greatest at or below `span_to`.
        const __m128 span_from = _mm_min_ps(_mm_max_ps(low, _mm_setzero_ps()), cap);
        const __m128 span_to = _mm_min_ps(top, high);
        if ((_mm_movemask_ps(_mm_cmpge_ps(span_to, span_from)) & 7) != 7) return;
        const __m128i whole = _mm_cvttps_epi32(span_from);
        const __m128i least =
            _mm_sub_epi32(whole, _mm_castps_si128(_mm_cmplt_ps(_mm_cvtepi32_ps(whole), span_from)));
        const __m128i last = _mm_cvttps_epi32(span_to);
        if (_mm_movemask_ps(_mm_castsi128_ps(_mm_cmpgt_epi32(least, last))) & 3) return;
        alignas(16) std::int32_t firsts[4], lasts[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(firsts), least);
        _mm_store_si128(reinterpret_cast<__m128i*>(lasts), last);
        const int c0 = firsts[0], r0 = firsts[1], c1 = lasts[0], r1 = lasts[1];
        const float near = _mm_cvtss_f32(_mm_movehl_ps(low, low));
        auto add = [&](int r, int c) { band.Add(corners, body, r * cols + c, near, HitPairs); };
        if ((r1 - r0 + 1) * (c1 - c0 + 1) <= 4) {  // the box's few cells
          for (int r = r0; r <= r1; ++r) {
            for (int c = c0; c <= c1; ++c) add(r, c);
          }
          return;
        }
        // Row by row, the cells within the triangle's span.
        alignas(16) float u[4], v[4];
        _mm_store_ps(u, column), _mm_store_ps(v, row);
        for (int r = r0; r <= r1; ++r) {
          float from, to;
          if (!RowSpan(u, v, float(r), frame.margin_rows, &from, &to)) continue;
          const int first_column =
              std::max(c0, CeilNotBelowZero(from - frame.margin_columns, cols));
          const int last_column = std::min(c1, FloorNotAbove(to + frame.margin_columns, cols - 1));
          for (int c = first_column; c <= last_column; ++c) add(r, c);
        }
      });
    }
    HitPairs(&band);
    if (band.normal != nullptr) {
      for (std::size_t i = 0; i < count; ++i) {
        WriteHit(first + i, band.t_max[i], band.body[i], band.normal[i], d, hits);
      }
    }
    band_seconds[std::size_t(band_index)] =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  };
  RunParallel(static_cast<int>(bands.size()), job);
  grid_costs_.assign(grids.size(), GridCost{0, 0.0});
  for (std::size_t b = 0; b < grids.size(); ++b) grid_costs_[b].rows = grids[b].rows;
  for (std::size_t i = 0; i < bands.size(); ++i) {
    grid_costs_[std::size_t(bands[i].block)].seconds += band_seconds[i];
  }
#endif
}

}  // namespace sandbox::sensors
