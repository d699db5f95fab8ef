#pragma once
// The renderer's GLSL (4.50 core). Positions reach the shaders relative to
// the camera ("camera-centred world": world axes, origin at the camera), so
// floats keep their precision however far from the world origin.

namespace sandbox::render::shaders {

// Scene geometry: colour, segment id and camera-frame normal at once (the
// outputs a pass has no attachment for are dropped).
inline constexpr const char* kSceneVertex = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec2 uv;
layout(location = 3) in vec2 lightmap_uv;
layout(location = 4) in vec4 vertex_rgba;
layout(location = 5) in uint vertex_segment;
uniform mat4 model;       // object to camera-centred world
uniform mat4 view_proj;   // camera-centred world to clip
uniform int vertex_color_space;  // to the shading space: 0 as they are, 1 decode sRGB, 2 encode
out vec3 world_normal;
out vec3 rel_position;
out vec2 tex_uv;
out vec2 baked_uv;
out vec4 vertex_color;
flat out uint segment_of_vertex;
void main() {
  vec4 p = model * vec4(position, 1.0);
  world_normal = mat3(model) * normal;
  rel_position = p.xyz;
  tex_uv = uv;
  baked_uv = lightmap_uv;
  vec3 c = clamp(vertex_rgba.rgb, 0.0, 1.0);
  if (vertex_color_space == 1) c = mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
  if (vertex_color_space == 2) c = mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
  vertex_color = vec4(c, vertex_rgba.a);
  segment_of_vertex = vertex_segment;
  gl_Position = view_proj * p;
}
)";

// What the scene's programs share: the frame's uniforms and the shading of a
// surface point from its albedo, normal and position. Compiled for each use
// with defines after the version line (llvmpipe runs every branch of a
// shader, and a shader that may discard loses the early depth test, so each
// program holds only what its draws use):
//   the look: GAMMA (shade in linear light, write sRGB), MATERIALS, SHADOWS;
//   the scene program's surface: SURFACE 0 plain, 1 terrain, 2 water;
//   the mesh: TEXTURE, LIGHTMAP, NORMAL_MAP, ALPHA_MASK, VERTEX_COLORS,
//     TRIANGLE_SEGMENTS (per-triangle ids for robots' bones);
//   the outputs: DATA (segment and normal too), DATA_ONLY (only those),
//     GBUFFER (what deferred shading needs, not the colour), TRANSLUCENT (of
//     a translucent surface: with its alpha, depth and code).
// Colours reach them in the shading space (linear with GAMMA, else display).
inline constexpr const char* kShading = R"(
uniform vec3 sun;
uniform vec3 horizon;             // the sky's colours, shading space
uniform vec3 zenith;
uniform vec2 fog;                 // start, end; end <= 0: none
uniform float camera_z;           // the camera's world height: heights for the ground's layers
uniform vec2 camera_xy;           // the camera's world x, y modulo 6900 m (patterns repeat there)
uniform float water_level;
uniform float snow_line;
uniform vec3 ground_rgb[4];       // grass, rock, snow, sand; shading space
uniform sampler2DArray detail;    // grass, rock, snow, sand
uniform sampler2DArrayShadow shadow_map;
uniform mat4 shadow_clip[4];
uniform float cascade_far[4];
uniform float shadow_texel[4];
uniform int cascades;
uniform vec3 view_axis;           // the camera's optical axis in the world

// Value noise on a 1-unit lattice; the lattice's hash is integer arithmetic
// (llvmpipe's sin costs several times as much).
float Hash(vec2 p) {
  uvec2 q = uvec2(ivec2(p)) * uvec2(1597334673u, 3812015801u);
  return float(((q.x ^ q.y) * 1597334673u) >> 8) * (1.0 / 16777216.0);
}
float Noise(vec2 p) {
  vec2 i = floor(p), f = fract(p);
  vec2 s = f * f * (3.0 - 2.0 * f);
  return mix(mix(Hash(i), Hash(i + vec2(1, 0)), s.x), mix(Hash(i + vec2(0, 1)), Hash(i + vec2(1, 1)), s.x), s.y);
}

