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
  vertex_color = vertex_rgba;
  segment_of_vertex = vertex_segment;
  gl_Position = view_proj * p;
}
)";

// Compiled for each use with defines after the version line: SURFACE 0
// (plain), 1 (terrain) or 2 (water); GAMMA, MATERIALS, SHADOWS (the look's
// switches) and DATA_ONLY (segment and normal only) 0 or 1. llvmpipe runs
// every branch of a shader, so each program holds only what it uses.
inline constexpr const char* kSceneFragment = R"(
in vec3 world_normal;
in vec3 rel_position;
in vec2 tex_uv;
in vec2 baked_uv;
in vec4 vertex_color;
flat in uint segment_of_vertex;
layout(location = 0) out vec4 color;
layout(location = 1) out uint segment;
layout(location = 2) out vec4 camera_normal;

uniform vec4 base_color;          // as the material gives it
uniform bool linear_factor;       // base_color is linear (glTF); else display (sRGB)
uniform bool has_texture;
uniform sampler2D base_texture;   // sRGB texels, sampled linear
uniform bool has_lightmap;        // baked lighting replaces the sun (Quake 3 maps)
uniform sampler2D lightmap;
uniform bool has_normal_map;
uniform sampler2D normal_texture;
uniform int alpha_mode;           // 0 opaque, 1 mask, 2 blend
uniform float alpha_cutoff;
uniform vec2 metal_rough;
uniform float camera_z;           // the camera's world height: heights for the ground's layers
uniform vec2 camera_xy;           // the camera's world x, y modulo 6900 m (patterns repeat there)
uniform float water_level;
uniform float snow_line;
uniform vec3 grass_rgb;           // display colours
uniform sampler2DArray detail;    // grass, rock, snow, sand
uniform vec3 sun;
uniform vec3 horizon;             // display colours of the sky
uniform vec3 zenith;
uniform vec2 fog;                 // start, end; end <= 0: none
uniform sampler2DArrayShadow shadow_map;
uniform mat4 shadow_clip[4];
uniform float cascade_far[4];
uniform float shadow_texel[4];
uniform int cascades;
uniform vec3 view_axis;           // the camera's optical axis in the world
uniform mat3 world_to_camera;     // rows: camera x (forward), y (left), z (up)
uniform uint segment_base;
uniform bool triangle_segments;
uniform usamplerBuffer segments;  // per triangle, added to segment_base

vec3 Decode(vec3 c) {  // sRGB to linear
  return mix(c / 12.92, pow((c + 0.055) / 1.055, vec3(2.4)), step(0.04045, c));
}
vec3 Encode(vec3 c) {  // linear to sRGB
  c = clamp(c, 0.0, 1.0);
  return mix(12.92 * c, 1.055 * pow(c, vec3(1.0 / 2.4)) - 0.055, step(0.0031308, c));
}
// Display colours to the shading space and back.
vec3 In(vec3 display) { return GAMMA == 1 ? Decode(display) : display; }
vec3 Out(vec3 shaded) { return GAMMA == 1 ? Encode(shaded) : shaded; }

float Hash(vec2 p) { return fract(sin(dot(p, vec2(127.1, 311.7))) * 43758.5453); }
float Noise(vec2 p) {
  vec2 i = floor(p), f = fract(p);
  vec2 s = f * f * (3.0 - 2.0 * f);
  return mix(mix(Hash(i), Hash(i + vec2(1, 0)), s.x), mix(Hash(i + vec2(0, 1)), Hash(i + vec2(1, 1)), s.x), s.y);
}

