// The deferred shading kernel (deferred_kernel.h), written once for vectors
// of kLanes pixels in GCC's vector extensions and built per instruction set:
// avx512 (16 pixels at a time), avx2 (8, with FMA) and sse2 (8, in SSE2
// halves). Each line mirrors a line of the forward shaders (shaders.h:
// kShading, the scene and sky programs).

#include "sensors/render/deferred_kernel.h"

#include <immintrin.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace sandbox::render::SANDBOX_ISA {
namespace {

#if defined(__AVX512F__)
constexpr int kLanes = 16;
#else
constexpr int kLanes = 8;
#endif
typedef float vf __attribute__((vector_size(4 * kLanes)));
typedef std::int32_t vi __attribute__((vector_size(4 * kLanes)));
typedef std::uint32_t vu __attribute__((vector_size(4 * kLanes)));

#define INLINE static inline __attribute__((always_inline))

INLINE vf Splat(float x) { return vf{} + x; }
INLINE vf ToF(vi a) { return __builtin_convertvector(a, vf); }
INLINE vi ToI(vf a) { return __builtin_convertvector(a, vi); }  // toward zero
INLINE vf Select(vi mask, vf a, vf b) { return mask ? a : b; }
INLINE vi Select(vi mask, vi a, vi b) { return mask ? a : b; }
INLINE vf Min(vf a, vf b) { return a < b ? a : b; }
INLINE vf Max(vf a, vf b) { return a > b ? a : b; }
INLINE vf Clamp01(vf a) { return Min(Max(a, Splat(0.f)), Splat(1.f)); }
INLINE vf Abs(vf a) { return __builtin_bit_cast(vf, __builtin_bit_cast(vi, a) & 0x7fffffff); }
INLINE vf Mix(vf a, vf b, vf t) { return a + (b - a) * t; }
INLINE bool Any(vi mask) {
#if defined(__AVX512F__)
  const __m512i m = reinterpret_cast<__m512i>(mask);
  return _mm512_test_epi32_mask(m, m) != 0;
#elif defined(__AVX2__)
  return _mm256_movemask_ps(reinterpret_cast<__m256>(mask)) != 0;
#else
  for (int k = 0; k < kLanes; ++k) {
    if (mask[k]) return true;
  }
  return false;
#endif
}
// |x| < 2^31.
INLINE vf Floor(vf x) {
  const vf t = ToF(ToI(x));
  return t - Select(t > x, Splat(1.f), Splat(0.f));
}
INLINE vf Sqrt(vf x) {
#if defined(__AVX512F__)
  return reinterpret_cast<vf>(_mm512_maskz_sqrt_ps(0xffff, reinterpret_cast<__m512>(x)));
#elif defined(__AVX2__)
  return reinterpret_cast<vf>(_mm256_sqrt_ps(reinterpret_cast<__m256>(x)));
#else
  vf r;
  for (int k = 0; k < kLanes; ++k) r[k] = std::sqrt(x[k]);
  return r;
#endif
}
INLINE vf Gather(const float* base, vi index) {
#if defined(__AVX512F__)
  return reinterpret_cast<vf>(_mm512_mask_i32gather_ps(_mm512_setzero_ps(), 0xffff,
                                                       reinterpret_cast<__m512i>(index), base, 4));
#elif defined(__AVX2__)
  return reinterpret_cast<vf>(_mm256_i32gather_ps(base, reinterpret_cast<__m256i>(index), 4));
#else
  vf r;
  for (int k = 0; k < kLanes; ++k) r[k] = base[index[k]];
  return r;
#endif
}
INLINE vi Gather(const std::int32_t* base, vi index) {
#if defined(__AVX512F__)
  return reinterpret_cast<vi>(_mm512_mask_i32gather_epi32(
      _mm512_setzero_si512(), 0xffff, reinterpret_cast<__m512i>(index), base, 4));
#elif defined(__AVX2__)
  return reinterpret_cast<vi>(_mm256_i32gather_epi32(base, reinterpret_cast<__m256i>(index), 4));
#else
  vi r;
  for (int k = 0; k < kLanes; ++k) r[k] = base[index[k]];
  return r;
#endif
}
// 0, 1, 2, ...
INLINE vi LaneIndex() {
  vi v;
  for (int k = 0; k < kLanes; ++k) v[k] = k;
  return v;
}
// Each lane's 2 x 2 quad's left and right column's value (even x on the left).
INLINE vf QuadLeft(vf v) {
#if defined(__AVX512F__)
  return __builtin_shufflevector(v, v, 0, 0, 2, 2, 4, 4, 6, 6, 8, 8, 10, 10, 12, 12, 14, 14);
#else
  return __builtin_shufflevector(v, v, 0, 0, 2, 2, 4, 4, 6, 6);
#endif
}
INLINE vf QuadRight(vf v) {
#if defined(__AVX512F__)
  return __builtin_shufflevector(v, v, 1, 1, 3, 3, 5, 5, 7, 7, 9, 9, 11, 11, 13, 13, 15, 15);
#else
  return __builtin_shufflevector(v, v, 1, 1, 3, 3, 5, 5, 7, 7);
#endif
}
// GLSL's smoothstep (either order of edges).
INLINE vf SmoothStep(float e0, float e1, vf x) {
  const vf t = Clamp01((x - e0) * (1.f / (e1 - e0)));
  return t * t * (3.f - 2.f * t);
}
// log2 of x > 0 (to about 1e-5), 2^y for y <= 0, and x^y for x >= 0.
INLINE vf Log2(vf x) {
  const vi bits = __builtin_bit_cast(vi, x);
  const vf e = ToF(((bits >> 23) & 255) - 127);
  const vf m = __builtin_bit_cast(vf, (bits & 0x7fffff) | 0x3f800000) - 1.f;  // [0, 1)
  // log2(1 + m), least squares over [0, 1): within 5e-6.
  return e +
         m * (1.44251696f +
              m * (-0.71789728f +
                   m * (0.45688866f + m * (-0.27735293f + m * (0.12190201f + m * -0.02606180f)))));
}
INLINE vf Exp2(vf y) {
  y = Max(y, Splat(-126.f));
  const vf i = Floor(y), f = (y - i) * 0.693147181f;
  const vf p =
      1.f + f * (1.f + f * (0.5f + f * (1.f / 6.f +
                                        f * (1.f / 24.f + f * (1.f / 120.f + f * (1.f / 720.f))))));
  return __builtin_bit_cast(vf, (ToI(i) + 127) << 23) * p;
}
INLINE vf Pow(vf x, vf y) {
  return Select(x > 0.f, Exp2(y * Log2(Max(x, Splat(1e-30f)))), Splat(0.f));
}

struct Vec3 {
  vf x, y, z;
};
INLINE vf Dot(const Vec3& a, const Vec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
INLINE Vec3 Normalize(const Vec3& a) {
  const vf s = 1.f / Sqrt(Max(Dot(a, a), Splat(1e-30f)));
  return {a.x * s, a.y * s, a.z * s};
}
INLINE Vec3 Mix(const Vec3& a, const Eigen::Vector3f& b, vf t) {
  return {Mix(a.x, Splat(b.x()), t), Mix(a.y, Splat(b.y()), t), Mix(a.z, Splat(b.z()), t)};
}
INLINE Vec3 Splat(const Eigen::Vector3f& v) { return {Splat(v.x()), Splat(v.y()), Splat(v.z())}; }

// Bytes k of packed RGBA8 words.
INLINE vf Byte(vu words, int k) { return ToF(__builtin_bit_cast(vi, (words >> (8 * k)) & 255u)); }

// The octahedral normal (12 + 12 bits in r, g, b) of a G-buffer word.
INLINE Vec3 DecodeNormal(vu words) {
  const vu r = words & 255u, g = (words >> 8) & 255u, b = (words >> 16) & 255u;
  const vf ox = ToF(__builtin_bit_cast(vi, (r << 4) | (g >> 4))) * (2.f / 4095.f) - 1.f;
  const vf oy = ToF(__builtin_bit_cast(vi, ((g & 15u) << 8) | b)) * (2.f / 4095.f) - 1.f;
  const vf z = 1.f - Abs(ox) - Abs(oy);
  const vi fold = z < 0.f;
  const vf sx = Select(ox >= 0.f, Splat(1.f), Splat(-1.f)),
           sy = Select(oy >= 0.f, Splat(1.f), Splat(-1.f));
  return Normalize(
      {Select(fold, (1.f - Abs(oy)) * sx, ox), Select(fold, (1.f - Abs(ox)) * sy, oy), z});
}

// A translucent layer's word: octahedral normal in 8 + 8 bits.
INLINE Vec3 DecodeNormal8(vu words) {
  const vf ox = Byte(words, 0) * (2.f / 255.f) - 1.f, oy = Byte(words, 1) * (2.f / 255.f) - 1.f;
  const vf z = 1.f - Abs(ox) - Abs(oy);
  const vi fold = z < 0.f;
  const vf sx = Select(ox >= 0.f, Splat(1.f), Splat(-1.f)),
           sy = Select(oy >= 0.f, Splat(1.f), Splat(-1.f));
  return Normalize(
      {Select(fold, (1.f - Abs(oy)) * sx, ox), Select(fold, (1.f - Abs(ox)) * sy, oy), z});
}

// Value noise on a 1-unit lattice (shaders.h's Hash and Noise).
INLINE vf Hash(vi x, vi y) {
  const vu qx = __builtin_bit_cast(vu, x) * 1597334673u,
           qy = __builtin_bit_cast(vu, y) * 3812015801u;
  return ToF(__builtin_bit_cast(vi, ((qx ^ qy) * 1597334673u) >> 8)) * (1.f / 16777216.f);
}
INLINE vf Noise(vf px, vf py) {
  const vf fx = Floor(px), fy = Floor(py);
  const vi ix = ToI(fx), iy = ToI(fy);
  const vf ux = px - fx, uy = py - fy;
  const vf sx = ux * ux * (3.f - 2.f * ux), sy = uy * uy * (3.f - 2.f * uy);
  return Mix(Mix(Hash(ix, iy), Hash(ix + 1, iy), sx),
             Mix(Hash(ix, iy + 1), Hash(ix + 1, iy + 1), sx), sy);
}

// The display byte of linear values (clamped to 0..1).
INLINE vi Out(const ShadeConstants& k, vf c) {
  return Gather(k.srgb, ToI(Clamp01(c) * float(kSrgbSteps) + 0.5f));
}

// Bilinear in level `level` of `layer` of the detail texture, repeating.
INLINE vf DetailBilinear(const DetailTextures& d, vi layer, vi level, vf s, vf t) {
  vi size = d.size() >> level;
  const vf fs = ToF(size);
  const vf u = s * fs - 0.5f, v = t * fs - 0.5f;
  const vf u0 = Floor(u), v0 = Floor(v);
  const vf fu = u - u0, fv = v - v0;
  const vi mask = size - 1;
  const vi index = (ToI(v0) & mask) * size + (ToI(u0) & mask);
  const vi base = layer * d.layer_stride() + Gather(d.level_offsets(), level);
  const vu quad = __builtin_bit_cast(vu, Gather(d.data(), base + index));
  const vf a = Byte(quad, 0), b = Byte(quad, 1), c = Byte(quad, 2), e = Byte(quad, 3);
  return Mix(Mix(a, b, fu), Mix(c, e, fu), fv) * (1.f / 255.f);
}

// textureGrad(detail, vec3(s, t, layer), ds, dt).r with trilinear filtering.
INLINE vf Detail(const DetailTextures& d, vi layer, vf s, vf t, vf ds_x, vf dt_x, vf ds_y,
                 vf dt_y) {
  const float size = float(d.size());
  const vf rho = size * Sqrt(Max(ds_x * ds_x + dt_x * dt_x, ds_y * ds_y + dt_y * dt_y));
  const vf lambda = Min(Log2(Max(rho, Splat(1e-20f))), Splat(float(d.levels() - 1)));
  const vi magnify = lambda <= 0.f;
  const vf l = Max(lambda, Splat(0.f));
  const vi l0 = ToI(l);
  const vi l1 = Select(l0 + 1 < d.levels(), l0 + 1, l0);
  const vf near = DetailBilinear(d, layer, l0, s, t);
  if (!Any(l0 != l1)) return near;
  const vf far = DetailBilinear(d, layer, l1, s, t);
  return Select(magnify, near, Mix(near, far, l - ToF(l0)));
}

// Bilinear percentage-closer filtering in a px x px map from `depth` (texels
// from base on): how much of a receiver at window depth `ref` and map
// coordinates (s, t) in [0, 1] is lit (GL_LEQUAL, clamped to the edge).
INLINE vf Pcf(const float* depth, int px, vi base, vf s, vf t, vf ref) {
  const vf u = s * float(px) - 0.5f, v = t * float(px) - 0.5f;
  const vf u0 = Floor(u), v0 = Floor(v);
  const vf fu = u - u0, fv = v - v0;
  auto clamp_index = [px](vi i) {
    return Select(i < 0, vi{} + 0, Select(i > px - 1, vi{} + (px - 1), i));
  };
  const vi c0 = clamp_index(ToI(u0)), c1 = clamp_index(ToI(u0) + 1);
  const vi r0 = clamp_index(ToI(v0)) * px, r1 = clamp_index(ToI(v0) + 1) * px;
  auto lit = [&](vi index) {
    return Select(ref <= Gather(depth, base + index), Splat(1.f), Splat(0.f));
  };
  return Mix(Mix(lit(r0 + c0), lit(r0 + c1), fu), Mix(lit(r1 + c0), lit(r1 + c1), fu), fv);
}

// The point p pushed off the surface along n, more where the sun grazes it
// and by the levels of detail's allowance, then into `m`'s clip space.
INLINE Vec3 ToMap(const ShadeConstants& k, const ShadowMapView& m, const Vec3& n, const Vec3& p,
                  vf grazing, vf distance_m) {
  const vf offset = (0.4f + 1.5f * grazing) * m.texel_m + k.frame->lod_offset_per_m * distance_m;
  const vf x = p.x + n.x * offset, y = p.y + n.y * offset, z = p.z + n.z * offset;
  const Eigen::Matrix4f& M = m.light_clip;
  return {0.5f * (M(0, 0) * x + M(0, 1) * y + M(0, 2) * z + M(0, 3)) + 0.5f,
          0.5f * (M(1, 0) * x + M(1, 1) * y + M(1, 2) * z + M(1, 3)) + 0.5f,
          M(2, 0) * x + M(2, 1) * y + M(2, 2) * z + M(2, 3)};
}

// The sun's light reaching p (shaders.h's Shadow): the still casters'
// cascade for p's depth along the view, times the moving casters' map.
INLINE vf Shadow(const ShadeConstants& k, const Vec3& n, const Vec3& p, vf distance_m) {
  const std::vector<ShadowMapView>& cascades = k.frame->cascades;
  if (cascades.empty()) return Splat(1.f);
  const Eigen::Vector3f& sun = k.frame->sun;
  const vf view_depth =
      p.x * k.frame->view_axis.x() + p.y * k.frame->view_axis.y() + p.z * k.frame->view_axis.z();
  const int count = int(cascades.size());
  vi c = vi{} + 0;
  for (int i = 0; i + 1 < count; ++i) c -= view_depth > cascades[std::size_t(i)].far_m;
  const vf grazing = 1.f - Clamp01(n.x * sun.x() + n.y * sun.y() + n.z * sun.z());
  Vec3 q{Splat(0.f), Splat(0.f), Splat(0.f)};
  for (int i = 0; i < count; ++i) {
    const vi here = c == i;
    if (!Any(here)) continue;
    const Vec3 qi = ToMap(k, cascades[std::size_t(i)], n, p, grazing, distance_m);
    q = {Select(here, qi.x, q.x), Select(here, qi.y, q.y), Select(here, qi.z, q.z)};
  }
  const vi outside =
      (q.x < 0.f) | (q.x > 1.f) | (q.y < 0.f) | (q.y > 1.f) | (view_depth > cascades.back().far_m);
  const int px = cascades.front().px;
  vf visible = Splat(1.f);
  if (Any(~outside)) {
    const vi base = Select(outside, vi{} + 0, c * (px * px));
    visible = Select(outside, visible, Pcf(k.shadow, px, base, q.x, q.y, q.z));
  }
  const ShadowMapView& moving = k.frame->moving_casters;
  if (moving.px > 0) {
    const Vec3 m = ToMap(k, moving, n, p, grazing, distance_m);
    const vi inside = (m.x >= 0.f) & (m.x <= 1.f) & (m.y >= 0.f) & (m.y <= 1.f);
    if (Any(inside)) {
      visible *= Select(inside, Pcf(moving.depth, moving.px, vi{} + 0, m.x, m.y, m.z), Splat(1.f));
    }
  }
  return visible;
}

// The ground's albedo (shaders.h's GroundAlbedo); d*_x, d*_y: the screen
// derivatives of the world x, y.
INLINE Vec3 GroundAlbedo(const ShadeConstants& k, const Vec3& base, vi imagery, const Vec3& n,
                         const Vec3& p, vf distance_m, vf dx_x, vf dy_x, vf dx_y, vf dy_y) {
  const LightingFrame& f = *k.frame;
  const vf st_x = p.x + f.camera_xy.x(), st_y = p.y + f.camera_xy.y();
  const vf height = f.camera_z + p.z;
  const vf up = Clamp01(n.z);
  const vf rock = SmoothStep(0.82f, 0.7f, up);
  vf snow = Splat(0.f);
  const vi snowy = height > f.snow_line - 250.f;
  if (Any(snowy)) {
    snow = Select(snowy,
                  SmoothStep(f.snow_line - 150.f, f.snow_line + 150.f,
                             height + 200.f * (Noise(0.01f * st_x, 0.01f * st_y) - 0.5f)) *
                      (1.f - rock),
                  snow);
  }
  const vf sand =
      (1.f - SmoothStep(f.water_level + 0.8f, f.water_level + 2.5f, height)) * (1.f - rock);
  Vec3 ground = base;
  if (Any(~imagery)) {
    const vf v = 0.85f + 0.3f * Noise(0.05f * st_x, 0.05f * st_y);
    ground = {Select(imagery, base.x, f.ground[0].x() * v),
              Select(imagery, base.y, f.ground[0].y() * v),
              Select(imagery, base.z, f.ground[0].z() * v)};
  }
  ground = Mix(ground, f.ground[3], sand);
  ground = Mix(ground, f.ground[1], rock);
  ground = Mix(ground, f.ground[2], snow);
  const vi layer = Select(rock > 0.5f, vi{} + 1,
                          Select(snow > 0.5f, vi{} + 2, Select(sand > 0.5f, vi{} + 3, vi{} + 0)));
  const vf fade = SmoothStep(60.f, 400.f, distance_m);
  vf d = Splat(1.f);
  const vi near = fade < 1.f;
  if (Any(near)) {
    const float third = 1.f / 3.f;
    d = Select(near,
               2.f * Detail(*k.detail, layer, st_x * third, st_y * third, dx_x * third,
                            dx_y * third, dy_x * third, dy_y * third),
               d);
  }
  const vf m = Mix(d, Splat(1.f), fade);
  return {ground.x * m, ground.y * m, ground.z * m};
}

// Sun (with its shadow) and sky light, and with materials the highlight (shaders.h's Lit).
INLINE Vec3 Lit(const ShadeConstants& k, const Vec3& albedo, const Vec3& n, const Vec3& p,
                vf distance_m, vf metal, vf rough) {
  const LightingFrame& f = *k.frame;
  const Vec3 sun = Splat(f.sun);
  const vf sun_light = Max(Dot(n, sun), Splat(0.f)) * Shadow(k, n, p, distance_m);
  const vf light = 0.75f * sun_light + 0.25f * Mix(Splat(0.55f), Splat(1.f), 0.5f + 0.5f * n.z);
  Vec3 lit{albedo.x * light, albedo.y * light, albedo.z * light};
  const vi shiny = (rough < 0.95f) & (sun_light > 0.f);
  if (f.materials && Any(shiny)) {
    const vf inv = 1.f / Max(distance_m, Splat(1e-6f));
    const Vec3 h = Normalize({sun.x - p.x * inv, sun.y - p.y * inv, sun.z - p.z * inv});
    const vf shininess = 2.f / Max(rough * rough, Splat(0.002f));
    const vf spec =
        Pow(Max(Dot(n, h), Splat(0.f)), shininess) * sun_light * (shininess + 8.f) * (1.f / 32.f);
    lit.x += Select(shiny, Mix(Splat(0.04f), albedo.x, metal) * spec, Splat(0.f));
    lit.y += Select(shiny, Mix(Splat(0.04f), albedo.y, metal) * spec, Splat(0.f));
    lit.z += Select(shiny, Mix(Splat(0.04f), albedo.z, metal) * spec, Splat(0.f));
  }
  return lit;
}

INLINE vf Haze(const LightingFrame& f, vf distance_m) {
  if (f.fog.y() <= 0.f) return Splat(0.f);
  return Clamp01((distance_m - f.fog.x()) * (1.f / std::max(f.fog.y() - f.fog.x(), 1e-3f)));
}

// A surface point shaded, before haze, and for water its alpha.
struct Shaded {
  Vec3 color;
  vf alpha;
};

// Points of one kind code each: their linear colour (shaders.h's scene program).
INLINE Shaded ShadeSurface(const ShadeConstants& k, const Vec3& p, const Vec3& n, Vec3 albedo,
                           vi code, vf rough, vf distance_m, vf haze, const vf derivatives[4]) {
  const LightingFrame& f = *k.frame;
  const vi kind = code & 7;
  const vf metal = ToF(code >> 3) * (1.f / 31.f);
  Shaded out{albedo, Splat(1.f)};
  const vi ground =
      (kind == int(SurfaceKind::kGround)) | (kind == int(SurfaceKind::kGroundImagery));
  if (f.materials && Any(ground)) {
    const Vec3 g =
        GroundAlbedo(k, albedo, kind == int(SurfaceKind::kGroundImagery), n, p, distance_m,
                     derivatives[0], derivatives[1], derivatives[2], derivatives[3]);
    albedo = {Select(ground, g.x, albedo.x), Select(ground, g.y, albedo.y),
              Select(ground, g.z, albedo.z)};
  }
  const vi lit_kinds = (kind != int(SurfaceKind::kPrelit)) & (kind != int(SurfaceKind::kWater));
  if (Any(lit_kinds)) {
    const Vec3 lit = Lit(k, albedo, n, p, distance_m, metal, rough);
    out.color = {Select(lit_kinds, lit.x, albedo.x), Select(lit_kinds, lit.y, albedo.y),
                 Select(lit_kinds, lit.z, albedo.z)};
  }
  const vi water = kind == int(SurfaceKind::kWater);
  if (Any(water)) {
    // Ripples, the sky reflected by Fresnel's law, the sun's glint.
    const vf inv = 1.f / Max(distance_m, Splat(1e-6f));
    const Vec3 to_eye{-p.x * inv, -p.y * inv, -p.z * inv};
    const vf wx = p.x + f.camera_xy.x(), wy = p.y + f.camera_xy.y();
    const Vec3 rn = Normalize({0.06f * (Noise(0.7f * wx, 0.7f * wy) - 0.5f) +
                                   0.04f * (Noise(2.3f * wy, 2.3f * wx) - 0.5f),
                               0.06f * (Noise(0.7f * wx + 17.f, 0.7f * wy + 17.f) - 0.5f) +
                                   0.04f * (Noise(2.3f * wx + 5.f, 2.3f * wy + 5.f) - 0.5f),
                               Splat(1.f)});
    const vf cos_i = Clamp01(Dot(rn, to_eye));
    const vf m = 1.f - cos_i, m2 = m * m;
    const vf fresnel = 0.02f + 0.98f * m2 * m2 * m;
    const vf body = Splat(0.35f + 0.4f * std::max(f.sun.z(), 0.f));
    const Vec3 sun = Splat(f.sun);
    const Vec3 h = Normalize({sun.x + to_eye.x, sun.y + to_eye.y, sun.z + to_eye.z});
    // (Below 0.97, x^400 < 6e-6: no glint to a display level.)
    const vf toward_sun = Dot(rn, h);
    vf glint = Splat(0.f);
    if (Any(toward_sun > 0.97f)) {
      glint = Pow(Max(toward_sun, Splat(0.f)), Splat(400.f)) * 4.f * Shadow(k, n, p, distance_m);
    }
    // The reflected direction's sky (shaders.h's Sky).
    const vf two_cos = 2.f * Dot(rn, to_eye);
    const vf rz = rn.z * two_cos - to_eye.z;
    const vf up = Pow(Clamp01(rz), Splat(0.6f));
    const Vec3 sky = Mix(Splat(f.horizon), f.zenith, up);
    const Vec3 c{Mix(albedo.x * body, sky.x, fresnel) + glint,
                 Mix(albedo.y * body, sky.y, fresnel) + glint,
                 Mix(albedo.z * body, sky.z, fresnel) + glint};
    out.color = {Select(water, c.x, out.color.x), Select(water, c.y, out.color.y),
                 Select(water, c.z, out.color.z)};
    out.alpha = Select(water, Mix(0.55f + 0.45f * fresnel, Splat(1.f), haze), out.alpha);
  }
  return out;
}

// Loads kLanes values of row `row` from column x (the last columns repeated past the width).
template <typename T, typename V>
INLINE V Load(const std::vector<T>& data, int width, int row, int x) {
  const std::size_t start = std::size_t(row) * std::size_t(width);
  V v;
  if (x + kLanes <= width) {
    std::memcpy(&v, &data[start + std::size_t(x)], sizeof(V));
  } else {
    for (int i = 0; i < kLanes; ++i) v[i] = data[start + std::size_t(std::min(x + i, width - 1))];
  }
  return v;
}

}  // namespace

void ShadeRows(const ShadeConstants& k, const SurfaceLayer& opaque, const SurfaceLayer* translucent,
               int row_begin, int row_end, std::uint32_t* rgba, float* luma) {
  const LightingFrame& f = *k.frame;
  const Eigen::Matrix4f& M = f.clip_to_world;
  const int w = k.width, h = k.height;
  const vf lane = ToF(LaneIndex());
  for (int y0 = row_begin; y0 < row_end; y0 += 2) {
    const int rows[2] = {y0, std::min(y0 + 1, h - 1)};
    for (int x = 0; x < w; x += kLanes) {
      const vf ndc_x = (float(x) + lane + 0.5f) * (2.f / float(w)) - 1.f;
      // Both rows' points (camera-centred world), for the derivatives of a 2 x 2 quad.
      Vec3 p[2];
      vf depth[2];
      for (int r = 0; r < 2; ++r) {
        depth[r] = Load<float, vf>(opaque.depth, w, rows[r], x);
        const vf ndc_y = Splat((float(rows[r]) + 0.5f) * (2.f / float(h)) - 1.f);
        const vf d = Select(depth[r] > 0.f, depth[r], Splat(0.5f));
        const vf inv_w = 1.f / (M(3, 0) * ndc_x + M(3, 1) * ndc_y + M(3, 2) * d + M(3, 3));
        p[r] = {(M(0, 0) * ndc_x + M(0, 1) * ndc_y + M(0, 2) * d + M(0, 3)) * inv_w,
                (M(1, 0) * ndc_x + M(1, 1) * ndc_y + M(1, 2) * d + M(1, 3)) * inv_w,
                (M(2, 0) * ndc_x + M(2, 1) * ndc_y + M(2, 2) * d + M(2, 3)) * inv_w};
      }
      // d(x, y)/d(column) and d(x, y)/d(row), one per quad.
      const vf derivatives[4] = {
          QuadRight(p[0].x) - QuadLeft(p[0].x), QuadLeft(p[1].x) - QuadLeft(p[0].x),
          QuadRight(p[0].y) - QuadLeft(p[0].y), QuadLeft(p[1].y) - QuadLeft(p[0].y)};
      for (int r = 0; r < (rows[1] != rows[0] ? 2 : 1); ++r) {
        const int row = rows[r];
        const vi sky = depth[r] <= 0.f;
        vi out[3] = {vi{}, vi{}, vi{}};
        // The sky, where nothing was drawn: gradient and the sun's disc (display values).
        if (Any(sky)) {
          const Vec3 d = Normalize(p[r]);
          const vf up = Pow(Clamp01(d.z), Splat(0.6f));
          const vf disc = SmoothStep(0.99985f, 0.99995f, Dot(d, Splat(f.sun)));
          const Eigen::Vector3f sun_rgb(1.f, 0.98f, 0.9f);
          for (int c = 0; c < 3; ++c) {
            const vf s =
                Mix(Mix(Splat(f.sky_horizon_display[c]), Splat(f.sky_zenith_display[c]), up),
                    Splat(sun_rgb[c]), disc);
            out[c] = ToI(Clamp01(s) * 255.f + 0.5f);
          }
        }
        if (Any(~sky)) {
          const vu a = Load<std::uint32_t, vu>(opaque.albedo, w, row, x);
          const vu nw = Load<std::uint32_t, vu>(opaque.normal, w, row, x);
          const Vec3 n = DecodeNormal(nw);
          const vf ar = Byte(a, 0) * (1.f / 255.f), ag = Byte(a, 1) * (1.f / 255.f),
                   ab = Byte(a, 2) * (1.f / 255.f);
          const vi code = __builtin_bit_cast(vi, a >> 24);
          const vf distance_m = Sqrt(Dot(p[r], p[r]));
          const vf haze = Haze(f, distance_m);
          const Shaded s = ShadeSurface(k, p[r], n, {ar * ar, ag * ag, ab * ab}, code,
                                        Byte(nw, 3) * (1.f / 255.f), distance_m, haze, derivatives);
          const vf color[3] = {s.color.x, s.color.y, s.color.z};
          for (int c = 0; c < 3; ++c) {
            out[c] = Select(sky, out[c], Out(k, Mix(color[c], Splat(f.horizon[c]), haze)));
          }
        }
        // The nearest translucent surface over it, blended as GL blends (display values).
        if (translucent != nullptr) {
          const vf t_depth = Load<float, vf>(translucent->depth, w, row, x);
          const vi over = t_depth > depth[r];
          if (Any(over)) {
            const vf ndc_y = Splat((float(row) + 0.5f) * (2.f / float(h)) - 1.f);
            const vf d = Select(over, t_depth, Splat(0.5f));
            const vf inv_w = 1.f / (M(3, 0) * ndc_x + M(3, 1) * ndc_y + M(3, 2) * d + M(3, 3));
            const Vec3 tp{(M(0, 0) * ndc_x + M(0, 1) * ndc_y + M(0, 2) * d + M(0, 3)) * inv_w,
                          (M(1, 0) * ndc_x + M(1, 1) * ndc_y + M(1, 2) * d + M(1, 3)) * inv_w,
                          (M(2, 0) * ndc_x + M(2, 1) * ndc_y + M(2, 2) * d + M(2, 3)) * inv_w};
            const vu a = Load<std::uint32_t, vu>(translucent->albedo, w, row, x);
            const vu nw = Load<std::uint32_t, vu>(translucent->normal, w, row, x);
            const vi code = __builtin_bit_cast(vi, nw >> 24);
            const vf ar = Byte(a, 0) * (1.f / 255.f), ag = Byte(a, 1) * (1.f / 255.f),
                     ab = Byte(a, 2) * (1.f / 255.f);
            const vf distance_m = Sqrt(Dot(tp, tp));
            const vf haze = Haze(f, distance_m);
            const Shaded s =
                ShadeSurface(k, tp, DecodeNormal8(nw), {ar * ar, ag * ag, ab * ab}, code,
                             Byte(nw, 2) * (1.f / 255.f), distance_m, haze, derivatives);
            const vf alpha =
                Select((code & 7) == int(SurfaceKind::kWater), s.alpha, Byte(a, 3) * (1.f / 255.f));
            const vf color[3] = {s.color.x, s.color.y, s.color.z};
            for (int c = 0; c < 3; ++c) {
              const vf src = ToF(Out(k, Mix(color[c], Splat(f.horizon[c]), haze)));
              out[c] = Select(over, ToI(src * alpha + ToF(out[c]) * (1.f - alpha) + 0.5f), out[c]);
            }
          }
        }
        const std::size_t at = std::size_t(row) * std::size_t(w) + std::size_t(x);
        const vi words = out[0] | out[1] << 8 | out[2] << 16 | int(0xff000000u);
        if (x + kLanes <= w) {
          std::memcpy(rgba + at, &words, sizeof(words));
        } else {
          for (int i = 0; x + i < w; ++i) rgba[at + std::size_t(i)] = std::uint32_t(words[i]);
        }
        if (luma != nullptr) {
          const vf l = (0.299f / 255.f) * ToF(out[0]) + (0.587f / 255.f) * ToF(out[1]) +
                       (0.114f / 255.f) * ToF(out[2]);
          if (x + kLanes <= w) {
            std::memcpy(luma + at, &l, sizeof(l));
          } else {
            for (int i = 0; x + i < w; ++i) luma[at + std::size_t(i)] = l[i];
          }
        }
      }
    }
  }
}

int EdgesOfRow(const float* luma, int w, int h, int row, int* columns) {
  int count = 0;
  const float* above = luma + std::size_t(std::max(row - 1, 0)) * std::size_t(w);
  const float* here = luma + std::size_t(row) * std::size_t(w);
  const float* below = luma + std::size_t(std::min(row + 1, h - 1)) * std::size_t(w);
  for (int x = 0; x < w; x += kLanes) {
    vf m, a, b, c, d;
    if (x >= 1 && x + kLanes + 1 <= w) {
      std::memcpy(&m, here + x, sizeof(vf));
      std::memcpy(&a, above + x - 1, sizeof(vf));
      std::memcpy(&b, above + x + 1, sizeof(vf));
      std::memcpy(&c, below + x - 1, sizeof(vf));
      std::memcpy(&d, below + x + 1, sizeof(vf));
    } else {
      for (int i = 0; i < kLanes; ++i) {
        const int xi = std::min(x + i, w - 1);
        const int lo = std::max(xi - 1, 0), hi = std::min(xi + 1, w - 1);
        m[i] = here[xi], a[i] = above[lo], b[i] = above[hi], c[i] = below[lo], d[i] = below[hi];
      }
    }
    const vf lo = Min(m, Min(Min(a, b), Min(c, d))), hi = Max(m, Max(Max(a, b), Max(c, d)));
    const vi edges = hi - lo >= Max(Splat(1.f / 32.f), hi * (1.f / 8.f));
    if (!Any(edges)) continue;
    for (int i = 0; i < kLanes && x + i < w; ++i) {
      if (edges[i]) columns[count++] = x + i;
    }
  }
  return count;
}

}  // namespace sandbox::render::SANDBOX_ISA