// The sun's light reaching point p (camera-centred) of a surface with normal n: 0 in shadow.
float Shadow(vec3 n, vec3 p) {
#if SHADOWS == 0
  return 1.0;
#else
  float view_depth = dot(p, view_axis);
  if (view_depth > cascade_far[cascades - 1]) return 1.0;
  int c = 0;
  while (c < cascades - 1 && view_depth > cascade_far[c]) ++c;
  // Pushed off the surface along its normal, more where the sun grazes it: no acne.
  float grazing = 1.0 - clamp(dot(n, sun), 0.0, 1.0);
  vec4 q = shadow_clip[c] * vec4(p + n * ((0.4 + 1.5 * grazing) * shadow_texel[c]), 1.0);
  vec2 st = 0.5 * q.xy + 0.5;
  if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0)))) return 1.0;
  return texture(shadow_map, vec4(st, float(c), q.z));  // bilinear percentage-closer
#endif
}

// The shading space to display values (sRGB).
vec3 Out(vec3 c) {
#if GAMMA == 1
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
#else
  return c;
#endif
}

// The sky's colour in direction d (the sky pass's gradient, without the sun).
vec3 Sky(vec3 d) {
  return mix(horizon, zenith, pow(clamp(d.z, 0.0, 1.0), 0.6));
}

// How much of the horizon's colour covers a surface `distance_m` away.
float Haze(float distance_m) {
  return fog.y > 0.0 ? clamp((distance_m - fog.x) / max(fog.y - fog.x, 1e-3), 0.0, 1.0) : 0.0;
}

// Ground: sand by the water, rock on steep slopes, snow high up, grass elsewhere;
// `base` is the imagery's colour, or without imagery the grass varied by noise.
// st_dx, st_dy: the screen derivatives of the world position's x, y.
vec3 GroundAlbedo(vec3 base, bool imagery, vec3 n, vec3 p, float distance_m, vec2 st_dx, vec2 st_dy) {
  vec2 st = p.xy + camera_xy;
  float height = camera_z + p.z;
  float up = clamp(n.z, 0.0, 1.0);
  float rock = smoothstep(0.82, 0.7, up);
  float snow = 0.0;
  if (height > snow_line - 250.0) {  // the noise moves the line by 100 m at most
    snow = smoothstep(snow_line - 150.0, snow_line + 150.0, height + 200.0 * (Noise(0.01 * st) - 0.5)) * (1.0 - rock);
  }
  float sand = (1.0 - smoothstep(water_level + 0.8, water_level + 2.5, height)) * (1.0 - rock);
  vec3 ground = imagery ? base : ground_rgb[0] * (0.85 + 0.3 * Noise(0.05 * st));
  ground = mix(ground, ground_rgb[3], sand);
  ground = mix(ground, ground_rgb[1], rock);
  ground = mix(ground, ground_rgb[2], snow);
  // Detail texture: world-anchored, one scale (the colour noise or imagery above
  // hides its tiling; a second scale cost a fifth of a frame); fades with distance.
  int layer = rock > 0.5 ? 1 : snow > 0.5 ? 2 : sand > 0.5 ? 3 : 0;
  float fade = smoothstep(60.0, 400.0, distance_m);
  float d = 1.0;
  if (fade < 1.0) {
    d = 2.0 * textureGrad(detail, vec3(st / 3.0, float(layer)), st_dx / 3.0, st_dy / 3.0).r;
  }
  return ground * mix(d, 1.0, fade);
}

// Sun (with its shadow) and sky light on a surface of `albedo` at p with normal n;
// with MATERIALS, the sun's highlight by metalness and roughness.
vec3 Lit(vec3 albedo, vec3 n, vec3 p, float distance_m, vec2 metal_rough) {
#if GAMMA == 1
  float sun_light = max(dot(n, sun), 0.0) * Shadow(n, p);
  // Sky light from above, less from the ground below.
  vec3 lit = albedo * (0.75 * sun_light + 0.25 * mix(0.55, 1.0, 0.5 + 0.5 * n.z));
#if MATERIALS == 1
  if (metal_rough.y < 0.95 && sun_light > 0.0) {
    vec3 h = normalize(sun - p / max(distance_m, 1e-6));
    float shininess = 2.0 / max(metal_rough.y * metal_rough.y, 0.002);
    vec3 f0 = mix(vec3(0.04), albedo, metal_rough.x);
    lit += f0 * pow(max(dot(n, h), 0.0), shininess) * sun_light * (shininess + 8.0) / 32.0;
  }
#endif
  return lit;
#else
  return albedo * (0.35 + 0.65 * abs(dot(n, sun)));  // the plain look
#endif
}

