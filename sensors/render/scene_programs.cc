#include "sensors/render/scene_programs.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "sensors/render/shaders.h"

namespace sandbox::render {
namespace {

constexpr double kPatternPeriod_m = 6900.0;  // the ground's and water's patterns repeat here
constexpr float kSnowLine_m = 2800.f;

void ApplyFrameUniforms(GlProgram& p, const FrameUniforms& u) {
  glUniformMatrix4fv(p.Uniform("view_proj"), 1, GL_FALSE, u.view_proj.data());
  glUniform3fv(p.Uniform("sun"), 1, u.sun.data());
  glUniform3fv(p.Uniform("horizon"), 1, u.horizon.data());
  glUniform3fv(p.Uniform("zenith"), 1, u.zenith.data());
  glUniform2fv(p.Uniform("fog"), 1, u.fog.data());
  glUniform1f(p.Uniform("camera_z"), u.camera_z);
  glUniform2fv(p.Uniform("camera_xy"), 1, u.camera_xy.data());
  glUniform1f(p.Uniform("water_level"), u.water_level);
  glUniform1f(p.Uniform("snow_line"), kSnowLine_m);
  glUniform3fv(p.Uniform("ground_rgb"), 4, u.ground[0].data());
  glUniform3fv(p.Uniform("view_axis"), 1, u.view_axis.data());
  glUniformMatrix3fv(p.Uniform("world_to_camera"), 1, GL_FALSE, u.R_CW.data());
  glUniform1i(p.Uniform("cascades"), int(u.cascades.size()));
  for (std::size_t c = 0; c < u.cascades.size(); ++c) {
    const std::string i = "[" + std::to_string(c) + "]";
    const Eigen::Matrix4f M = u.cascades[c].light_clip.cast<float>();
    glUniformMatrix4fv(p.Uniform("shadow_clip" + i), 1, GL_FALSE, M.data());
    glUniform1f(p.Uniform("cascade_far" + i), float(u.cascades[c].far_m));
    glUniform1f(p.Uniform("shadow_texel" + i), float(u.cascades[c].texel_m));
  }
}

}  // namespace

int SceneProgramKey(int look, scene::Surface surface, int features) {
  if (look & kDataOnly) {
    int key = kDataOnly | (features & (kAlphaMask | kTriangleSegments));
    if (features & kAlphaMask) key |= features & (kTexture | kVertexColors);
    return key;
  }
  int key = look | features | int(surface);
  if (!(look & kData)) key &= ~kTriangleSegments;
  if (!(look & kMaterials)) key &= ~kNormalMap;
  return key;
}

Eigen::Vector3f Zenith(const Eigen::Vector3f& horizon) {
  return 0.55f * horizon + Eigen::Vector3f(0.02f, 0.08f, 0.25f);
}

Eigen::Vector3f Shading(const Eigen::Vector3f& rgb, bool linear, bool gamma) {
  Eigen::Vector3f out;
  for (int i = 0; i < 3; ++i) {
    const float c = std::clamp(rgb[i], 0.f, 1.f);
    if (gamma && !linear) {
      out[i] = c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f);
    } else if (!gamma && linear) {
      out[i] = c <= 0.0031308f ? 12.92f * c : 1.055f * std::pow(c, 1.f / 2.4f) - 0.055f;
    } else {
      out[i] = c;
    }
  }
  return out;
}

FrameUniforms MakeFrameUniforms(const CameraView& view, const Eigen::Matrix4f& view_proj,
                                const RenderSettings& settings, const scene::Level& level,
                                const Eigen::Vector3d& camera_W, float water_level,
                                const std::vector<ShadowCascade>& cascades) {
  const bool gamma = settings.gamma_correct;
  FrameUniforms u;
  u.view_proj = view_proj;
  u.sun = settings.sun_direction_W.normalized();
  u.horizon = Shading(settings.sky_rgb, false, gamma);
  u.zenith = Shading(Zenith(settings.sky_rgb), false, gamma);
  // The haze: the level's visibility when it gives one.
  const bool default_fog = settings.fog_end_m == RenderSettings{}.fog_end_m;
  const double visibility = level.horizon ? level.horizon->visibility_m : 0.0;
  if (!settings.haze) {
    u.fog = Eigen::Vector2f::Zero();
  } else if (default_fog && visibility > 0.0) {
    u.fog = Eigen::Vector2f(float(0.1 * visibility), float(visibility));
  } else {
    u.fog = Eigen::Vector2f(settings.fog_start_m, settings.fog_end_m);
  }
  u.camera_z = float(camera_W.z());
  u.camera_xy = Eigen::Vector2f(float(std::fmod(camera_W.x(), kPatternPeriod_m)),
                                float(std::fmod(camera_W.y(), kPatternPeriod_m)));
  u.water_level = water_level;
  const Eigen::Vector3f grass =
      level.horizon ? level.horizon->rgb : Eigen::Vector3f(0.36f, 0.45f, 0.24f);
  const Eigen::Vector3f layers[4] = {
      grass, {0.45f, 0.42f, 0.38f}, {0.93f, 0.94f, 0.96f}, {0.74f, 0.67f, 0.48f}};
  for (int i = 0; i < 4; ++i) u.ground[i] = Shading(layers[i], false, gamma);
  u.view_axis = view.X_WC.linear().col(0).cast<float>();
  u.R_CW = view.X_WC.linear().transpose().cast<float>();
  u.cascades = cascades;
  return u;
}

