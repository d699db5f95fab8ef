#pragma once
// One mesh drawn in the pass being drawn: its scene program for the pass's
// look, its material's uniforms and textures, its segment ids, its level of
// detail, and whether its hidden back faces are culled.

#include <Eigen/Geometry>
#include <cstdint>
#include <utility>
#include <vector>

#include "scene/level.h"
#include "sensors/render/gpu_mesh.h"
#include "sensors/render/material_textures.h"
#include "sensors/render/scene_programs.h"

namespace sandbox::render {

// The passes a frame is drawn in.
enum class Pass {
  kColor,   // colour (and, without multisampling, segment and normal too)
  kData,    // segment and normal only, one sample at each pixel centre
  kShadow,  // depth from the sun
};

// What the pass being drawn is; the renderer sets it before each pass.
struct PassState {
  Pass pass{Pass::kColor};
  int look{0};                                             // scene_programs.h's Look bits
  Eigen::Matrix4f view_proj{Eigen::Matrix4f::Identity()};  // camera-centred world to clip
  bool gamma{true};                                        // shading in linear light
  long frame{0};  // the frame number, for the programs' frame uniforms
  const FrameUniforms* uniforms{nullptr};
  bool cull_hidden_back_faces{true};  // RenderSettings' switch
  double near_reach_m{0.0};           // from the eye to the near plane's corners
  bool cpu_shadows{false};            // the moving casters' map for deferred shading
  float lod_error_m{0.f};             // the error the next draw of what stays may have
  bool translucent_drawn{false};      // set when a draw in a kTranslucent look happened
};

class MeshDrawer {
 public:
  // `programs` and `textures` outlive this.
  MeshDrawer(ScenePrograms& programs, MaterialTextures& textures)
      : programs_(programs), textures_(textures) {}
  void SetLevel(const scene::Level& level) { level_ = &level; }
  PassState& state() { return state_; }
  const PassState& state() const { return state_; }

  // A mesh with its level material, `model` to the camera-centred world.
  void Draw(const GpuMesh& mesh, const Eigen::Matrix4f& model);
  // A mesh in one colour (and texture, 0: none), not a level material: the
  // horizon and terrain tiles. Draws all of it unless `ranges` [first, end) are given.
  void DrawPlain(const GpuMesh& mesh, const Eigen::Matrix4f& model, const Eigen::Vector4f& color,
                 GLuint texture,
                 const std::vector<std::pair<std::uint32_t, std::uint32_t>>* ranges = nullptr);

  // Back faces culled in the next draws where they cannot be seen from
  // `eye` (in the mesh's frame; its axes keep their handedness). Not in
  // shadow maps: the sun's view is not the eye's.
  void CullHiddenBackFaces(const GpuMesh& mesh, const Eigen::Vector3f& eye);
  void CullBackFacesIf(bool hidden);

 private:
  GlProgram& UseProgram(scene::Surface surface, int features);
  void DrawTriangles(const GpuMesh& mesh);

  ScenePrograms& programs_;
  MaterialTextures& textures_;
  const scene::Level* level_{nullptr};
  PassState state_;
};

}  // namespace sandbox::render