// G-buffer codes: a surface's kind (deferred_shading.h's SurfaceKind) + 8 x
// metalness (0..31); and its normal, octahedral in 12 + 12 bits, with roughness.
const int kLitSurface = 0, kGround = 1, kGroundImagery = 2, kPrelit = 3, kWater = 4;
vec4 PackNormal(vec3 n, float roughness) {
  n /= abs(n.x) + abs(n.y) + abs(n.z);
  vec2 o = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
  uvec2 q = uvec2(round(clamp(0.5 * o + 0.5, 0.0, 1.0) * 4095.0));
  return vec4(float(q.x >> 4u), float(((q.x & 15u) << 4u) | (q.y >> 8u)), float(q.y & 255u),
              round(255.0 * clamp(roughness, 0.0, 1.0))) / 255.0;
}
// Translucent surfaces: the normal in 8 + 8 bits, roughness, the code.
vec4 PackNormalAndCode(vec3 n, float roughness, int code) {
  n /= abs(n.x) + abs(n.y) + abs(n.z);
  vec2 o = n.z >= 0.0 ? n.xy : (1.0 - abs(n.yx)) * vec2(n.x >= 0.0 ? 1.0 : -1.0, n.y >= 0.0 ? 1.0 : -1.0);
  return vec4(round(clamp(0.5 * o + 0.5, 0.0, 1.0) * 255.0), round(255.0 * clamp(roughness, 0.0, 1.0)),
              float(code)) / 255.0;
}
)";

// Scene geometry: colour (or, with GBUFFER, what deferred shading needs:
// deferred_shading.h's SurfaceLayer), segment id and camera-frame normal at
// once (the outputs a pass has no attachment for are dropped).
inline constexpr const char* kSceneFragment = R"(
in vec3 world_normal;
in vec3 rel_position;
in vec2 tex_uv;
in vec2 baked_uv;
in vec4 vertex_color;
flat in uint segment_of_vertex;
layout(location = 0) out vec4 color;  // with GBUFFER: sqrt(albedo), code or alpha
#if DATA == 1 || DATA_ONLY == 1
layout(location = 1) out uint segment;
layout(location = 2) out vec4 camera_normal;
#endif
#if GBUFFER == 1
layout(location = 3) out vec4 g_normal;  // PackNormal; TRANSLUCENT: PackNormalAndCode
#endif

uniform vec4 base_color;          // shading space
uniform sampler2D base_texture;   // sampled in the shading space
uniform sampler2D lightmap;       // baked lighting replaces the sun (Quake 3 maps)
uniform sampler2D normal_texture;
uniform float alpha_cutoff;
uniform vec2 metal_rough;
uniform mat3 world_to_camera;     // rows: camera x (forward), y (left), z up
uniform uint segment_base;
uniform usamplerBuffer segments;  // per triangle, added to segment_base

void main() {
  vec4 albedo = base_color;
#if TEXTURE == 1
  albedo *= texture(base_texture, tex_uv);
#endif
#if VERTEX_COLORS == 1
  albedo *= vertex_color;
#endif
#if ALPHA_MASK == 1
  if (albedo.a < alpha_cutoff) discard;
  albedo.a = 1.0;
#endif

  vec3 n = normalize(world_normal);
  if (!gl_FrontFacing) n = -n;  // thin surfaces: the side seen
#if DATA == 1 || DATA_ONLY == 1
#if TRIANGLE_SEGMENTS == 1
  segment = segment_base + segment_of_vertex + texelFetch(segments, gl_PrimitiveID).r;
#else
  segment = segment_base + segment_of_vertex;
#endif
  camera_normal = vec4(world_to_camera * n, 1.0);
#endif
#if DATA_ONLY == 1
  color = vec4(0.0);
}
#else
#if NORMAL_MAP == 1
  {
    // Tangent frame from the screen derivatives of position and uv.
    vec3 dp1 = dFdx(rel_position), dp2 = dFdy(rel_position);
    vec2 du1 = dFdx(tex_uv), du2 = dFdy(tex_uv);
    vec3 a = cross(dp2, n), b = cross(n, dp1);
    vec3 t = a * du1.x + b * du2.x, bt = a * du1.y + b * du2.y;
    float scale = inversesqrt(max(max(dot(t, t), dot(bt, bt)), 1e-20));
    vec3 m = texture(normal_texture, tex_uv).xyz * 2.0 - 1.0;
    n = normalize(mat3(t * scale, bt * scale, n) * m);
  }
#endif

  float distance_m = length(rel_position);
