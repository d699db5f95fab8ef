#pragma once
// The programs that draw the scene's meshes: one GLSL source compiled into a
// variant per surface, look and mesh features (each made at its first use),
// the depth-only programs for the sun's view, and the uniforms every scene
// program takes once a frame.

#include <Eigen/Geometry>
#include <map>
#include <vector>

#include "scene/level.h"
#include "sensors/render/deferred_shading.h"
#include "sensors/render/gl_program.h"
#include "sensors/render/renderer.h"
#include "sensors/render/shadow_cascades.h"

namespace sandbox::render {

// A pass's look (bits of a program key): gamma-correct shading, materials,
// shadows, segment and normal targets too (kData) or alone (kDataOnly), the
// G-buffer of deferred shading, for opaque or translucent surfaces.
enum Look : int {
  kGamma = 4,
  kMaterials = 8,
  kShadows = 16,
  kData = 32,
  kDataOnly = 64,
  kGBuffer = 8192,
  kTranslucent = 16384,
};
// What a mesh brings (bits of a program key).
enum MeshFeature : int {
  kTexture = 128,
  kLightmap = 256,
  kNormalMap = 512,
  kAlphaMask = 1024,
  kVertexColors = 2048,
  kTriangleSegments = 4096,
};

// The program variant for a surface, a pass's look and a mesh's features:
// the surface in bits 0-1, then the look's and the features' bits that the
// look uses (data-only passes: what decides which fragments exist, and the ids).
int SceneProgramKey(int look, scene::Surface surface, int features);

// This frame's uniforms for the scene programs; colours in the shading space.
struct FrameUniforms {
  Eigen::Matrix4f view_proj;
  Eigen::Vector3f sun, horizon, zenith, ground[4], view_axis;
  Eigen::Vector2f fog, camera_xy;
  float camera_z{0.f};
  float water_level{-1e9f};
  Eigen::Matrix3f R_CW;
  std::vector<ShadowCascade> cascades;
};

// The sky's colour overhead for a horizon colour (display values).
Eigen::Vector3f Zenith(const Eigen::Vector3f& horizon);
// A colour to the shading space: linear light with `gamma` (gamma-correct
// shading), else display (sRGB) values. `linear`: the colour is given linear (glTF).
Eigen::Vector3f Shading(const Eigen::Vector3f& rgb, bool linear, bool gamma);

// This frame's uniforms, without GL. `camera_W`: the camera's position.
FrameUniforms MakeFrameUniforms(const CameraView& view, const Eigen::Matrix4f& view_proj,
                                const RenderSettings& settings, const scene::Level& level,
                                const Eigen::Vector3d& camera_W, float water_level,
                                const std::vector<ShadowCascade>& cascades);
// The same lighting for deferred shading on the CPU (without its shadow maps).
LightingFrame LightingOf(const FrameUniforms& u, const RenderSettings& settings,
                         const Eigen::Matrix4f& clip_to_world, float lod_offset_per_m);

class ScenePrograms {
 public:
  ScenePrograms();  // the depth-only programs, in the current context

  // The variant `key` in use, made at its first use, with `frame`'s uniforms
  // set at its first use in that frame.
  GlProgram& Use(int key, long frame, const FrameUniforms& uniforms);
  // The depth-only program (`masked`: cut-outs cut) in use, with `view_proj`
  // set when it comes into use.
  GlProgram& UseShadow(bool masked, const Eigen::Matrix4f& view_proj);
  // Another program was put in use: the next Use or UseShadow sets its own.
  void Forget() { key_ = kNone; }

 private:
  static constexpr int kNone = -1;
  struct Variant {
    GlProgram program;
    long frame{-1};  // the frame its frame uniforms are from
  };
  std::map<int, Variant> variants_;
  GlProgram shadow_[2];  // [masked]
  int key_{kNone};       // in use: a variant's key, or -2 - masked for a shadow program
  GlProgram* current_{nullptr};
};

}  // namespace sandbox::render
