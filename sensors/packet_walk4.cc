// The packet kernel of four rays (sensors/ray_kernels.h): the walk of each
// object's own hierarchy and the watertight triangle test, four rays at a
// time for Cast() and four triangle-ray pairs at a time for CastGrids().
// Built twice by sensors/CMakeLists.txt: for any x86-64 (namespace sse2) and
// with -mfma (namespace fma, __FMA__ defined).

#include <Eigen/Core>
#include <algorithm>
#include <limits>

#include "sensors/lanes4.h"
#include "sensors/ray_kernels.h"
#include "sensors/walk_stack.h"

namespace sandbox::sensors::SANDBOX_ISA {
namespace {

#if defined(__FMA__)
// Fused multiply-adds throughout: what Embree's kernels use on CPUs with the
// unit, the reference the grazing rules are matched to.
inline __m128 FusedMulAdd(__m128 a, __m128 b, __m128 c, bool subtract) {
  return subtract ? _mm_fmsub_ps(a, b, c) : _mm_fmadd_ps(a, b, c);
}
constexpr bool kPlainFirst = false;
#else
// Plain arithmetic first, fused where rounding could turn a decision, the
// fused a b + c (or a b - c) emulated: the product of two floats is exact in
// double, so only the sum rounds, to double and then to float. The same
// results as the fma build but for that double rounding, which differs from
// a single one only at a tie at float precision after rounding to double:
// about once in 2^29 operations.
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
#endif

// Four rays walked together (SSE2): a node is visited when any of them
// enters it, and every test is done for the four at once. Rays of a sensor
// are coherent (neighbouring beams or grid points), so the four mostly agree.
struct Packet {
  __m128 ox, oy, oz, dx, dy, dz;  // Bullet frame
  __m128 t_max;                   // per lane
  __m128 active;                  // all bits set in lanes that hold a ray
  int surface[4];
  float reflectivity[4];      // Target::ReflectivityOf the part hit
  Eigen::Vector3f normal[4];  // in the Bullet frame, unnormalised
};

template <bool kFused>
inline __m128 MulAdd(__m128 a, __m128 b, __m128 c, bool subtract) {
  if (kFused) return FusedMulAdd(a, b, c, subtract);
  return subtract ? Sub(Mul(a, b), c) : Add(Mul(a, b), c);
}
template <bool kFused>
inline __m128 Dot(const Vec4& a, const Vec4& b) {
  return MulAdd<kFused>(a.x, b.x, MulAdd<kFused>(a.y, b.y, Mul(a.z, b.z), false), false);
}
template <bool kFused>
inline Vec4 Cross(const Vec4& a, const Vec4& b) {
  return {MulAdd<kFused>(a.y, b.z, Mul(a.z, b.y), true),
          MulAdd<kFused>(a.z, b.x, Mul(a.x, b.z), true),
          MulAdd<kFused>(a.x, b.y, Mul(a.y, b.x), true)};
}
// The triangle normal from its edges (e0 + e1 + e2 = 0), each component
// from whichever of e0 x e1 and e1 x e2 suffers less cancellation.
template <bool kFused>
inline Vec4 StableNormal4(const Vec4& a, const Vec4& b, const Vec4& c) {
  const __m128 ab_x = Mul(a.z, b.y), ab_y = Mul(a.x, b.z), ab_z = Mul(a.y, b.x);
  const __m128 bc_x = Mul(b.z, c.y), bc_y = Mul(b.x, c.z), bc_z = Mul(b.y, c.x);
  return {Select(_mm_cmplt_ps(Abs(ab_x), Abs(bc_x)), MulAdd<kFused>(a.y, b.z, ab_x, true),
                 MulAdd<kFused>(b.y, c.z, bc_x, true)),
          Select(_mm_cmplt_ps(Abs(ab_y), Abs(bc_y)), MulAdd<kFused>(a.z, b.x, ab_y, true),
                 MulAdd<kFused>(b.z, c.x, bc_y, true)),
          Select(_mm_cmplt_ps(Abs(ab_z), Abs(bc_z)), MulAdd<kFused>(a.x, b.y, ab_z, true),
                 MulAdd<kFused>(b.x, c.y, bc_z, true))};
}

// HitTriangle (the rules of docs/reference/sensors.md) for four rays against four
// triangles, a ray and a triangle a lane (corners c[k], in the Bullet frame):
// the lanes hit closer than their t_max (or at it, in `ties`: lanes whose
// hit so far is a higher surface's), which take the distance; the (unnormalised)
// normals in *normal. So a tie between bodies goes to the lower surface, in
// whatever order a kernel meets the triangles.
inline __m128 HitLanes4(const Vec4 c[3], const Vec4& o, const Vec4& d, __m128 lanes, __m128 ties,
                        __m128* t_max, Vec4* normal) {
  const Vec4 v0 = Sub(c[0], o), v1 = Sub(c[1], o), v2 = Sub(c[2], o);
  const Vec4 e0 = Sub(v2, v0), e1 = Sub(v0, v1), e2 = Sub(v1, v2);
  // Plain arithmetic moves a value by a few ulps of its terms: an edge
  // function by a few of |e| |sum| (|d| = 1), the normal by a few of
  // |e0| |e1|. Within 1e-5 of them (of 0 or of the edge tolerance), the
  // fused value decides.
  const __m128 doubt = _mm_set1_ps(1e-5f);
  auto edge = [&](const Vec4& e, const Vec4& sum) {
    if (!kPlainFirst) return Dot<true>(Cross<true>(e, sum), d);
    const __m128 plain = Dot<false>(Cross<false>(e, sum), d);
    const __m128 near_edge = Mul(doubt, Mul(L1(e), L1(sum)));
    if (_mm_movemask_ps(_mm_and_ps(lanes, _mm_cmple_ps(Abs(plain), near_edge))) == 0) return plain;
    return Dot<true>(Cross<true>(e, sum), d);
  };
  const __m128 u = edge(e0, Add(v2, v0)), v = edge(e1, Add(v0, v1)), w = edge(e2, Add(v1, v2));
  const __m128 eps =
      Mul(_mm_set1_ps(std::numeric_limits<float>::epsilon()), Abs(Add(Add(u, v), w)));
  const __m128 low = _mm_min_ps(_mm_min_ps(u, v), w), high = _mm_max_ps(_mm_max_ps(u, v), w);
  __m128 hit = _mm_and_ps(
      lanes, _mm_or_ps(_mm_cmpge_ps(low, Sub(_mm_setzero_ps(), eps)), _mm_cmple_ps(high, eps)));
  if (_mm_movemask_ps(hit) == 0) return hit;
  Vec4 n = StableNormal4<!kPlainFirst>(e0, e1, e2);
  __m128 den = Mul(_mm_set1_ps(2.0f), Dot<!kPlainFirst>(n, d));
  __m128 depth = Mul(_mm_set1_ps(2.0f), Dot<!kPlainFirst>(v0, n));
  if (kPlainFirst) {
    const __m128 normal_scale = Mul(L1(e0), L1(e1));
    const __m128 unsure =
        _mm_or_ps(_mm_cmple_ps(Abs(den), Mul(doubt, normal_scale)),
                  _mm_cmple_ps(Abs(depth), Mul(doubt, Mul(normal_scale, L1(v0)))));
    if (_mm_movemask_ps(_mm_and_ps(hit, unsure)) != 0) {
      n = StableNormal4<true>(e0, e1, e2);
      den = Mul(_mm_set1_ps(2.0f), Dot<true>(n, d));
      depth = Mul(_mm_set1_ps(2.0f), Dot<true>(v0, n));
    }
  }
  const __m128 t = _mm_div_ps(depth, den);
  hit = _mm_and_ps(hit, _mm_cmpneq_ps(den, _mm_setzero_ps()));
  hit = _mm_and_ps(hit, _mm_cmpge_ps(t, _mm_setzero_ps()));
  hit = _mm_and_ps(hit,
                   _mm_or_ps(_mm_cmplt_ps(t, *t_max), _mm_and_ps(ties, _mm_cmpeq_ps(t, *t_max))));
  if (_mm_movemask_ps(hit) == 0) return hit;
  const Vec4 box_low{_mm_min_ps(_mm_min_ps(c[0].x, c[1].x), c[2].x),
                     _mm_min_ps(_mm_min_ps(c[0].y, c[1].y), c[2].y),
                     _mm_min_ps(_mm_min_ps(c[0].z, c[1].z), c[2].z)};
  const Vec4 box_high{_mm_max_ps(_mm_max_ps(c[0].x, c[1].x), c[2].x),
                      _mm_max_ps(_mm_max_ps(c[0].y, c[1].y), c[2].y),
                      _mm_max_ps(_mm_max_ps(c[0].z, c[1].z), c[2].z)};
  hit = _mm_and_ps(hit, MeetsCornerBox4(box_low, box_high, o, d, t));
  *t_max = Select(hit, t, *t_max);
  *normal = n;
  return hit;
}

// HitLanes4 for four rays against one triangle (of `part` of `target`): the
// lanes it hits take its distance, `surface_id`, reflectivity and its
// (unnormalised) normal.
inline void HitCorners4(const Eigen::Vector3f corner[3], int surface_id, const Target& target,
                        int part, const Vec4& o, const Vec4& d, __m128 lanes, __m128* t_max,
                        Packet* packet) {
  int* surface = packet->surface;
  Vec4 c[3];
  for (int k = 0; k < 3; ++k) {
    c[k] = {_mm_set1_ps(corner[k].x()), _mm_set1_ps(corner[k].y()), _mm_set1_ps(corner[k].z())};
  }
  Vec4 n;
  const __m128 ties = _mm_castsi128_ps(_mm_cmpgt_epi32(
      _mm_loadu_si128(reinterpret_cast<const __m128i*>(surface)), _mm_set1_epi32(surface_id)));
  const int mask = _mm_movemask_ps(HitLanes4(c, o, d, lanes, ties, t_max, &n));
  if (mask == 0) return;
  alignas(16) float nx[4], ny[4], nz[4];
  _mm_store_ps(nx, n.x), _mm_store_ps(ny, n.y), _mm_store_ps(nz, n.z);
  const float reflectivity = target.ReflectivityOf(part);
  for (int lane = 0; lane < 4; ++lane) {
    if (mask & (1 << lane)) {
      surface[lane] = surface_id;
      packet->reflectivity[lane] = reflectivity;
      packet->normal[lane] = Eigen::Vector3f(nx[lane], ny[lane], nz[lane]);
    }
  }
}

// The packet's walk of one object's own hierarchy (scene::TriangleBvh: four
// children a node, four triangles a leaf), nearest child first (by the
// nearest entry of the lanes that enter it), shortening the lanes' rays at
// every hit. Boxes are in the object's frame, the rays taken there; each
// box is grown by the object's margin (the rounding of that change of frame),
// so a ray's box test never drops a triangle its Bullet-frame test would hit.
void WalkWide4(const Target& target, Packet* packet) {
  const scene::TriangleBvh& bvh = *target.bvh;
  if (bvh.root == scene::TriangleBvh::kEmpty) return;
  const Eigen::Matrix3f& R = target.R_LB;
  auto transform = [&](int row, __m128 x, __m128 y, __m128 z, float offset) {
    return Add(Add(Mul(_mm_set1_ps(R(row, 0)), x), Mul(_mm_set1_ps(R(row, 1)), y)),
               Add(Mul(_mm_set1_ps(R(row, 2)), z), _mm_set1_ps(offset)));
  };
  __m128 o[3], inverse[3];
  for (int k = 0; k < 3; ++k) {
    o[k] = transform(k, packet->ox, packet->oy, packet->oz, target.p_LB[k]);
    inverse[k] = _mm_div_ps(_mm_set1_ps(1.0f),
                            AwayFromZero(transform(k, packet->dx, packet->dy, packet->dz, 0.0f)));
  }
  const __m128 grow = _mm_set1_ps(1.0f + 8.0f * std::numeric_limits<float>::epsilon());
  // WalkWide16's slabs: a box grown by the margin m, its distances (lower -
  // m - o) i and (upper + m - o) i as lower i - (o i + m i) and upper i -
  // (o i - m i) (their rounding covered as there); and per axis
  // whether every lane runs the same way (+1, -1; 0 mixed).
  __m128 at_lower[3], at_upper[3];
  int sign[3];
  const int active = _mm_movemask_ps(packet->active);
  for (int k = 0; k < 3; ++k) {
    const __m128 o_inverse = Mul(o[k], inverse[k]);
    const __m128 m_inverse = Mul(_mm_set1_ps(target.box_margin), inverse[k]);
    at_lower[k] = Add(o_inverse, m_inverse), at_upper[k] = Sub(o_inverse, m_inverse);
    const int positive = _mm_movemask_ps(_mm_cmpgt_ps(inverse[k], _mm_setzero_ps())) & active;
    sign[k] = positive == active ? 1 : positive == 0 ? -1 : 0;
  }
  const __m128 infinity = _mm_set1_ps(std::numeric_limits<float>::infinity());
  __m128 t_max = packet->t_max;
  const Vec4 o_B{packet->ox, packet->oy, packet->oz}, d_B{packet->dx, packet->dy, packet->dz};
  WalkStack<WalkEntry, kStackInPlace> stack;
  stack.Push({bvh.root, std::uint32_t(_mm_movemask_ps(packet->active))});
  while (!stack.empty()) {
    const WalkEntry entry = stack.Pop();
    const __m128 lanes = _mm_and_ps(packet->active, LaneMask(int(entry.lanes())));
    if (entry.ref() < 0) {
      const scene::TriangleBvh::Leaves& leaf = bvh.leaves[std::size_t(-1 - entry.ref())];
      for (int i = 0; i < leaf.count; ++i) {
        Eigen::Vector3f corner[3];
        LeafCorners(target, leaf, i, corner);
        HitCorners4(corner, target.SurfaceOf(leaf.part[i]), target, leaf.part[i], o_B, d_B, lanes,
                    &t_max, packet);
      }
      continue;
    }
    const scene::TriangleBvh::Node& node = bvh.nodes[std::size_t(entry.ref())];
    // The four children's slabs first (independent work, no branch between
    // them; an empty child's box is inverted), then the entered ones kept.
    __m128 near_of[scene::TriangleBvh::kWidth];
    int enter_of[scene::TriangleBvh::kWidth];
    for (int c = 0; c < scene::TriangleBvh::kWidth; ++c) {
      __m128 near = _mm_setzero_ps(), far = t_max;
      for (int a = 0; a < 3; ++a) {
        const __m128 t0 =
            MulAdd<!kPlainFirst>(_mm_set1_ps(node.lower[a][c]), inverse[a], at_lower[a], true);
        const __m128 t1 =
            MulAdd<!kPlainFirst>(_mm_set1_ps(node.upper[a][c]), inverse[a], at_upper[a], true);
        if (sign[a] > 0) {
          near = _mm_max_ps(near, t0), far = _mm_min_ps(far, t1);
        } else if (sign[a] < 0) {
          near = _mm_max_ps(near, t1), far = _mm_min_ps(far, t0);
        } else {
          near = _mm_max_ps(near, _mm_min_ps(t0, t1));
          far = _mm_min_ps(far, _mm_max_ps(t0, t1));
        }
      }
      near_of[c] = near;
      enter_of[c] = _mm_movemask_ps(_mm_and_ps(lanes, _mm_cmple_ps(near, Mul(far, grow))));
    }
    WalkEntry children[scene::TriangleBvh::kWidth];
    float nearest[scene::TriangleBvh::kWidth];
    int count = 0;
    for (int c = 0; c < scene::TriangleBvh::kWidth; ++c) {
      const int mask = enter_of[c];
      if (mask == 0 || node.child[c] == scene::TriangleBvh::kEmpty) continue;
      // The nearest entry among the lanes that enter.
      __m128 key = Select(LaneMask(mask), near_of[c], infinity);
      key = _mm_min_ps(key, _mm_shuffle_ps(key, key, _MM_SHUFFLE(2, 3, 0, 1)));
      key = _mm_min_ps(key, _mm_shuffle_ps(key, key, _MM_SHUFFLE(1, 0, 3, 2)));
      nearest[count] = _mm_cvtss_f32(key);
      children[count++] = WalkEntry(node.child[c], std::uint32_t(mask));
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
}  // namespace

// Four pairs at a time. A ray that ends before the
// pair's `near` (its triangle's nearest depth) is left out. Where two lanes
// hold the same ray, the nearer hit stays (on a tie, the lower surface's, then
// the earlier pair's): the same result as the pairs taken one by one.
void HitPairs(GridBand* band) {
  GridBand::Pairs& pairs = band->pairs;
  const Vec4 d{band->dx, band->dy, band->dz};
  const __m128i lane_index = _mm_setr_epi32(0, 1, 2, 3);
  float* t = band->t_max;
  const Eigen::Vector3f* start = band->start;
  for (int k = 0; k < pairs.count; k += 4) {
    const int in_packet = std::min(4, pairs.count - k);
    int cell[4];
    for (int lane = 0; lane < 4; ++lane) cell[lane] = pairs.cell[k + std::min(lane, in_packet - 1)];
    __m128 t_max = _mm_setr_ps(t[cell[0]], t[cell[1]], t[cell[2]], t[cell[3]]);
    const __m128 lanes =
        _mm_and_ps(_mm_castsi128_ps(_mm_cmplt_epi32(lane_index, _mm_set1_epi32(in_packet))),
                   _mm_cmpgt_ps(t_max, _mm_load_ps(&pairs.near[k])));
    if (_mm_movemask_ps(lanes) == 0) continue;
    // Each origin as Cast() forms it: the batch origin plus the ray's start.
    auto starts = [&](int a) {
      return _mm_setr_ps(start[cell[0]][a], start[cell[1]][a], start[cell[2]][a],
                         start[cell[3]][a]);
    };
    const Vec4 o{Add(band->ox, starts(0)), Add(band->oy, starts(1)), Add(band->oz, starts(2))};
    Vec4 c[3];
    for (int j = 0; j < 3; ++j) {
      c[j] = {_mm_load_ps(&pairs.corner[3 * j][k]), _mm_load_ps(&pairs.corner[3 * j + 1][k]),
              _mm_load_ps(&pairs.corner[3 * j + 2][k])};
    }
    Vec4 n;
    const __m128 ties = _mm_castsi128_ps(
        _mm_cmpgt_epi32(_mm_setr_epi32(band->surface[cell[0]], band->surface[cell[1]],
                                       band->surface[cell[2]], band->surface[cell[3]]),
                        _mm_setr_epi32(pairs.surface[k + std::min(0, in_packet - 1)],
                                       pairs.surface[k + std::min(1, in_packet - 1)],
                                       pairs.surface[k + std::min(2, in_packet - 1)],
                                       pairs.surface[k + std::min(3, in_packet - 1)])));
    const int mask = _mm_movemask_ps(HitLanes4(c, o, d, lanes, ties, &t_max, &n));
    if (mask == 0) continue;
    alignas(16) float t_hit[4], nx[4], ny[4], nz[4];
    _mm_store_ps(t_hit, t_max);
    if (band->normal != nullptr) {
      n = FacingUnits4(n, d);
      _mm_store_ps(nx, n.x), _mm_store_ps(ny, n.y), _mm_store_ps(nz, n.z);
    }
    for (int lane = 0; lane < in_packet; ++lane) {
      const auto i = std::size_t(cell[lane]);
      const bool nearer =
          t_hit[lane] < t[i] || (t_hit[lane] == t[i] && pairs.surface[k + lane] < band->surface[i]);
      if (!(mask & (1 << lane)) || !nearer) continue;
      t[i] = t_hit[lane];
      band->surface[i] = pairs.surface[k + lane];
      if (band->normal != nullptr) band->normal[i] = Eigen::Vector3f(nx[lane], ny[lane], nz[lane]);
    }
  }
  pairs.count = 0;
}

void CastRays(const RayBatch& rays, const Eigen::Vector3f& origin_B, std::size_t first,
              std::size_t end, const Target* const* targets, std::size_t num_targets,
              RayHits* hits) {
  for (std::size_t i = first; i < end; i += 4) {
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
    for (int l = 0; l < 4; ++l) packet.surface[l] = RayHits::kNoHit;
    WalkTargetsMet(
        targets, num_targets,
        [&](const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
          return PacketMeetsBox(packet, inverse, lo, hi);
        },
        [&](const Target& target) { WalkWide4(target, &packet); });
    alignas(16) float t_max[4];
    _mm_store_ps(t_max, packet.t_max);
    for (int l = 0; l < 4 && i + std::size_t(l) < end; ++l) {
      const std::size_t r = i + std::size_t(l);
      WriteHit(r, t_max[l], packet.surface[l], packet.reflectivity[l], packet.normal[l],
               rays.direction[r], hits);
    }
  }
}

const RayKernel kKernel{SANDBOX_ISA_NAME, CastRays, HitPairs};

}  // namespace sandbox::sensors::SANDBOX_ISA