#if GBUFFER == 1
  // Deferred: the surface's albedo (lit already under a lightmap), normal and kind.
  int kind = kLitSurface;
  vec3 base = albedo.rgb;
#if LIGHTMAP == 1
#if SURFACE == 1 && MATERIALS == 1
  base = GroundAlbedo(base, TEXTURE == 1, n, rel_position, distance_m, dFdx(rel_position.xy), dFdy(rel_position.xy));
#endif
  // Quake 3 stores lightmaps at half brightness (its "overbright" bit): twice the display value.
  base *= min((GAMMA == 1 ? 4.595 : 2.0) * texture(lightmap, baked_uv).rgb, vec3(1.0));
  kind = kPrelit;
#elif SURFACE == 1 && MATERIALS == 1
  kind = TEXTURE == 1 ? kGroundImagery : kGround;
#elif SURFACE == 2 && MATERIALS == 1
  kind = kWater;
#endif
  int code = kind + 8 * int(round(31.0 * clamp(metal_rough.x, 0.0, 1.0)));
#if TRANSLUCENT == 1
  color = vec4(sqrt(base), albedo.a);
  g_normal = PackNormalAndCode(n, metal_rough.y, code);
#else
  color = vec4(sqrt(base), float(code) / 255.0);
  g_normal = PackNormal(n, metal_rough.y);
#endif
}
#else
#if SURFACE == 2 && MATERIALS == 1
  {
    // Water: ripples, the sky reflected by Fresnel's law, the sun's glint.
    float haze = Haze(distance_m);
    vec3 to_eye = -rel_position / max(distance_m, 1e-6);
    vec2 p = rel_position.xy + camera_xy;
    vec3 rn = normalize(vec3(0.06 * (Noise(0.7 * p) - 0.5) + 0.04 * (Noise(2.3 * p.yx) - 0.5),
                             0.06 * (Noise(0.7 * p + 17.0) - 0.5) + 0.04 * (Noise(2.3 * p + 5.0) - 0.5), 1.0));
    float cos_i = clamp(dot(rn, to_eye), 0.0, 1.0);
    float fresnel = 0.02 + 0.98 * pow(1.0 - cos_i, 5.0);
    vec3 body = albedo.rgb * (0.35 + 0.4 * max(sun.z, 0.0));
    vec3 h = normalize(sun + to_eye);
    float glint = pow(max(dot(rn, h), 0.0), 400.0) * 4.0 * Shadow(n, rel_position);
    vec3 c = mix(body, Sky(reflect(-to_eye, rn)), fresnel) + vec3(glint);
    color = vec4(Out(mix(c, horizon, haze)), mix(0.55 + 0.45 * fresnel, 1.0, haze));
    return;
  }
#endif
#if SURFACE == 1 && MATERIALS == 1
  albedo.rgb = GroundAlbedo(albedo.rgb, TEXTURE == 1, n, rel_position, distance_m, dFdx(rel_position.xy), dFdy(rel_position.xy));
#endif
#if LIGHTMAP == 1
  // Quake 3 stores lightmaps at half brightness (its "overbright" bit): twice the display value.
  vec3 lit = albedo.rgb * min((GAMMA == 1 ? 4.595 : 2.0) * texture(lightmap, baked_uv).rgb, vec3(1.0));
#else
  vec3 lit = Lit(albedo.rgb, n, rel_position, distance_m, metal_rough);
#endif
  color = vec4(Out(mix(lit, horizon, Haze(distance_m))), albedo.a);
}
#endif
#endif
)";

// Shadow maps: depth only; cut-outs cut.
inline constexpr const char* kShadowVertex = R"(#version 450 core
layout(location = 0) in vec3 position;
layout(location = 2) in vec2 uv;
uniform mat4 model;
uniform mat4 view_proj;
out vec2 tex_uv;
void main() {
  tex_uv = uv;
  gl_Position = view_proj * (model * vec4(position, 1.0));
}
)";

// Without ALPHA_MASK it does nothing (depth only, tested early); with it, cut-outs cut.
inline constexpr const char* kShadowFragment = R"(
in vec2 tex_uv;
uniform float alpha_cutoff;
uniform sampler2D base_texture;
void main() {
#if ALPHA_MASK == 1
  if (texture(base_texture, tex_uv).a < alpha_cutoff) discard;
#endif
}
)";

