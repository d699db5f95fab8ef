// The packet kernel of eight rays (sensors/ray_kernels.h), for CPUs with
// AVX2 and FMA but no AVX-512: packet_walk16.cc's walk and fused watertight
// triangle test, operation for operation, eight lanes wide (the same bits in
// every lane). Built once, with -mavx2 -mfma (namespace avx2). AVX2 has no
// mask registers: a lane mask is a compare's result (all bits set) in the
// arithmetic and its movemask (a bit a lane) in the walk's entries. A
// packet whose rays start at one point tests a leaf's triangles from terms
// computed once for the leaf (ShareLeaf).

#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "sensors/ray_kernels.h"
#include "sensors/walk_stack.h"

namespace sandbox::sensors::SANDBOX_ISA {
namespace {

struct V8 {  // a vector per lane
  __m256 x, y, z;
};
inline __m256 Set(float v) { return _mm256_set1_ps(v); }
inline __m256 Mul(__m256 a, __m256 b) { return _mm256_mul_ps(a, b); }
inline __m256 Add(__m256 a, __m256 b) { return _mm256_add_ps(a, b); }
inline __m256 Sub(__m256 a, __m256 b) { return _mm256_sub_ps(a, b); }
inline V8 Sub(const V8& a, const V8& b) { return {Sub(a.x, b.x), Sub(a.y, b.y), Sub(a.z, b.z)}; }
inline V8 Add(const V8& a, const V8& b) { return {Add(a.x, b.x), Add(a.y, b.y), Add(a.z, b.z)}; }
inline __m256 Min(__m256 a, __m256 b) { return _mm256_min_ps(a, b); }
inline __m256 Max(__m256 a, __m256 b) { return _mm256_max_ps(a, b); }
inline __m256 And(__m256 a, __m256 b) { return _mm256_and_ps(a, b); }
inline __m256 Or(__m256 a, __m256 b) { return _mm256_or_ps(a, b); }
inline __m256 Abs(__m256 x) { return _mm256_andnot_ps(Set(-0.0f), x); }
template <int kPredicate>
inline __m256 Cmp(__m256 a, __m256 b) {
  return _mm256_cmp_ps(a, b, kPredicate);
}
inline int Bits(__m256 mask) { return _mm256_movemask_ps(mask); }
// The lanes whose bits are set in `bits`, all bits set.
inline __m256 LaneMask(int bits) {
  const __m256i bit = _mm256_setr_epi32(1, 2, 4, 8, 16, 32, 64, 128);
  return _mm256_castsi256_ps(
      _mm256_cmpeq_epi32(_mm256_and_si256(_mm256_set1_epi32(bits), bit), bit));
}
// a where the mask is set, b elsewhere.
inline __m256 Select(__m256 mask, __m256 a, __m256 b) { return _mm256_blendv_ps(b, a, mask); }
inline __m256 Dot(const V8& a, const V8& b) {
  return _mm256_fmadd_ps(a.x, b.x, _mm256_fmadd_ps(a.y, b.y, Mul(a.z, b.z)));
}
inline V8 Cross(const V8& a, const V8& b) {
  return {_mm256_fmsub_ps(a.y, b.z, Mul(a.z, b.y)), _mm256_fmsub_ps(a.z, b.x, Mul(a.x, b.z)),
          _mm256_fmsub_ps(a.x, b.y, Mul(a.y, b.x))};
}
// StableNormal4<true>.
inline V8 StableNormal(const V8& a, const V8& b, const V8& c) {
  const __m256 ab_x = Mul(a.z, b.y), ab_y = Mul(a.x, b.z), ab_z = Mul(a.y, b.x);
  const __m256 bc_x = Mul(b.z, c.y), bc_y = Mul(b.x, c.z), bc_z = Mul(b.y, c.x);
  auto less = [](__m256 p, __m256 q) { return Cmp<_CMP_LT_OS>(Abs(p), Abs(q)); };
  return {
      Select(less(ab_x, bc_x), _mm256_fmsub_ps(a.y, b.z, ab_x), _mm256_fmsub_ps(b.y, c.z, bc_x)),
      Select(less(ab_y, bc_y), _mm256_fmsub_ps(a.z, b.x, ab_y), _mm256_fmsub_ps(b.z, c.x, bc_y)),
      Select(less(ab_z, bc_z), _mm256_fmsub_ps(a.x, b.y, ab_z), _mm256_fmsub_ps(b.x, c.y, bc_z))};
}
// The unit normals along n facing rays along d (FacingUnits4, eight lanes:
// the estimate and one Newton step).
inline V8 FacingUnits8(const V8& n, const V8& d) {
  const __m256 n2 = Add(Add(Mul(n.x, n.x), Mul(n.y, n.y)), Mul(n.z, n.z));
  const __m256 r0 = _mm256_rsqrt_ps(n2);
  // r = r0 (3 - n2 r0^2) / 2, negated where n runs along d.
  __m256 scale = Mul(Mul(Set(0.5f), r0), Sub(Set(3.0f), Mul(n2, Mul(r0, r0))));
  const __m256 along = Add(Add(Mul(n.x, d.x), Mul(n.y, d.y)), Mul(n.z, d.z));
  scale = _mm256_xor_ps(scale, And(Cmp<_CMP_GT_OQ>(along, _mm256_setzero_ps()), Set(-0.0f)));
  return {Mul(n.x, scale), Mul(n.y, scale), Mul(n.z, scale)};
}
// MeetsCornerBox's inverse directions: a zero component counts as an
// infinitesimally positive one.
inline V8 CornerBoxInverse(const V8& d) {
  const __m256 direction[3] = {d.x, d.y, d.z};
  __m256 inverse[3];
  for (int k = 0; k < 3; ++k) {
    const __m256 zero = Cmp<_CMP_EQ_OQ>(direction[k], _mm256_setzero_ps());
    inverse[k] = Select(zero, Set(kHuge), _mm256_div_ps(Set(1.0f), direction[k]));
  }
  return {inverse[0], inverse[1], inverse[2]};
}
// MeetsCornerBox4, eight lanes (inverse: CornerBoxInverse of the directions).
inline __m256 MeetsCornerBox8(const V8& low, const V8& high, const V8& o, const V8& inverse_d,
                              __m256 t) {
  const __m256 origin[3] = {o.x, o.y, o.z}, inverse[3] = {inverse_d.x, inverse_d.y, inverse_d.z};
  const __m256 lo[3] = {low.x, low.y, low.z}, hi[3] = {high.x, high.y, high.z};
  __m256 t_enter = _mm256_setzero_ps(), t_exit = t;
  for (int k = 0; k < 3; ++k) {
    const __m256 t1 = Mul(Sub(lo[k], origin[k]), inverse[k]);
    const __m256 t2 = Mul(Sub(hi[k], origin[k]), inverse[k]);
    t_enter = Max(t_enter, Min(t1, t2));
    t_exit = Min(t_exit, Max(t1, t2));
  }
  const float slack = 2.0f * std::numeric_limits<float>::epsilon();
  return Cmp<_CMP_LE_OS>(Mul(t_enter, Set(1.0f - slack)), Mul(t_exit, Set(1.0f + slack)));
}

// The lanes of `lanes` whose ray passes inside or on the triangle's three
// edges (u, v, w: the edges' signed volumes with the ray).
SANDBOX_KERNEL_INLINE __m256 InsideEdges8(__m256 u, __m256 v, __m256 w, __m256 lanes) {
  const __m256 eps = Mul(Set(std::numeric_limits<float>::epsilon()), Abs(Add(Add(u, v), w)));
  const __m256 low = Min(Min(u, v), w);
  const __m256 high = Max(Max(u, v), w);
  return And(lanes,
             Or(Cmp<_CMP_GE_OS>(low, Sub(_mm256_setzero_ps(), eps)), Cmp<_CMP_LE_OS>(high, eps)));
}

// The rest of the test for the lanes in `hit`: the plane's distance (n its
// normal, depth twice the dot of corner 0 from the origin with n), then the
// triangle's box; those closer than their t_max (or at it, in `ties`) take it.
SANDBOX_KERNEL_INLINE __m256 HitPlane8(__m256 hit, const V8 c[3], const V8& n, __m256 depth,
                                       const V8& o, const V8& d, const V8& box_inverse, __m256 ties,
                                       __m256* t_max, V8* normal) {
  const __m256 den = Mul(Set(2.0f), Dot(n, d));
  const __m256 t = _mm256_div_ps(depth, den);
  hit = And(hit, Cmp<_CMP_NEQ_UQ>(den, _mm256_setzero_ps()));
  hit = And(hit, Cmp<_CMP_GE_OS>(t, _mm256_setzero_ps()));
  hit = And(hit, Or(Cmp<_CMP_LT_OS>(t, *t_max), And(ties, Cmp<_CMP_EQ_OQ>(t, *t_max))));
  if (Bits(hit) == 0) return hit;
  // (MeetsCornerBox: the segment up to the hit meets the triangle's box.)
  const V8 box_low{Min(Min(c[0].x, c[1].x), c[2].x), Min(Min(c[0].y, c[1].y), c[2].y),
                   Min(Min(c[0].z, c[1].z), c[2].z)};
  const V8 box_high{Max(Max(c[0].x, c[1].x), c[2].x), Max(Max(c[0].y, c[1].y), c[2].y),
                    Max(Max(c[0].z, c[1].z), c[2].z)};
  hit = And(hit, MeetsCornerBox8(box_low, box_high, o, box_inverse, t));
  *t_max = Select(hit, t, *t_max);
  *normal = n;
  return hit;
}

// HitLanes4 (fused), eight lanes: the lanes hit closer than their t_max (or
// at it, in `ties`) take the distance; the (unnormalised) normals in *normal.
SANDBOX_KERNEL_INLINE __m256 HitLanes8(const V8 c[3], const V8& o, const V8& d,
                                       const V8& box_inverse, __m256 lanes, __m256 ties,
                                       __m256* t_max, V8* normal) {
  const V8 v0 = Sub(c[0], o), v1 = Sub(c[1], o), v2 = Sub(c[2], o);
  const V8 e0 = Sub(v2, v0), e1 = Sub(v0, v1), e2 = Sub(v1, v2);
  const __m256 u = Dot(Cross(e0, Add(v2, v0)), d);
  const __m256 v = Dot(Cross(e1, Add(v0, v1)), d);
  const __m256 w = Dot(Cross(e2, Add(v1, v2)), d);
  const __m256 hit = InsideEdges8(u, v, w, lanes);
  if (Bits(hit) == 0) return hit;
  const V8 n = StableNormal(e0, e1, e2);
  return HitPlane8(hit, c, n, Mul(Set(2.0f), Dot(v0, n)), o, d, box_inverse, ties, t_max, normal);
}

// packet_walk16.cc's LeafShared, ShareLeaf and HitShared16, eight lanes.
struct LeafShared {
  alignas(32) float corner[3][3][8];      // [corner][axis][triangle], Bullet frame
  alignas(32) float edge_cross[3][3][8];  // Cross(e_k, sum_k): [edge][axis][triangle]
  alignas(32) float normal[3][8];         // StableNormal(e0, e1, e2)
  alignas(32) float depth[8];             // 2 Dot(v0, normal)
};

SANDBOX_KERNEL_INLINE void ShareLeaf(const Target& target, const scene::TriangleBvh::Leaves& leaf,
                                     const V8& origin, LeafShared* shared) {
  constexpr int kLanes = scene::TriangleBvh::kWidth;
  static_assert(kLanes == 4, "a leaf's triangles fill half a vector");
  V8 c[3];
  if (target.identity) {
    for (int k = 0; k < 3; ++k) {
      auto load = [&](int a) {
        return _mm256_setr_m128(_mm_loadu_ps(leaf.corner[3 * k + a]), _mm_setzero_ps());
      };
      c[k] = {load(0), load(1), load(2)};
    }
  } else {
    alignas(32) float placed[3][3][8] = {};  // [corner][axis][triangle]
    for (int i = 0; i < kLanes; ++i) {
      Eigen::Vector3f corner[3];
      LeafCorners(target, leaf, i, corner);
      for (int k = 0; k < 3; ++k) {
        for (int a = 0; a < 3; ++a) placed[k][a][i] = corner[k][a];
      }
    }
    for (int k = 0; k < 3; ++k) {
      c[k] = {_mm256_load_ps(placed[k][0]), _mm256_load_ps(placed[k][1]),
              _mm256_load_ps(placed[k][2])};
    }
  }
  const V8 v0 = Sub(c[0], origin), v1 = Sub(c[1], origin), v2 = Sub(c[2], origin);
  const V8 e0 = Sub(v2, v0), e1 = Sub(v0, v1), e2 = Sub(v1, v2);
  const V8 cross[3] = {Cross(e0, Add(v2, v0)), Cross(e1, Add(v0, v1)), Cross(e2, Add(v1, v2))};
  const V8 n = StableNormal(e0, e1, e2);
  auto store = [](float* to, const V8& v) {
    _mm256_store_ps(to, v.x), _mm256_store_ps(to + 8, v.y), _mm256_store_ps(to + 16, v.z);
  };
  for (int k = 0; k < 3; ++k) {
    store(shared->corner[k][0], c[k]), store(shared->edge_cross[k][0], cross[k]);
  }
  store(shared->normal[0], n);
  _mm256_store_ps(shared->depth, Mul(Set(2.0f), Dot(v0, n)));
}

SANDBOX_KERNEL_INLINE __m256 HitShared8(const LeafShared& shared, int i, const V8& o, const V8& d,
                                        const V8& box_inverse, __m256 lanes, __m256 ties,
                                        __m256* t_max, V8* normal) {
  auto lane = [&](const float(*v)[8]) { return V8{Set(v[0][i]), Set(v[1][i]), Set(v[2][i])}; };
  const __m256 u = Dot(lane(shared.edge_cross[0]), d);
  const __m256 v = Dot(lane(shared.edge_cross[1]), d);
  const __m256 w = Dot(lane(shared.edge_cross[2]), d);
  const __m256 hit = InsideEdges8(u, v, w, lanes);
  if (Bits(hit) == 0) return hit;
  const V8 c[3] = {lane(shared.corner[0]), lane(shared.corner[1]), lane(shared.corner[2])};
  return HitPlane8(hit, c, lane(shared.normal), Set(shared.depth[i]), o, d, box_inverse, ties,
                   t_max, normal);
}

struct Packet8 {
  V8 o, d;         // Bullet frame
  V8 box_inverse;  // CornerBoxInverse(d)
  __m256 t_max;
  int active;       // lanes that hold a ray, a bit a lane
  bool one_origin;  // every lane's o the same, bit for bit (a still lidar's sweep)
  // Each lane's nearest hit so far: its surface and normal (Bullet frame, unnormalised).
  alignas(32) std::int32_t surface[8];
  alignas(32) float reflectivity[8];  // Target::ReflectivityOf the part hit
  alignas(32) float normal[3][8];
};

// The packet's nearest hits so far take those of `hit` (found by HitLanes8
// or HitShared8, normal n) on a triangle of `part` of `target`.
SANDBOX_KERNEL_INLINE void TakeHits8(__m256 hit, const V8& n, int surface_id, const Target& target,
                                     int part, Packet8* packet) {
  if (Bits(hit) == 0) return;
  const __m256i hit_i = _mm256_castps_si256(hit);
  _mm256_maskstore_epi32(packet->surface, hit_i, _mm256_set1_epi32(surface_id));
  _mm256_maskstore_ps(packet->reflectivity, hit_i, Set(target.ReflectivityOf(part)));
  _mm256_maskstore_ps(packet->normal[0], hit_i, n.x);
  _mm256_maskstore_ps(packet->normal[1], hit_i, n.y);
  _mm256_maskstore_ps(packet->normal[2], hit_i, n.z);
}
// The lanes that keep their hit on a tie with `surface_id` (a smaller id wins).
SANDBOX_KERNEL_INLINE __m256 Ties8(const Packet8& packet, int surface_id) {
  return _mm256_castsi256_ps(
      _mm256_cmpgt_epi32(_mm256_load_si256(reinterpret_cast<const __m256i*>(packet.surface)),
                         _mm256_set1_epi32(surface_id)));
}

// HitLanes8 for the packet's lanes against one triangle (corners in the
// Bullet frame) of `part` of `target`.
SANDBOX_KERNEL_INLINE void HitCorners8(const Eigen::Vector3f corner[3], int surface_id,
                                       const Target& target, int part, Packet8* packet,
                                       __m256 lanes, __m256* t_max) {
  V8 c[3];
  for (int k = 0; k < 3; ++k) c[k] = {Set(corner[k].x()), Set(corner[k].y()), Set(corner[k].z())};
  V8 n{};
  const __m256 hit = HitLanes8(c, packet->o, packet->d, packet->box_inverse, lanes,
                               Ties8(*packet, surface_id), t_max, &n);
  TakeHits8(hit, n, surface_id, target, part, packet);
}

// The lanes whose rays enter the box [lo, hi] (Bullet frame) before their
// t_max, a bit a lane.
inline int MeetsBox8(const Packet8& packet, const __m256 inverse[3], const Eigen::Vector3f& lo,
                     const Eigen::Vector3f& hi) {
  const __m256 o[3] = {packet.o.x, packet.o.y, packet.o.z};
  __m256 t_enter = _mm256_setzero_ps(), t_exit = packet.t_max;
  for (int k = 0; k < 3; ++k) {
    const __m256 t1 = Mul(Sub(Set(lo[k]), o[k]), inverse[k]);
    const __m256 t2 = Mul(Sub(Set(hi[k]), o[k]), inverse[k]);
    t_enter = Max(t_enter, Min(t1, t2));
    t_exit = Min(t_exit, Max(t1, t2));
  }
  return packet.active & Bits(Cmp<_CMP_LE_OS>(t_enter, t_exit));
}

// Eight consecutive (x, y, z) triples from `xyz`, as a vector per axis: the
// three loads blended so that each lane holds its axis's component of one
// triple, then put in order by one permute.
inline V8 Deinterleave(const float* xyz) {
  const __m256 a = _mm256_loadu_ps(xyz), b = _mm256_loadu_ps(xyz + 8);
  const __m256 c = _mm256_loadu_ps(xyz + 16);
  // x: floats 0 3 6 | 9 12 15 | 18 21 at lanes 0 3 6 of a, 1 4 7 of b, 2 5 of c.
  const __m256 x = _mm256_blend_ps(_mm256_blend_ps(a, b, 0x92), c, 0x24);
  // y: floats 1 4 7 | 10 13 | 16 19 22 at lanes 1 4 7 of a, 2 5 of b, 0 3 6 of c.
  const __m256 y = _mm256_blend_ps(_mm256_blend_ps(a, b, 0x24), c, 0x49);
  // z: floats 2 5 | 8 11 14 | 17 20 23 at lanes 2 5 of a, 0 3 6 of b, 1 4 7 of c.
  const __m256 z = _mm256_blend_ps(_mm256_blend_ps(a, b, 0x49), c, 0x92);
  return {_mm256_permutevar8x32_ps(x, _mm256_setr_epi32(0, 3, 6, 1, 4, 7, 2, 5)),
          _mm256_permutevar8x32_ps(y, _mm256_setr_epi32(1, 4, 7, 2, 5, 0, 3, 6)),
          _mm256_permutevar8x32_ps(z, _mm256_setr_epi32(2, 5, 0, 3, 6, 1, 4, 7))};
}
inline V8 Splat(const Eigen::Vector3f& v) { return {Set(v.x()), Set(v.y()), Set(v.z())}; }
// Whether every lane of x holds the same bits (+0 and -0 differ).
inline bool SameInEveryLane(__m256 x) {
  const __m256i bits = _mm256_castps_si256(x);
  const __m256i first = _mm256_permutevar8x32_epi32(bits, _mm256_setzero_si256());
  return _mm256_movemask_epi8(_mm256_cmpeq_epi32(bits, first)) == -1;
}

// x with every component of magnitude under 1e-30 moved to +-1e-30 (the
// inverse stays finite).
inline __m256 AwayFromZero8(__m256 x) {
  const __m256 tiny = Cmp<_CMP_LT_OS>(Abs(x), Set(1e-30f));
  const __m256 negative = Cmp<_CMP_LT_OS>(x, _mm256_setzero_ps());
  return Select(tiny, Select(negative, Set(-1e-30f), Set(1e-30f)), x);
}
// CornerBoxInverse(d) from the inverses of AwayFromZero8(d) (the same
// values wherever |d| >= 1e-30): divides only in a packet with tiny components.
inline V8 CornerBoxInverse(const V8& d, const __m256 away_inverse[3]) {
  const __m256 direction[3] = {d.x, d.y, d.z};
  __m256 inverse[3];
  for (int k = 0; k < 3; ++k) {
    const __m256 zero = Cmp<_CMP_EQ_OQ>(direction[k], _mm256_setzero_ps());
    const __m256 tiny = _mm256_andnot_ps(zero, Cmp<_CMP_LT_OS>(Abs(direction[k]), Set(1e-30f)));
    inverse[k] = away_inverse[k];
    if (Bits(tiny) != 0) {
      inverse[k] = Select(tiny, _mm256_div_ps(Set(1.0f), direction[k]), inverse[k]);
    }
    inverse[k] = Select(zero, Set(kHuge), inverse[k]);
  }
  return {inverse[0], inverse[1], inverse[2]};
}

// WalkWide16's walk, eight rays.
// (inverse_B: the packet's inverse directions in the Bullet frame.)
void WalkWide8(const Target& target, const __m256 inverse_B[3], Packet8* packet) {
  const scene::TriangleBvh& bvh = *target.bvh;
  if (bvh.root == scene::TriangleBvh::kEmpty) return;
  const Eigen::Matrix3f& R = target.R_LB;
  auto transform = [&](int row, const V8& v, float offset) {
    return Add(Add(Mul(Set(R(row, 0)), v.x), Mul(Set(R(row, 1)), v.y)),
               Add(Mul(Set(R(row, 2)), v.z), Set(offset)));
  };
  // As WalkWide16: per axis the inverse direction, origin times it, and
  // whether every ray runs the same way along it.
  const __m256 origin_B[3] = {packet->o.x, packet->o.y, packet->o.z};
  __m256 inverse[3], o_inverse[3];
  int sign[3];  // +1 all increasing, -1 all decreasing, 0 mixed
  for (int k = 0; k < 3; ++k) {
    inverse[k] = target.identity
                     ? inverse_B[k]
                     : _mm256_div_ps(Set(1.0f), AwayFromZero8(transform(k, packet->d, 0.0f)));
    o_inverse[k] =
        Mul(target.identity ? origin_B[k] : transform(k, packet->o, target.p_LB[k]), inverse[k]);
    const int positive = Bits(Cmp<_CMP_GT_OS>(inverse[k], _mm256_setzero_ps())) & packet->active;
    sign[k] = positive == packet->active ? 1 : positive == 0 ? -1 : 0;
  }
  // WalkWide16's growth and margin (the reasons are there).
  const __m256 grow = Set(1.0f + 8.0f * std::numeric_limits<float>::epsilon());
  __m256 at_lower[3], at_upper[3];
  for (int k = 0; k < 3; ++k) {
    const __m256 m_inverse = Mul(Set(target.box_margin), inverse[k]);
    at_lower[k] = Add(o_inverse[k], m_inverse), at_upper[k] = Sub(o_inverse[k], m_inverse);
  }
  __m256 t_max = packet->t_max;
  WalkStack<WalkEntry, kStackInPlace> stack;
  stack.Push({bvh.root, std::uint32_t(packet->active)});
  while (!stack.empty()) {
    const WalkEntry entry = stack.Pop();
    const int lane_bits = int(entry.lanes());
    if (entry.ref() < 0) {
      const __m256 lanes = LaneMask(lane_bits);
      const scene::TriangleBvh::Leaves& leaf = bvh.leaves[std::size_t(-1 - entry.ref())];
      if (packet->one_origin) {
        LeafShared shared;
        ShareLeaf(target, leaf, packet->o, &shared);
        for (int i = 0; i < leaf.count; ++i) {
          const int surface_id = target.SurfaceOf(leaf.part[i]);
          V8 n{};
          const __m256 hit = HitShared8(shared, i, packet->o, packet->d, packet->box_inverse, lanes,
                                        Ties8(*packet, surface_id), &t_max, &n);
          TakeHits8(hit, n, surface_id, target, leaf.part[i], packet);
        }
        continue;
      }
      for (int i = 0; i < leaf.count; ++i) {
        Eigen::Vector3f corner[3];
        LeafCorners(target, leaf, i, corner);
        HitCorners8(corner, target.SurfaceOf(leaf.part[i]), target, leaf.part[i], packet, lanes,
                    &t_max);
      }
      continue;
    }
    const scene::TriangleBvh::Node& node = bvh.nodes[std::size_t(entry.ref())];
    WalkEntry children[scene::TriangleBvh::kWidth];
    float nearest[scene::TriangleBvh::kWidth];
    // The four children's slabs first, then the entered ones kept in order.
    __m256 near[scene::TriangleBvh::kWidth];
    int enter[scene::TriangleBvh::kWidth];
    for (int c = 0; c < scene::TriangleBvh::kWidth; ++c) {
      __m256 far = t_max;
      near[c] = _mm256_setzero_ps();
      for (int a = 0; a < 3; ++a) {
        const __m256 t0 = _mm256_fmsub_ps(Set(node.lower[a][c]), inverse[a], at_lower[a]);
        const __m256 t1 = _mm256_fmsub_ps(Set(node.upper[a][c]), inverse[a], at_upper[a]);
        if (sign[a] > 0) {
          near[c] = Max(near[c], t0), far = Min(far, t1);
        } else if (sign[a] < 0) {
          near[c] = Max(near[c], t1), far = Min(far, t0);
        } else {
          near[c] = Max(near[c], Min(t0, t1)), far = Min(far, Max(t0, t1));
        }
      }
      enter[c] = lane_bits & Bits(Cmp<_CMP_LE_OS>(near[c], Mul(far, grow)));
    }
    int count = 0;
    for (int c = 0; c < scene::TriangleBvh::kWidth; ++c) {
      if (enter[c] == 0 || node.child[c] == scene::TriangleBvh::kEmpty) continue;
      // Ordered by the first lane that enters.
      alignas(32) float entries[8];
      _mm256_store_ps(entries, near[c]);
      nearest[count] = entries[__builtin_ctz(unsigned(enter[c]))];
      children[count++] = WalkEntry(node.child[c], std::uint32_t(enter[c]));
    }
    // Farthest pushed first: the nearest is walked first.
    for (int k = 1; k < count; ++k) {
      for (int j = k; j > 0 && nearest[j - 1] < nearest[j]; --j) {
        std::swap(nearest[j - 1], nearest[j]);
        std::swap(children[j - 1], children[j]);
      }
    }
    for (int k = 0; k < count; ++k) stack.Push(children[k]);
  }
  packet->t_max = t_max;
}

}  // namespace

// Eight rays at a time.
void CastRays(const RayBatch& rays, const Eigen::Vector3f& origin_B, std::size_t first,
              std::size_t end, const Target* const* targets, std::size_t num_targets,
              RayHits* hits) {
  for (std::size_t i = first; i < end; i += 8) {
    Packet8 packet;
    const bool full = i + 8 <= end;
    if (full) {
      // Eight x, y, z triples in three loads, sorted into x, y and z.
      packet.o = Add(Splat(origin_B), Deinterleave(rays.start[i].data()));
      packet.d = Deinterleave(rays.direction[i].data());
      packet.t_max = _mm256_loadu_ps(&rays.length_m[i]);
      packet.active = 0xFF;
    } else {
      alignas(32) float lane[7][8];
      int active = 0;
      for (int l = 0; l < 8; ++l) {
        const std::size_t r = std::min(i + std::size_t(l), end - 1);
        const Eigen::Vector3f o = origin_B + rays.start[r];
        lane[0][l] = o.x(), lane[1][l] = o.y(), lane[2][l] = o.z();
        lane[3][l] = rays.direction[r].x(), lane[4][l] = rays.direction[r].y();
        lane[5][l] = rays.direction[r].z(), lane[6][l] = rays.length_m[r];
        if (i + std::size_t(l) < end) active |= 1 << l;
      }
      packet.o = {_mm256_load_ps(lane[0]), _mm256_load_ps(lane[1]), _mm256_load_ps(lane[2])};
      packet.d = {_mm256_load_ps(lane[3]), _mm256_load_ps(lane[4]), _mm256_load_ps(lane[5])};
      packet.t_max = _mm256_load_ps(lane[6]);
      packet.active = active;
    }
    packet.one_origin =
        SameInEveryLane(packet.o.x) && SameInEveryLane(packet.o.y) && SameInEveryLane(packet.o.z);
    const __m256 inverse[3] = {_mm256_div_ps(Set(1.0f), AwayFromZero8(packet.d.x)),
                               _mm256_div_ps(Set(1.0f), AwayFromZero8(packet.d.y)),
                               _mm256_div_ps(Set(1.0f), AwayFromZero8(packet.d.z))};
    packet.box_inverse = CornerBoxInverse(packet.d, inverse);
    for (int l = 0; l < 8; ++l) packet.surface[l] = RayHits::kNoHit;
    WalkTargetsMet(
        targets, num_targets,
        [&](const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
          return MeetsBox8(packet, inverse, lo, hi);
        },
        [&](const Target& target) { WalkWide8(target, inverse, &packet); });
    if (full && !hits->with_normals && !hits->with_reflectivity) {  // WriteHit's two stores
      _mm256_storeu_ps(&hits->distance_m[i], packet.t_max);
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(&hits->surface[i]),
                          _mm256_load_si256(reinterpret_cast<const __m256i*>(packet.surface)));
      continue;
    }
    alignas(32) float t_max[8];
    _mm256_store_ps(t_max, packet.t_max);
    for (int l = 0; l < 8 && i + std::size_t(l) < end; ++l) {
      const std::size_t r = i + std::size_t(l);
      const Eigen::Vector3f normal(packet.normal[0][l], packet.normal[1][l], packet.normal[2][l]);
      WriteHit(r, t_max[l], packet.surface[l], packet.reflectivity[l], normal, rays.direction[r],
               hits);
    }
  }
}

