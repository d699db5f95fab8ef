// The packet kernel of sixteen rays (sensors/ray_kernels.h), for CPUs with
// AVX-512: the walk of the objects' own hierarchies (packet_walk4.cc's
// WalkWide4) and the fused watertight triangle test (its HitLanes4 as built
// for fma, operation for operation, sixteen lanes wide: the same bits in
// every lane). Built once, with -mavx512f -mavx512dq (namespace avx512).
// Its own code, not packet_walk4.cc's made wide: its masks are registers of
// their own and it loads sixteen rays by permutes (docs/decisions/005). A
// packet whose rays start at one point tests a leaf's triangles from terms
// computed once for the leaf (ShareLeaf).

#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "sensors/ray_kernels.h"
#include "sensors/walk_stack.h"

namespace sandbox::sensors::SANDBOX_ISA {
namespace {

struct V16 {  // a vector per lane
  __m512 x, y, z;
};
inline __m512 Set(float v) { return _mm512_set1_ps(v); }
inline __m512 Mul(__m512 a, __m512 b) { return _mm512_mul_ps(a, b); }
inline __m512 Add(__m512 a, __m512 b) { return _mm512_add_ps(a, b); }
inline __m512 Sub(__m512 a, __m512 b) { return _mm512_sub_ps(a, b); }
inline V16 Sub(const V16& a, const V16& b) { return {Sub(a.x, b.x), Sub(a.y, b.y), Sub(a.z, b.z)}; }
inline V16 Add(const V16& a, const V16& b) { return {Add(a.x, b.x), Add(a.y, b.y), Add(a.z, b.z)}; }
// (GCC 12 warns of the unmasked min, max and and-not's undefined source: the
// all-lanes zero-masked forms are the same operations.)
inline __m512 Min(__m512 a, __m512 b) { return _mm512_maskz_min_ps(0xFFFF, a, b); }
inline __m512 Max(__m512 a, __m512 b) { return _mm512_maskz_max_ps(0xFFFF, a, b); }
inline __m512 Abs(__m512 x) {
  return _mm512_castsi512_ps(
      _mm512_maskz_andnot_epi32(0xFFFF, _mm512_castps_si512(Set(-0.0f)), _mm512_castps_si512(x)));
}
// a where the mask is set, b elsewhere.
inline __m512 Select(__mmask16 mask, __m512 a, __m512 b) {
  return _mm512_mask_blend_ps(mask, b, a);
}
inline __m512 Dot(const V16& a, const V16& b) {
  return _mm512_fmadd_ps(a.x, b.x, _mm512_fmadd_ps(a.y, b.y, Mul(a.z, b.z)));
}
inline V16 Cross(const V16& a, const V16& b) {
  return {_mm512_fmsub_ps(a.y, b.z, Mul(a.z, b.y)), _mm512_fmsub_ps(a.z, b.x, Mul(a.x, b.z)),
          _mm512_fmsub_ps(a.x, b.y, Mul(a.y, b.x))};
}
// StableNormal4<true>.
inline V16 StableNormal(const V16& a, const V16& b, const V16& c) {
  const __m512 ab_x = Mul(a.z, b.y), ab_y = Mul(a.x, b.z), ab_z = Mul(a.y, b.x);
  const __m512 bc_x = Mul(b.z, c.y), bc_y = Mul(b.x, c.z), bc_z = Mul(b.y, c.x);
  auto less = [](__m512 p, __m512 q) { return _mm512_cmp_ps_mask(Abs(p), Abs(q), _CMP_LT_OS); };
  return {
      Select(less(ab_x, bc_x), _mm512_fmsub_ps(a.y, b.z, ab_x), _mm512_fmsub_ps(b.y, c.z, bc_x)),
      Select(less(ab_y, bc_y), _mm512_fmsub_ps(a.z, b.x, ab_y), _mm512_fmsub_ps(b.z, c.x, bc_y)),
      Select(less(ab_z, bc_z), _mm512_fmsub_ps(a.x, b.y, ab_z), _mm512_fmsub_ps(b.x, c.y, bc_z))};
}
// The unit normals along n facing rays along d (FacingUnits4, sixteen
// lanes; the estimate to 2^-14 and one Newton step).
inline V16 FacingUnits16(const V16& n, const V16& d) {
  const __m512 n2 = Dot(n, n);
  const __m512 r0 = _mm512_maskz_rsqrt14_ps(0xFFFF, n2);  // (as Min: GCC 12)
  // r = r0 (3 - n2 r0^2) / 2, negated where n runs along d.
  __m512 scale = Mul(Mul(Set(0.5f), r0), _mm512_fnmadd_ps(Mul(n2, r0), r0, Set(3.0f)));
  const __mmask16 along = _mm512_cmp_ps_mask(Dot(n, d), _mm512_setzero_ps(), _CMP_GT_OQ);
  scale = _mm512_mask_sub_ps(scale, along, _mm512_setzero_ps(), scale);
  return {Mul(n.x, scale), Mul(n.y, scale), Mul(n.z, scale)};
}
// MeetsCornerBox's inverse directions: a zero component counts as an
// infinitesimally positive one.
inline V16 CornerBoxInverse(const V16& d) {
  const __m512 direction[3] = {d.x, d.y, d.z};
  __m512 inverse[3];
  for (int k = 0; k < 3; ++k) {
    const __mmask16 zero = _mm512_cmp_ps_mask(direction[k], _mm512_setzero_ps(), _CMP_EQ_OQ);
    inverse[k] = Select(zero, Set(kHuge), _mm512_div_ps(Set(1.0f), direction[k]));
  }
  return {inverse[0], inverse[1], inverse[2]};
}
// MeetsCornerBox4, sixteen lanes (inverse: CornerBoxInverse of the directions).
inline __mmask16 MeetsCornerBox16(const V16& low, const V16& high, const V16& o,
                                  const V16& inverse_d, __m512 t) {
  const __m512 origin[3] = {o.x, o.y, o.z}, inverse[3] = {inverse_d.x, inverse_d.y, inverse_d.z};
  const __m512 lo[3] = {low.x, low.y, low.z}, hi[3] = {high.x, high.y, high.z};
  __m512 t_enter = _mm512_setzero_ps(), t_exit = t;
  for (int k = 0; k < 3; ++k) {
    const __m512 t1 = Mul(Sub(lo[k], origin[k]), inverse[k]);
    const __m512 t2 = Mul(Sub(hi[k], origin[k]), inverse[k]);
    t_enter = Max(t_enter, Min(t1, t2));
    t_exit = Min(t_exit, Max(t1, t2));
  }
  const float slack = 2.0f * std::numeric_limits<float>::epsilon();
  return _mm512_cmp_ps_mask(Mul(t_enter, Set(1.0f - slack)), Mul(t_exit, Set(1.0f + slack)),
                            _CMP_LE_OS);
}

// The lanes of `lanes` whose ray passes inside or on the triangle's three
// edges (u, v, w: the edges' signed volumes with the ray).
SANDBOX_KERNEL_INLINE __mmask16 InsideEdges16(__m512 u, __m512 v, __m512 w, __mmask16 lanes) {
  const __m512 eps = Mul(Set(std::numeric_limits<float>::epsilon()), Abs(Add(Add(u, v), w)));
  const __m512 low = Min(Min(u, v), w);
  const __m512 high = Max(Max(u, v), w);
  return lanes & (_mm512_cmp_ps_mask(low, Sub(_mm512_setzero_ps(), eps), _CMP_GE_OS) |
                  _mm512_cmp_ps_mask(high, eps, _CMP_LE_OS));
}

// The rest of the test for the lanes in `hit`: the plane's distance (n its
// normal, depth twice the dot of corner 0 from the origin with n), then the
// triangle's box; those closer than their t_max (or at it, in `ties`) take it.
SANDBOX_KERNEL_INLINE __mmask16 HitPlane16(__mmask16 hit, const V16 c[3], const V16& n,
                                           __m512 depth, const V16& o, const V16& d,
                                           const V16& box_inverse, __mmask16 ties, __m512* t_max,
                                           V16* normal) {
  const __m512 den = Mul(Set(2.0f), Dot(n, d));
  const __m512 t = _mm512_div_ps(depth, den);
  hit &= _mm512_cmp_ps_mask(den, _mm512_setzero_ps(), _CMP_NEQ_UQ);
  hit &= _mm512_cmp_ps_mask(t, _mm512_setzero_ps(), _CMP_GE_OS);
  hit &= _mm512_cmp_ps_mask(t, *t_max, _CMP_LT_OS) |
         (ties & _mm512_cmp_ps_mask(t, *t_max, _CMP_EQ_OQ));
  if (hit == 0) return hit;
  // (MeetsCornerBox: the segment up to the hit meets the triangle's box.)
  const V16 box_low{Min(Min(c[0].x, c[1].x), c[2].x), Min(Min(c[0].y, c[1].y), c[2].y),
                    Min(Min(c[0].z, c[1].z), c[2].z)};
  const V16 box_high{Max(Max(c[0].x, c[1].x), c[2].x), Max(Max(c[0].y, c[1].y), c[2].y),
                     Max(Max(c[0].z, c[1].z), c[2].z)};
  hit &= MeetsCornerBox16(box_low, box_high, o, box_inverse, t);
  *t_max = Select(hit, t, *t_max);
  *normal = n;
  return hit;
}

// HitLanes4 (fused), sixteen lanes: the lanes hit closer than their t_max
// (or at it, in `ties`) take the distance; the (unnormalised) normals in *normal.
SANDBOX_KERNEL_INLINE __mmask16 HitLanes16(const V16 c[3], const V16& o, const V16& d,
                                           const V16& box_inverse, __mmask16 lanes, __mmask16 ties,
                                           __m512* t_max, V16* normal) {
  const V16 v0 = Sub(c[0], o), v1 = Sub(c[1], o), v2 = Sub(c[2], o);
  const V16 e0 = Sub(v2, v0), e1 = Sub(v0, v1), e2 = Sub(v1, v2);
  const __m512 u = Dot(Cross(e0, Add(v2, v0)), d);
  const __m512 v = Dot(Cross(e1, Add(v0, v1)), d);
  const __m512 w = Dot(Cross(e2, Add(v1, v2)), d);
  const __mmask16 hit = InsideEdges16(u, v, w, lanes);
  if (hit == 0) return hit;
  const V16 n = StableNormal(e0, e1, e2);
  return HitPlane16(hit, c, n, Mul(Set(2.0f), Dot(v0, n)), o, d, box_inverse, ties, t_max, normal);
}

// What HitLanes16 computes from the corners and the origin alone, for the
// triangles of a leaf at once (a lane a triangle), when every lane of the
// packet starts at one origin: per lane, the same operations on the same
// values, so the same bits. Per lane then only the products with the
// direction are left (HitShared16).
struct LeafShared {
  alignas(64) float corner[3][3][16];      // [corner][axis][triangle], Bullet frame
  alignas(64) float edge_cross[3][3][16];  // Cross(e_k, sum_k): [edge][axis][triangle]
  alignas(64) float normal[3][16];         // StableNormal(e0, e1, e2)
  alignas(64) float depth[16];             // 2 Dot(v0, normal)
};

// Fills *shared for the leaf's triangles (lanes past `count` repeat the last).
SANDBOX_KERNEL_INLINE void ShareLeaf(const Target& target, const scene::TriangleBvh::Leaves& leaf,
                                     const V16& origin, LeafShared* shared) {
  constexpr int kLanes = scene::TriangleBvh::kWidth;
  static_assert(kLanes <= 16, "a leaf's triangles fit in a vector");
  const __mmask16 in_leaf = __mmask16((1u << kLanes) - 1u);
  V16 c[3];
  if (target.identity) {
    for (int k = 0; k < 3; ++k) {
      c[k] = {_mm512_maskz_loadu_ps(in_leaf, leaf.corner[3 * k]),
              _mm512_maskz_loadu_ps(in_leaf, leaf.corner[3 * k + 1]),
              _mm512_maskz_loadu_ps(in_leaf, leaf.corner[3 * k + 2])};
    }
  } else {
    alignas(64) float placed[3][3][16] = {};  // [corner][axis][triangle]
    for (int i = 0; i < kLanes; ++i) {
      Eigen::Vector3f corner[3];
      LeafCorners(target, leaf, i, corner);
      for (int k = 0; k < 3; ++k) {
        for (int a = 0; a < 3; ++a) placed[k][a][i] = corner[k][a];
      }
    }
    for (int k = 0; k < 3; ++k) {
      c[k] = {_mm512_load_ps(placed[k][0]), _mm512_load_ps(placed[k][1]),
              _mm512_load_ps(placed[k][2])};
    }
  }
  const V16 v0 = Sub(c[0], origin), v1 = Sub(c[1], origin), v2 = Sub(c[2], origin);
  const V16 e0 = Sub(v2, v0), e1 = Sub(v0, v1), e2 = Sub(v1, v2);
  const V16 cross[3] = {Cross(e0, Add(v2, v0)), Cross(e1, Add(v0, v1)), Cross(e2, Add(v1, v2))};
  const V16 n = StableNormal(e0, e1, e2);
  auto store = [](float* to, const V16& v) {
    _mm512_store_ps(to, v.x), _mm512_store_ps(to + 16, v.y), _mm512_store_ps(to + 32, v.z);
  };
  for (int k = 0; k < 3; ++k)
    store(shared->corner[k][0], c[k]), store(shared->edge_cross[k][0], cross[k]);
  store(shared->normal[0], n);
  _mm512_store_ps(shared->depth, Mul(Set(2.0f), Dot(v0, n)));
}

// HitLanes16 for triangle i of a shared leaf.
SANDBOX_KERNEL_INLINE __mmask16 HitShared16(const LeafShared& shared, int i, const V16& o,
                                            const V16& d, const V16& box_inverse, __mmask16 lanes,
                                            __mmask16 ties, __m512* t_max, V16* normal) {
  auto lane = [&](const float(*v)[16]) { return V16{Set(v[0][i]), Set(v[1][i]), Set(v[2][i])}; };
  const __m512 u = Dot(lane(shared.edge_cross[0]), d);
  const __m512 v = Dot(lane(shared.edge_cross[1]), d);
  const __m512 w = Dot(lane(shared.edge_cross[2]), d);
  const __mmask16 hit = InsideEdges16(u, v, w, lanes);
  if (hit == 0) return hit;
  const V16 c[3] = {lane(shared.corner[0]), lane(shared.corner[1]), lane(shared.corner[2])};
  return HitPlane16(hit, c, lane(shared.normal), Set(shared.depth[i]), o, d, box_inverse, ties,
                    t_max, normal);
}

struct Packet16 {
  V16 o, d;         // Bullet frame
  V16 box_inverse;  // CornerBoxInverse(d)
  __m512 t_max;
  __mmask16 active;  // lanes that hold a ray
  bool one_origin;   // every lane's o the same, bit for bit (a still lidar's sweep)
  // Each lane's nearest hit so far: its surface and normal (Bullet frame, unnormalised).
  alignas(64) std::int32_t surface[16];
  alignas(64) float reflectivity[16];  // Target::ReflectivityOf the part hit
  alignas(64) float normal[3][16];
};

// The packet's nearest hits so far take those of `hit` (found by HitLanes16
// or HitShared16, normal n) on a triangle of `part` of `target`.
SANDBOX_KERNEL_INLINE void TakeHits16(__mmask16 hit, const V16& n, int surface_id,
                                      const Target& target, int part, Packet16* packet) {
  if (hit == 0) return;
  _mm512_mask_store_epi32(packet->surface, hit, _mm512_set1_epi32(surface_id));
  _mm512_mask_store_ps(packet->reflectivity, hit, Set(target.ReflectivityOf(part)));
  _mm512_mask_store_ps(packet->normal[0], hit, n.x);
  _mm512_mask_store_ps(packet->normal[1], hit, n.y);
  _mm512_mask_store_ps(packet->normal[2], hit, n.z);
}
// The lanes that keep their hit on a tie with `surface_id` (a smaller id wins).
SANDBOX_KERNEL_INLINE __mmask16 Ties16(const Packet16& packet, int surface_id) {
  return _mm512_cmpgt_epi32_mask(_mm512_load_si512(packet.surface), _mm512_set1_epi32(surface_id));
}

// HitLanes16 for the packet's lanes against one triangle (corners in the
// Bullet frame) of `part` of `target`.
SANDBOX_KERNEL_INLINE void HitCorners16(const Eigen::Vector3f corner[3], int surface_id,
                                        const Target& target, int part, Packet16* packet,
                                        __mmask16 lanes, __m512* t_max) {
  V16 c[3];
  for (int k = 0; k < 3; ++k) c[k] = {Set(corner[k].x()), Set(corner[k].y()), Set(corner[k].z())};
  V16 n;
  const __mmask16 hit = HitLanes16(c, packet->o, packet->d, packet->box_inverse, lanes,
                                   Ties16(*packet, surface_id), t_max, &n);
  TakeHits16(hit, n, surface_id, target, part, packet);
}

// The lanes whose rays enter the box [lo, hi] (Bullet frame) before their t_max.
inline __mmask16 MeetsBox16(const Packet16& packet, const __m512 inverse[3],
                            const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  const __m512 o[3] = {packet.o.x, packet.o.y, packet.o.z};
  __m512 t_enter = _mm512_setzero_ps(), t_exit = packet.t_max;
  for (int k = 0; k < 3; ++k) {
    const __m512 t1 = Mul(Sub(Set(lo[k]), o[k]), inverse[k]);
    const __m512 t2 = Mul(Sub(Set(hi[k]), o[k]), inverse[k]);
    t_enter = Max(t_enter, Min(t1, t2));
    t_exit = Min(t_exit, Max(t1, t2));
  }
  return packet.active & _mm512_cmp_ps_mask(t_enter, t_exit, _CMP_LE_OS);
}

// Sixteen consecutive (x, y, z) triples from `xyz`, as a vector per axis:
// component k of triple l is float 3 l + k of the three loads a (floats
// 0-15), b (16-31) and c (32-47); picked from a and b as one table of 32,
// then those past b replaced from c.
struct DeinterleaveIndex {
  std::int32_t from_ab[3][16], from_abc[3][16];
};
constexpr DeinterleaveIndex MakeDeinterleaveIndex() {
  DeinterleaveIndex index{};
  for (int k = 0; k < 3; ++k) {
    for (int l = 0; l < 16; ++l) {
      const int at = 3 * l + k;
      index.from_ab[k][l] = at < 32 ? at : 0;
      index.from_abc[k][l] = at < 32 ? l : 16 + (at - 32);
    }
  }
  return index;
}
alignas(64) constexpr DeinterleaveIndex kDeinterleave = MakeDeinterleaveIndex();
inline V16 Deinterleave(const float* xyz) {
  const __m512 a = _mm512_loadu_ps(xyz), b = _mm512_loadu_ps(xyz + 16);
  const __m512 c = _mm512_loadu_ps(xyz + 32);
  V16 v;
  __m512* out[3] = {&v.x, &v.y, &v.z};
  for (int k = 0; k < 3; ++k) {
    const __m512 ab = _mm512_permutex2var_ps(a, _mm512_load_si512(kDeinterleave.from_ab[k]), b);
    *out[k] = _mm512_permutex2var_ps(ab, _mm512_load_si512(kDeinterleave.from_abc[k]), c);
  }
  return v;
}
inline V16 Splat(const Eigen::Vector3f& v) { return {Set(v.x()), Set(v.y()), Set(v.z())}; }
// Whether every lane of x holds the same bits (+0 and -0 differ).
inline bool SameInEveryLane(__m512 x) {
  const __m512i bits = _mm512_castps_si512(x);
  const __m512i first = _mm512_maskz_permutexvar_epi32(0xFFFF, _mm512_setzero_si512(), bits);
  return _mm512_cmpeq_epi32_mask(bits, first) == 0xFFFF;
}

// x with every component of magnitude under 1e-30 moved to +-1e-30 (the
// inverse stays finite).
inline __m512 AwayFromZero16(__m512 x) {
  const __mmask16 tiny = _mm512_cmp_ps_mask(Abs(x), Set(1e-30f), _CMP_LT_OS);
  const __mmask16 negative = _mm512_cmp_ps_mask(x, _mm512_setzero_ps(), _CMP_LT_OS);
  return Select(tiny, Select(negative, Set(-1e-30f), Set(1e-30f)), x);
}
// CornerBoxInverse(d) from the inverses of AwayFromZero16(d) (the same
// values wherever |d| >= 1e-30): divides only in a packet with tiny components.
inline V16 CornerBoxInverse(const V16& d, const __m512 away_inverse[3]) {
  const __m512 direction[3] = {d.x, d.y, d.z};
  __m512 inverse[3];
  for (int k = 0; k < 3; ++k) {
    const __mmask16 zero = _mm512_cmp_ps_mask(direction[k], _mm512_setzero_ps(), _CMP_EQ_OQ);
    const __mmask16 tiny = _mm512_cmp_ps_mask(Abs(direction[k]), Set(1e-30f), _CMP_LT_OS) & ~zero;
    inverse[k] = away_inverse[k];
    if (tiny != 0) inverse[k] = Select(tiny, _mm512_div_ps(Set(1.0f), direction[k]), inverse[k]);
    inverse[k] = Select(zero, Set(kHuge), inverse[k]);
  }
  return {inverse[0], inverse[1], inverse[2]};
}

// WalkWide4's walk, sixteen rays.
// (inverse_B: the packet's inverse directions in the Bullet frame.)
void WalkWide16(const Target& target, const __m512 inverse_B[3], Packet16* packet) {
  const scene::TriangleBvh& bvh = *target.bvh;
  if (bvh.root == scene::TriangleBvh::kEmpty) return;
  const Eigen::Matrix3f& R = target.R_LB;
  auto transform = [&](int row, const V16& v, float offset) {
    return Add(Add(Mul(Set(R(row, 0)), v.x), Mul(Set(R(row, 1)), v.y)),
               Add(Mul(Set(R(row, 2)), v.z), Set(offset)));
  };
  // Per axis: the rays' inverse direction and origin times it (a slab's
  // distance is then one fused operation), and whether every ray runs the
  // same way along it (then which of a box's planes it enters by is known).
  // In an object placed at the identity, the Bullet frame's (the transform
  // would give the same values: 1 x + 0 y + 0 z + 0).
  const __m512 origin_B[3] = {packet->o.x, packet->o.y, packet->o.z};
  __m512 inverse[3], o_inverse[3];
  int sign[3];  // +1 all increasing, -1 all decreasing, 0 mixed
  for (int k = 0; k < 3; ++k) {
    inverse[k] = target.identity
                     ? inverse_B[k]
                     : _mm512_div_ps(Set(1.0f), AwayFromZero16(transform(k, packet->d, 0.0f)));
    o_inverse[k] =
        Mul(target.identity ? origin_B[k] : transform(k, packet->o, target.p_LB[k]), inverse[k]);
    const __mmask16 positive = _mm512_cmp_ps_mask(inverse[k], _mm512_setzero_ps(), _CMP_GT_OS);
    sign[k] = (positive & packet->active) == packet->active ? 1
              : (positive & packet->active) == 0            ? -1
                                                            : 0;
  }
  // A box is entered where near (1 - 2 ulps) <= far (1 + 2 ulps); tested as
  // near <= far (1 + 8 ulps), which passes wherever that does (the products'
  // rounding included) for one multiplication less.
  const __m512 grow = Set(1.0f + 8.0f * std::numeric_limits<float>::epsilon());
  // A box grown by the margin m: the slabs' distances (lower - m - o) i and
  // (upper + m - o) i as one fused operation each, lower i - (o i + m i) and
  // upper i - (o i - m i). Their rounding, a few ulps of o i, is inside the
  // margin for origins within the object's scale, and inside the distances'
  // growth of the distances (`grow`) for origins beyond a few times it:
  // rays from up to 30 km at a 12 m room's edges hit with box tests as they
  // do with none (tried on all three kernels; without the margin and the
  // growth, 0.8-6.5% of them differed).
  __m512 at_lower[3], at_upper[3];
  for (int k = 0; k < 3; ++k) {
    const __m512 m_inverse = Mul(Set(target.box_margin), inverse[k]);
    at_lower[k] = Add(o_inverse[k], m_inverse), at_upper[k] = Sub(o_inverse[k], m_inverse);
  }
  __m512 t_max = packet->t_max;
  WalkStack<WalkEntry, kStackInPlace> stack;
  stack.Push({bvh.root, packet->active});
  while (!stack.empty()) {
    const WalkEntry entry = stack.Pop();
    const __mmask16 lanes = __mmask16(entry.lanes());
    if (entry.ref() < 0) {
      const scene::TriangleBvh::Leaves& leaf = bvh.leaves[std::size_t(-1 - entry.ref())];
      if (packet->one_origin) {
        LeafShared shared;
        ShareLeaf(target, leaf, packet->o, &shared);
        for (int i = 0; i < leaf.count; ++i) {
          const int surface_id = target.SurfaceOf(leaf.part[i]);
          V16 n;
          const __mmask16 hit = HitShared16(shared, i, packet->o, packet->d, packet->box_inverse,
                                            lanes, Ties16(*packet, surface_id), &t_max, &n);
          TakeHits16(hit, n, surface_id, target, leaf.part[i], packet);
        }
        continue;
      }
      for (int i = 0; i < leaf.count; ++i) {
        Eigen::Vector3f corner[3];
        LeafCorners(target, leaf, i, corner);
        HitCorners16(corner, target.SurfaceOf(leaf.part[i]), target, leaf.part[i], packet, lanes,
                     &t_max);
      }
      continue;
    }
    const scene::TriangleBvh::Node& node = bvh.nodes[std::size_t(entry.ref())];
    WalkEntry children[scene::TriangleBvh::kWidth];
    float nearest[scene::TriangleBvh::kWidth];
    // The four children's slabs first (independent work, no branch between
    // them; an empty child's box is inverted and no lane enters it), then
    // the entered ones kept in order.
    __m512 near[scene::TriangleBvh::kWidth];
    __mmask16 enter[scene::TriangleBvh::kWidth];
    for (int c = 0; c < scene::TriangleBvh::kWidth; ++c) {
      __m512 far = t_max;
      near[c] = _mm512_setzero_ps();
      for (int a = 0; a < 3; ++a) {
        const __m512 t0 = _mm512_fmsub_ps(Set(node.lower[a][c]), inverse[a], at_lower[a]);
        const __m512 t1 = _mm512_fmsub_ps(Set(node.upper[a][c]), inverse[a], at_upper[a]);
        if (sign[a] > 0) {
          near[c] = Max(near[c], t0), far = Min(far, t1);
        } else if (sign[a] < 0) {
          near[c] = Max(near[c], t1), far = Min(far, t0);
        } else {
          near[c] = Max(near[c], Min(t0, t1)), far = Min(far, Max(t0, t1));
        }
      }
      enter[c] = lanes & _mm512_cmp_ps_mask(near[c], Mul(far, grow), _CMP_LE_OS);
    }
    int count = 0;
    for (int c = 0; c < scene::TriangleBvh::kWidth; ++c) {
      if (enter[c] == 0 || node.child[c] == scene::TriangleBvh::kEmpty) continue;
      // Ordered by the first lane that enters.
      alignas(64) float entries[16];
      _mm512_store_ps(entries, near[c]);
      nearest[count] = entries[__builtin_ctz(enter[c])];
      children[count++] = WalkEntry(node.child[c], enter[c]);
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

// Sixteen rays at a time.
void CastRays(const RayBatch& rays, const Eigen::Vector3f& origin_B, std::size_t first,
              std::size_t end, const Target* const* targets, std::size_t num_targets,
              RayHits* hits) {
  for (std::size_t i = first; i < end; i += 16) {
    Packet16 packet;
    const bool full = i + 16 <= end;
    if (full) {
      // Sixteen x, y, z triples in three loads, sorted into x, y and z.
      packet.o = Add(Splat(origin_B), Deinterleave(rays.start[i].data()));
      packet.d = Deinterleave(rays.direction[i].data());
      packet.t_max = _mm512_loadu_ps(&rays.length_m[i]);
      packet.active = 0xFFFF;
    } else {
      alignas(64) float lane[7][16];
      __mmask16 active = 0;
      for (int l = 0; l < 16; ++l) {
        const std::size_t r = std::min(i + std::size_t(l), end - 1);
        const Eigen::Vector3f o = origin_B + rays.start[r];
        lane[0][l] = o.x(), lane[1][l] = o.y(), lane[2][l] = o.z();
        lane[3][l] = rays.direction[r].x(), lane[4][l] = rays.direction[r].y();
        lane[5][l] = rays.direction[r].z(), lane[6][l] = rays.length_m[r];
        if (i + std::size_t(l) < end) active |= __mmask16(1u << l);
      }
      packet.o = {_mm512_load_ps(lane[0]), _mm512_load_ps(lane[1]), _mm512_load_ps(lane[2])};
      packet.d = {_mm512_load_ps(lane[3]), _mm512_load_ps(lane[4]), _mm512_load_ps(lane[5])};
      packet.t_max = _mm512_load_ps(lane[6]);
      packet.active = active;
    }
    packet.one_origin =
        SameInEveryLane(packet.o.x) && SameInEveryLane(packet.o.y) && SameInEveryLane(packet.o.z);
    const __m512 inverse[3] = {_mm512_div_ps(Set(1.0f), AwayFromZero16(packet.d.x)),
                               _mm512_div_ps(Set(1.0f), AwayFromZero16(packet.d.y)),
                               _mm512_div_ps(Set(1.0f), AwayFromZero16(packet.d.z))};
    packet.box_inverse = CornerBoxInverse(packet.d, inverse);
    for (int l = 0; l < 16; ++l) packet.surface[l] = RayHits::kNoHit;
    WalkTargetsMet(
        targets, num_targets,
        [&](const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
          return MeetsBox16(packet, inverse, lo, hi);
        },
        [&](const Target& target) { WalkWide16(target, inverse, &packet); });
    if (full && !hits->with_normals &&
        !hits->with_reflectivity) {  // WriteHit's two stores, sixteen at once
      _mm512_storeu_ps(&hits->distance_m[i], packet.t_max);
      _mm512_storeu_si512(&hits->surface[i], _mm512_load_si512(packet.surface));
      continue;
    }
    alignas(64) float t_max[16];
    _mm512_store_ps(t_max, packet.t_max);
    for (int l = 0; l < 16 && i + std::size_t(l) < end; ++l) {
      const std::size_t r = i + std::size_t(l);
      const Eigen::Vector3f normal(packet.normal[0][l], packet.normal[1][l], packet.normal[2][l]);
      WriteHit(r, t_max[l], packet.surface[l], packet.reflectivity[l], normal, rays.direction[r],
               hits);
    }
  }
}

namespace {

// The vectors at xyz (indexes of their x) of an array of them, in `lanes`.
inline V16 Gather(const float* base, __mmask16 lanes, __m512i xyz) {
  return {_mm512_mask_i32gather_ps(_mm512_setzero_ps(), lanes, xyz, base, 4),
          _mm512_mask_i32gather_ps(_mm512_setzero_ps(), lanes, xyz, base + 1, 4),
          _mm512_mask_i32gather_ps(_mm512_setzero_ps(), lanes, xyz, base + 2, 4)};
}

}  // namespace

// packet_walk4.cc's HitPairs, sixteen pairs a test: the same lanes, the same
// bits, the same order of taking the hits.
void HitPairs(GridBand* band) {
  GridBand::Pairs& pairs = band->pairs;
  float* t = band->t_max;
  std::int32_t* surface = band->surface;
  const float* start = band->start[0].data();
  const V16 origin{Set(_mm_cvtss_f32(band->ox)), Set(_mm_cvtss_f32(band->oy)),
                   Set(_mm_cvtss_f32(band->oz))};
  V16 d{Set(_mm_cvtss_f32(band->dx)), Set(_mm_cvtss_f32(band->dy)), Set(_mm_cvtss_f32(band->dz))};
  V16 box_inverse = CornerBoxInverse(d);
  for (int k = 0; k < pairs.count; k += 16) {
    const __mmask16 in_packet = __mmask16((1u << std::min(16, pairs.count - k)) - 1u);
    const __m512i cell = _mm512_maskz_loadu_epi32(in_packet, &pairs.cell[k]);
    __m512 t_max = _mm512_mask_i32gather_ps(_mm512_setzero_ps(), in_packet, cell, t, 4);
    const __mmask16 lanes =
        _mm512_mask_cmp_ps_mask(in_packet, t_max, _mm512_loadu_ps(&pairs.near[k]), _CMP_GT_OQ);
    if (lanes == 0) continue;
    // Each origin as Cast() forms it: the batch origin plus the ray's start.
    const __m512i xyz = _mm512_mullo_epi32(cell, _mm512_set1_epi32(3));
    const V16 o = Add(origin, Gather(start, lanes, xyz));
    V16 c[3];
    for (int j = 0; j < 3; ++j) {
      c[j] = {_mm512_loadu_ps(&pairs.corner[3 * j][k]),
              _mm512_loadu_ps(&pairs.corner[3 * j + 1][k]),
              _mm512_loadu_ps(&pairs.corner[3 * j + 2][k])};
    }
    const __m512i pair_surface = _mm512_maskz_loadu_epi32(in_packet, &pairs.surface[k]);
    const __m512i ray_surface =
        _mm512_mask_i32gather_epi32(_mm512_setzero_si512(), lanes, cell, surface, 4);
    const __mmask16 ties = _mm512_cmpgt_epi32_mask(ray_surface, pair_surface);
    V16 n;
    const __mmask16 hit = HitLanes16(c, o, d, box_inverse, lanes, ties, &t_max, &n);
    if (hit == 0) continue;
    alignas(64) float t_hit[16], nx[16], ny[16], nz[16];
    alignas(64) std::int32_t cells[16];
    _mm512_store_ps(t_hit, t_max);
    _mm512_store_si512(cells, cell);
    if (band->normal != nullptr) {
      n = FacingUnits16(n, d);
      _mm512_store_ps(nx, n.x), _mm512_store_ps(ny, n.y), _mm512_store_ps(nz, n.z);
    }
    // In lane order, as the pairs one by one: the nearer hit stays.
    for (unsigned rest = hit; rest != 0; rest &= rest - 1) {
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