// The overlay: coloured points and lines, pulled 0.2% towards the camera so
// that marks lying on a surface are not hidden by it.
inline constexpr const char* kOverlayVertex = R"(#version 450 core
layout(location = 0) in vec3 position;  // camera-centred world
layout(location = 1) in vec3 rgb;
uniform mat4 view_proj;
out vec3 mark_rgb;
void main() {
  mark_rgb = rgb;
  gl_Position = view_proj * vec4(0.998 * position, 1.0);
}
)";

inline constexpr const char* kOverlayFragment = R"(#version 450 core
in vec3 mark_rgb;
out vec4 color;
void main() { color = vec4(mark_rgb, 1.0); }
)";

// A triangle covering the screen (the sky, the edge filter); ndc: its
// normalised device coordinates.
inline constexpr const char* kFullScreenVertex = R"(#version 450 core
out vec2 ndc;
void main() {
  ndc = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(ndc, 0.0, 1.0);
}
)";

// The sky, where no surface was drawn: light at the horizon (the haze
// colour, so distant ground fades into it), deeper overhead, with the sun's disc.
inline constexpr const char* kSkyFragment = R"(#version 450 core
in vec2 ndc;
uniform mat4 clip_to_world;  // directions: clip to camera-centred world
uniform vec3 horizon;
uniform vec3 zenith;
uniform vec3 sun;
out vec4 color;
void main() {
  vec4 far_point = clip_to_world * vec4(ndc, 0.5, 1.0);
  vec3 d = normalize(far_point.xyz / far_point.w);
  float up = clamp(d.z, 0.0, 1.0);
  vec3 c = mix(horizon, zenith, pow(up, 0.6));
  float s = dot(d, sun);
  c = mix(c, vec3(1.0, 0.98, 0.9), smoothstep(0.99985, 0.99995, s));
  color = vec4(c, 1.0);
}
)";

// The edge filter (the approach of Lottes' FXAA, console variant): a pixel
// whose luma differs little from its four diagonal neighbours' stays as it
// is; on an edge it is averaged along the edge's direction (across the
// luma gradient), two or four taps, the wider only if it stays within the
// neighbourhood's luma range. Reads the finished (display-encoded) image.
inline constexpr const char* kEdgeFilterFragment = R"(#version 450 core
uniform sampler2D image;  // bilinear, clamped to its edge
out vec4 color;
float Luma(vec3 c) { return dot(c, vec3(0.299, 0.587, 0.114)); }
void main() {
  ivec2 size = textureSize(image, 0);
  ivec2 p = ivec2(gl_FragCoord.xy);
  ivec2 lo_p = max(p - 1, ivec2(0)), hi_p = min(p + 1, size - 1);
  vec3 m = texelFetch(image, p, 0).rgb;
  float l_m = Luma(m);
  float l_a = Luma(texelFetch(image, lo_p, 0).rgb);
  float l_b = Luma(texelFetch(image, ivec2(hi_p.x, lo_p.y), 0).rgb);
  float l_c = Luma(texelFetch(image, ivec2(lo_p.x, hi_p.y), 0).rgb);
  float l_d = Luma(texelFetch(image, hi_p, 0).rgb);
  float lo = min(l_m, min(min(l_a, l_b), min(l_c, l_d)));
  float hi = max(l_m, max(max(l_a, l_b), max(l_c, l_d)));
  if (hi - lo < max(1.0 / 32.0, hi / 8.0)) discard;  // not an edge: the pixel stays
  // Along the edge: the luma gradient (x, y) turned to (y, -x).
  vec2 dir = vec2((l_c + l_d) - (l_a + l_b), (l_a + l_c) - (l_b + l_d));
  float reduce = max((l_a + l_b + l_c + l_d) / 32.0, 1.0 / 128.0);
  vec2 px = 1.0 / vec2(size), uv = gl_FragCoord.xy * px;
  dir = clamp(dir / (min(abs(dir.x), abs(dir.y)) + reduce), vec2(-8.0), vec2(8.0)) * px;
  vec3 near_pair = 0.5 * (texture(image, uv - dir / 6.0).rgb + texture(image, uv + dir / 6.0).rgb);
  vec3 wide = 0.5 * near_pair +
              0.25 * (texture(image, uv - dir / 2.0).rgb + texture(image, uv + dir / 2.0).rgb);
  float l_wide = Luma(wide);
  color = vec4(l_wide < lo || l_wide > hi ? near_pair : wide, 1.0);
}
)";

}  // namespace sandbox::render::shaders