float Shadow(vec3 n, float view_depth) {
#if SHADOWS == 0
  return 1.0;
#else
  int c = 0;
  while (c < cascades - 1 && view_depth > cascade_far[c]) ++c;
  if (view_depth > cascade_far[cascades - 1]) return 1.0;
  // Pushed off the surface along its normal by about a texel: no acne.
  vec3 p = rel_position + n * (1.5 * shadow_texel[c]);
  vec4 q = shadow_clip[c] * vec4(p, 1.0);
  vec2 st = 0.5 * q.xy + 0.5;
  if (any(lessThan(st, vec2(0.0))) || any(greaterThan(st, vec2(1.0)))) return 1.0;
  vec2 texel = 1.0 / vec2(textureSize(shadow_map, 0).xy);
  float lit = 0.0;
  for (int k = 0; k < 4; ++k) {
    vec2 o = vec2((k & 1) == 1 ? 0.5 : -0.5, (k & 2) == 2 ? 0.5 : -0.5) * texel;
    lit += texture(shadow_map, vec4(st + o, float(c), q.z));
  }
  return 0.25 * lit;
#endif
}

// The sky's colour in direction d (the sky pass's gradient, without the sun).
vec3 Sky(vec3 d) {
  return mix(horizon, zenith, pow(clamp(d.z, 0.0, 1.0), 0.6));
}