LightingFrame LightingOf(const FrameUniforms& u, const RenderSettings& settings,
                         const Eigen::Matrix4f& clip_to_world, float lod_offset_per_m) {
  LightingFrame f;
  f.clip_to_world = clip_to_world;
  f.sun = u.sun;
  f.horizon = u.horizon;
  f.zenith = u.zenith;
  f.sky_horizon_display = settings.sky_rgb;
  f.sky_zenith_display = Zenith(settings.sky_rgb);
  f.fog = u.fog;
  f.camera_z = u.camera_z;
  f.camera_xy = u.camera_xy;
  f.water_level = u.water_level;
  f.snow_line = kSnowLine_m;
  for (int i = 0; i < 4; ++i) f.ground[std::size_t(i)] = u.ground[i];
  f.view_axis = u.view_axis;
  f.materials = settings.materials;
  f.lod_offset_per_m = lod_offset_per_m;
  return f;
}

ScenePrograms::ScenePrograms() {
  for (const bool masked : {false, true}) {
    const std::string fragment = std::string("#version 450 core\n#define ALPHA_MASK ") +
                                 (masked ? "1" : "0") + "\n" + shaders::kShadowFragment;
    GlProgram& program = shadow_[masked] =
        GlProgram(masked ? "cut-out shadow" : "shadow", shaders::kShadowVertex, fragment);
    program.Use();
    glUniform1i(program.Uniform("base_texture"), 0);
  }
}

GlProgram& ScenePrograms::Use(int key, long frame, const FrameUniforms& uniforms) {
  if (key == key_) return *current_;
  key_ = key;
  auto found = variants_.find(key);
  const bool made = found == variants_.end();
  if (made) {
    std::string fragment = "#version 450 core\n";
    const std::pair<const char*, int> defines[] = {
        {"SURFACE", key & 3},
        {"GAMMA", (key & kGamma) != 0},
        {"MATERIALS", (key & kMaterials) != 0},
        {"SHADOWS", (key & kShadows) != 0},
        {"DATA", (key & kData) != 0},
        {"DATA_ONLY", (key & kDataOnly) != 0},
        {"TEXTURE", (key & kTexture) != 0},
        {"LIGHTMAP", (key & kLightmap) != 0},
        {"NORMAL_MAP", (key & kNormalMap) != 0},
        {"ALPHA_MASK", (key & kAlphaMask) != 0},
        {"VERTEX_COLORS", (key & kVertexColors) != 0},
        {"TRIANGLE_SEGMENTS", (key & kTriangleSegments) != 0},
        {"GBUFFER", (key & kGBuffer) != 0},
        {"TRANSLUCENT", (key & kTranslucent) != 0}};
    for (const auto& [name, value] : defines) {
      fragment += "#define " + std::string(name) + " " + std::to_string(value) + "\n";
    }
    fragment += shaders::kShading;
    fragment += shaders::kSceneFragment;
    found = variants_.emplace(key, Variant{GlProgram("scene", shaders::kSceneVertex, fragment), -1})
                .first;
  }
  Variant& variant = found->second;
  current_ = &variant.program;
  current_->Use();
  if (made) {
    // Fixed sampler units: 0 base colour, 1 lightmap, 2 normal map, 3 detail,
    // 4 shadow map, 5 triangle segments.
    const std::pair<const char*, int> units[] = {{"base_texture", 0},   {"lightmap", 1},
                                                 {"normal_texture", 2}, {"detail", 3},
                                                 {"shadow_map", 4},     {"segments", 5}};
    for (const auto& [name, unit] : units) glUniform1i(current_->Uniform(name), unit);
  }
  if (variant.frame != frame) {
    variant.frame = frame;
    ApplyFrameUniforms(*current_, uniforms);
  }
  return *current_;
}

GlProgram& ScenePrograms::UseShadow(bool masked, const Eigen::Matrix4f& view_proj) {
  const int key = masked ? -3 : -2;
  GlProgram& program = shadow_[masked];
  if (key_ == key) return program;
  key_ = key;
  current_ = &program;
  program.Use();
  glUniformMatrix4fv(program.Uniform("view_proj"), 1, GL_FALSE, view_proj.data());
  return program;
}

}  // namespace sandbox::render
