#pragma once
// Four float lanes in an SSE register, and the operations the caster's
// four-lane code shares (its packet kernel, packet_walk4.cc, and the grid
// bands' triangle binning, ray_caster.cc). Internal linkage throughout: each
// file's copy is compiled for that file's instruction set (sandbox_isa_kernel)
// and never merged with another build's by the linker.

#include <immintrin.h>

#include <limits>

#include "sensors/ray_kernels.h"

namespace sandbox::sensors {

// x with every component of magnitude under 1e-30 moved to +-1e-30 (the
// inverse stays finite).
static inline __m128 AwayFromZero(__m128 x) {
  const __m128 sign = _mm_and_ps(x, _mm_set1_ps(-0.0f));
  const __m128 magnitude = _mm_max_ps(_mm_andnot_ps(_mm_set1_ps(-0.0f), x), _mm_set1_ps(1e-30f));
  return _mm_or_ps(magnitude, sign);
}

static inline __m128 Mul(__m128 a, __m128 b) { return _mm_mul_ps(a, b); }
static inline __m128 Add(__m128 a, __m128 b) { return _mm_add_ps(a, b); }
static inline __m128 Sub(__m128 a, __m128 b) { return _mm_sub_ps(a, b); }

struct Vec4 {  // a vector per lane
  __m128 x, y, z;
};
static inline Vec4 Sub(const Vec4& a, const Vec4& b) {
  return {Sub(a.x, b.x), Sub(a.y, b.y), Sub(a.z, b.z)};
}
static inline Vec4 Add(const Vec4& a, const Vec4& b) {
  return {Add(a.x, b.x), Add(a.y, b.y), Add(a.z, b.z)};
}
static inline __m128 Abs(__m128 x) { return _mm_andnot_ps(_mm_set1_ps(-0.0f), x); }
static inline __m128 L1(const Vec4& a) { return Add(Add(Abs(a.x), Abs(a.y)), Abs(a.z)); }
// The lanes whose bits are set in `bits` (a movemask), all bits set.
static inline __m128 LaneMask(int bits) {
  const __m128i bit = _mm_setr_epi32(1, 2, 4, 8);
  return _mm_castsi128_ps(_mm_cmpeq_epi32(_mm_and_si128(_mm_set1_epi32(bits), bit), bit));
}
static inline __m128 Select(__m128 mask, __m128 a, __m128 b) {
  return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b));
}
// The unit normals along n facing rays along d: the reciprocal square
// root's estimate and one Newton step (within 2 ulps of 1 / sqrt).
static inline Vec4 FacingUnits4(const Vec4& n, const Vec4& d) {
  const __m128 n2 = Add(Add(Mul(n.x, n.x), Mul(n.y, n.y)), Mul(n.z, n.z));
  const __m128 r0 = _mm_rsqrt_ps(n2);
  // r = r0 (3 - n2 r0^2) / 2, negated where n runs along d.
  __m128 scale = Mul(Mul(_mm_set1_ps(0.5f), r0), Sub(_mm_set1_ps(3.0f), Mul(n2, Mul(r0, r0))));
  const __m128 along = Add(Add(Mul(n.x, d.x), Mul(n.y, d.y)), Mul(n.z, d.z));
  scale = _mm_xor_ps(scale, _mm_and_ps(_mm_cmpgt_ps(along, _mm_setzero_ps()), _mm_set1_ps(-0.0f)));
  return {Mul(n.x, scale), Mul(n.y, scale), Mul(n.z, scale)};
}

// MeetsCornerBox, per lane, for the boxes [low, high] around each lane's corners.
static inline __m128 MeetsCornerBox4(const Vec4& low, const Vec4& high, const Vec4& o,
                                     const Vec4& d, __m128 t) {
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

}  // namespace sandbox::sensors