void main() {
#if GAMMA == 1
  vec4 albedo = vec4(linear_factor ? base_color.rgb : Decode(base_color.rgb), base_color.a);
#else
  vec4 albedo = vec4(linear_factor ? Encode(base_color.rgb) : base_color.rgb, base_color.a);
#endif
  if (has_texture) {
    vec4 t = texture(base_texture, tex_uv);
    albedo *= vec4(GAMMA == 1 ? t.rgb : Encode(t.rgb), t.a);
  }
  albedo *= vec4(In(vertex_color.rgb), vertex_color.a);
  if (alpha_mode == 1 && albedo.a < alpha_cutoff) discard;
  if (alpha_mode == 1) albedo.a = 1.0;

  vec3 n = normalize(world_normal);
  if (!gl_FrontFacing) n = -n;  // thin surfaces: the side seen
#if MATERIALS == 1 && DATA_ONLY == 0
  if (has_normal_map) {
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
  uint id = segment_base + segment_of_vertex;
  if (triangle_segments) id += texelFetch(segments, gl_PrimitiveID).r;
  segment = id;
  camera_normal = vec4(world_to_camera * n, 1.0);
#if DATA_ONLY == 1
  color = vec4(0.0);
}
#else

  float distance_m = length(rel_position);
  vec3 to_eye = -rel_position / max(distance_m, 1e-6);
  float specular = 0.0;
  float height = camera_z + rel_position.z;
#if SURFACE == 1 && MATERIALS == 1
  {
    // Ground: sand by the water, rock on steep slopes, snow high up, grass elsewhere.
    vec2 st = rel_position.xy + camera_xy;
    float up = clamp(n.z, 0.0, 1.0);
    float rock = smoothstep(0.82, 0.7, up);
    float snow = smoothstep(snow_line - 150.0, snow_line + 150.0, height + 200.0 * (Noise(0.01 * st) - 0.5)) * (1.0 - rock);
    float sand = (1.0 - smoothstep(water_level + 0.8, water_level + 2.5, height)) * (1.0 - rock);
    vec3 layers[4] = vec3[4](In(grass_rgb), In(vec3(0.45, 0.42, 0.38)), In(vec3(0.93, 0.94, 0.96)),
                             In(vec3(0.74, 0.67, 0.48)));
    vec3 grass = layers[0] * (0.85 + 0.3 * Noise(0.05 * st));
    vec3 ground = has_texture ? albedo.rgb : grass;
    ground = mix(ground, layers[3], sand);
    ground = mix(ground, layers[1], rock);
    ground = mix(ground, layers[2], snow);
    // Detail texture: world-anchored, two scales against visible tiling; fades with distance.
    vec2 world_xy = st;
    int layer = rock > 0.5 ? 1 : snow > 0.5 ? 2 : sand > 0.5 ? 3 : 0;
    float d = 2.0 * texture(detail, vec3(world_xy / 3.0, float(layer))).r *
              (2.0 * texture(detail, vec3(world_xy / 23.0, float(layer))).r);
    d = mix(d, 1.0, smoothstep(60.0, 400.0, distance_m));
    albedo.rgb = ground * d;
  }
#elif SURFACE == 2 && MATERIALS == 1
  {
    // Water: ripples, the sky reflected by Fresnel's law, the sun's glint.
    vec2 p = rel_position.xy + camera_xy;
    vec3 rn = normalize(vec3(0.06 * (Noise(0.7 * p) - 0.5) + 0.04 * (Noise(2.3 * p.yx) - 0.5),
                             0.06 * (Noise(0.7 * p + 17.0) - 0.5) + 0.04 * (Noise(2.3 * p + 5.0) - 0.5), 1.0));
    float cos_i = clamp(dot(rn, to_eye), 0.0, 1.0);
    float fresnel = 0.02 + 0.98 * pow(1.0 - cos_i, 5.0);
    vec3 reflected = In(Sky(reflect(-to_eye, rn)));
    vec3 body = albedo.rgb * (0.35 + 0.4 * max(sun.z, 0.0));
    vec3 h = normalize(sun + to_eye);
    float glint = pow(max(dot(rn, h), 0.0), 400.0) * 4.0 * Shadow(n, dot(rel_position, view_axis));
    vec3 c = mix(body, reflected, fresnel) + vec3(glint);
    float f = fog.y > 0.0 ? clamp((distance_m - fog.x) / max(fog.y - fog.x, 1e-3), 0.0, 1.0) : 0.0;
    color = vec4(Out(mix(c, In(horizon), f)), mix(0.55 + 0.45 * fresnel, 1.0, f));
    return;
  }
#endif

  vec3 lit;
  if (has_lightmap) {
    // Quake 3 stores lightmaps at half brightness (its "overbright" bit).
    lit = albedo.rgb * In(min(2.0 * texture(lightmap, baked_uv).rgb, vec3(1.0)));
  } else {
    float sun_light = max(dot(n, sun), 0.0) * Shadow(n, dot(rel_position, view_axis));
    // Sky light from above, less from the ground below.
    float sky_light = mix(0.55, 1.0, 0.5 + 0.5 * n.z);
#if GAMMA == 1
    lit = albedo.rgb * (0.75 * sun_light + 0.25 * sky_light);
#else
    lit = albedo.rgb * (0.35 + 0.65 * abs(dot(n, sun)));  // the plain look
#endif
#if MATERIALS == 1
    if (metal_rough.y < 0.95 && sun_light > 0.0) {
      vec3 h = normalize(sun + to_eye);
      float shininess = 2.0 / max(metal_rough.y * metal_rough.y, 0.002);
      vec3 f0 = mix(vec3(0.04), albedo.rgb, metal_rough.x);
      lit += f0 * pow(max(dot(n, h), 0.0), shininess) * sun_light * (shininess + 8.0) / 32.0;
    }
#endif
  }
  float f = fog.y > 0.0 ? clamp((distance_m - fog.x) / max(fog.y - fog.x, 1e-3), 0.0, 1.0) : 0.0;
  color = vec4(Out(mix(lit, In(horizon), f)), albedo.a);
}
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

inline constexpr const char* kShadowFragment = R"(#version 450 core
in vec2 tex_uv;
uniform bool masked;
uniform float alpha_cutoff;
uniform sampler2D base_texture;
void main() {
  if (masked && texture(base_texture, tex_uv).a < alpha_cutoff) discard;
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

// The sky: a full-screen triangle behind everything, light at the horizon
// (the haze colour, so distant ground fades into it), deeper overhead, with the sun's disc.
inline constexpr const char* kSkyVertex = R"(#version 450 core
out vec2 ndc;
void main() {
  ndc = vec2(gl_VertexID == 1 ? 3.0 : -1.0, gl_VertexID == 2 ? 3.0 : -1.0);
  gl_Position = vec4(ndc, 0.0, 1.0);
}
)";

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

}  // namespace sandbox::render::shaders