namespace {

// The vectors at xyz (indexes of their x) of an array of them, in `lanes`.
inline V8 Gather(const float* base, __m256 lanes, __m256i xyz) {
  const __m256 zero = _mm256_setzero_ps();
  return {_mm256_mask_i32gather_ps(zero, base, xyz, lanes, 4),
          _mm256_mask_i32gather_ps(zero, base + 1, xyz, lanes, 4),
          _mm256_mask_i32gather_ps(zero, base + 2, xyz, lanes, 4)};
}

}  // namespace

// packet_walk4.cc's HitPairs, eight pairs a test: the same lanes, the same
// bits, the same order of taking the hits.
void HitPairs(GridBand* band) {
  GridBand::Pairs& pairs = band->pairs;
  float* t = band->t_max;
  std::int32_t* surface = band->surface;
  const float* start = band->start[0].data();
  const V8 origin{Set(_mm_cvtss_f32(band->ox)), Set(_mm_cvtss_f32(band->oy)),
                  Set(_mm_cvtss_f32(band->oz))};
  const V8 d{Set(_mm_cvtss_f32(band->dx)), Set(_mm_cvtss_f32(band->dy)),
             Set(_mm_cvtss_f32(band->dz))};
  const V8 box_inverse = CornerBoxInverse(d);
  const __m256i lane_index = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (int k = 0; k < pairs.count; k += 8) {
    const int in_packet = std::min(8, pairs.count - k);
    const __m256i in_packet_i = _mm256_cmpgt_epi32(_mm256_set1_epi32(in_packet), lane_index);
    const __m256i cell = _mm256_maskload_epi32(&pairs.cell[k], in_packet_i);
    __m256 t_max =
        _mm256_mask_i32gather_ps(_mm256_setzero_ps(), t, cell, _mm256_castsi256_ps(in_packet_i), 4);
    const __m256 lanes = And(_mm256_castsi256_ps(in_packet_i),
                             Cmp<_CMP_GT_OQ>(t_max, _mm256_loadu_ps(&pairs.near[k])));
    if (Bits(lanes) == 0) continue;
    // Each origin as Cast() forms it: the batch origin plus the ray's start.
    const __m256i xyz = _mm256_mullo_epi32(cell, _mm256_set1_epi32(3));
    const V8 o = Add(origin, Gather(start, lanes, xyz));
    V8 c[3];
    for (int j = 0; j < 3; ++j) {
      c[j] = {_mm256_loadu_ps(&pairs.corner[3 * j][k]),
              _mm256_loadu_ps(&pairs.corner[3 * j + 1][k]),
              _mm256_loadu_ps(&pairs.corner[3 * j + 2][k])};
    }
    const __m256i pair_surface = _mm256_maskload_epi32(&pairs.surface[k], in_packet_i);
    const __m256i ray_surface = _mm256_mask_i32gather_epi32(_mm256_setzero_si256(), surface, cell,
                                                            _mm256_castps_si256(lanes), 4);
    const __m256 ties = _mm256_castsi256_ps(_mm256_cmpgt_epi32(ray_surface, pair_surface));
    V8 n{};
    const int hit = Bits(HitLanes8(c, o, d, box_inverse, lanes, ties, &t_max, &n));
    if (hit == 0) continue;
    alignas(32) float t_hit[8], nx[8], ny[8], nz[8];
    alignas(32) std::int32_t cells[8];
    _mm256_store_ps(t_hit, t_max);
    _mm256_store_si256(reinterpret_cast<__m256i*>(cells), cell);
    if (band->normal != nullptr) {
      n = FacingUnits8(n, d);
      _mm256_store_ps(nx, n.x), _mm256_store_ps(ny, n.y), _mm256_store_ps(nz, n.z);
    }
    // In lane order, as the pairs one by one: the nearer hit stays.
    for (unsigned rest = unsigned(hit); rest != 0; rest &= rest - 1) {
      const int lane = __builtin_ctz(rest);
      const auto i = std::size_t(cells[lane]);
      const int pair_surface_id = pairs.surface[k + lane];
      if (!(t_hit[lane] < t[i] || (t_hit[lane] == t[i] && pair_surface_id < surface[i]))) continue;
      t[i] = t_hit[lane];
      surface[i] = pair_surface_id;
      if (band->normal != nullptr) band->normal[i] = Eigen::Vector3f(nx[lane], ny[lane], nz[lane]);
    }
  }
  pairs.count = 0;
}

const RayKernel kKernel{SANDBOX_ISA_NAME, CastRays, HitPairs};

}  // namespace sandbox::sensors::SANDBOX_ISA
