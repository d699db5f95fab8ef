#include "sensors/render/mesh_drawer.h"

#include <algorithm>

#include "sensors/render/mesh_lods.h"

namespace sandbox::render {

// Back faces culled in a mesh's next draw where they cannot be seen from
// `eye` (in the mesh's frame; its axes keep their handedness). Not in
// shadow maps: the sun's view is not the eye's.
void MeshDrawer::CullHiddenBackFaces(const GpuMesh& mesh, const Eigen::Vector3f& eye) {
  CullBackFacesIf(mesh.hidden.HiddenFrom(eye, float(state_.near_reach_m)));
}
void MeshDrawer::CullBackFacesIf(bool hidden) {
  if (state_.cull_hidden_back_faces && state_.pass != Pass::kShadow && hidden) {
    glEnable(GL_CULL_FACE);
  } else {
    glDisable(GL_CULL_FACE);
  }
}

// A mesh with its material.
void MeshDrawer::Draw(const GpuMesh& mesh, const Eigen::Matrix4f& model) {
  const scene::Material* material =
      mesh.material >= 0 && mesh.material < int(level_->materials.size())
          ? &level_->materials[std::size_t(mesh.material)]
          : nullptr;
  static const scene::Material kDefault = [] {
    scene::Material m;
    m.base_color = {0.8f, 0.8f, 0.8f, 1.f};
    return m;
  }();
  const scene::Material& m = material != nullptr ? *material : kDefault;
  const MaterialTextures::Ids textures = textures_.Of(mesh.material);
  const int features = (textures.base != 0 && mesh.uvs != 0 ? kTexture : 0) |
                       (textures.lightmap != 0 && mesh.lightmap_uvs != 0 ? kLightmap : 0) |
                       (textures.normal != 0 && mesh.uvs != 0 ? kNormalMap : 0) |
                       (m.alpha_mode == scene::AlphaMode::kMask ? kAlphaMask : 0) |
                       (mesh.colors != 0 ? kVertexColors : 0) |
                       (mesh.triangle_segments != 0 ? kTriangleSegments : 0);
  if (state_.pass == Pass::kShadow) {
    const bool masked = (features & kAlphaMask) && (features & kTexture);
    GlProgram& program = programs_.UseShadow(masked, state_.view_proj);
    glUniform1f(program.Uniform("alpha_cutoff"), m.alpha_cutoff);
    glUniformMatrix4fv(program.Uniform("model"), 1, GL_FALSE, model.data());
    glBindTexture(GL_TEXTURE_2D, masked ? textures.base : 0);
    glBindVertexArray(mesh.vao);
    DrawTriangles(mesh);
    return;
  }
  if (state_.look & kTranslucent) state_.translucent_drawn = true;
  GlProgram& p = UseProgram(mesh.surface.value_or(m.surface), features);
  glUniformMatrix4fv(p.Uniform("model"), 1, GL_FALSE, model.data());
  const Eigen::Vector3f base = Shading(m.base_color.head<3>(), m.linear_color, state_.gamma);
  glUniform4f(p.Uniform("base_color"), base.x(), base.y(), base.z(), m.base_color.w());
  glUniform1i(p.Uniform("vertex_color_space"), state_.gamma == m.linear_color ? 0
                                               : state_.gamma                 ? 1
                                                                              : 2);
  glUniform1f(p.Uniform("alpha_cutoff"), m.alpha_cutoff);
  glUniform2f(p.Uniform("metal_rough"), m.metallic, m.roughness);
  textures_.Bind(GL_TEXTURE0, features & kTexture ? textures.base : 0, true, state_.gamma);
  textures_.Bind(GL_TEXTURE1, features & kLightmap ? textures.lightmap : 0, true, state_.gamma);
  textures_.Bind(GL_TEXTURE2, features & kNormalMap ? textures.normal : 0, false, state_.gamma);
  glUniform1ui(p.Uniform("segment_base"), mesh.segment_base);
  if (mesh.triangle_segments != 0) {
    glActiveTexture(GL_TEXTURE5);
    glBindTexture(GL_TEXTURE_BUFFER, mesh.triangle_segments);
    glActiveTexture(GL_TEXTURE0);
  }
  glBindVertexArray(mesh.vao);
  DrawTriangles(mesh);
}

// The scene program for a surface and a mesh's features in this pass's look.
GlProgram& MeshDrawer::UseProgram(scene::Surface surface, int features) {
  return programs_.Use(SceneProgramKey(state_.look, surface, features), state_.frame,
                       *state_.uniforms);
}

// The level of detail: what moves, this frame's (ChooseMovingLevels); what
// stays, the coarsest within this draw's allowance (in colour, NextLevel).
void MeshDrawer::DrawTriangles(const GpuMesh& mesh) {
  MeshLods::Level level{0, std::uint32_t(mesh.index_count), 0.f};
  if (!mesh.lods.empty()) {
    if (mesh.moving && !(state_.pass == Pass::kShadow && state_.cpu_shadows)) {
      level = mesh.lods[std::min(mesh.level, mesh.lods.size() - 1)];
    } else if (state_.pass == Pass::kColor) {
      level = mesh.lods[mesh.level = NextLevel(mesh.lods, mesh.level, state_.lod_error_m)];
    } else {
      level = LevelFor(mesh.lods, state_.lod_error_m);
    }
  }
  glDrawElements(GL_TRIANGLES, GLsizei(level.count), GL_UNSIGNED_INT,
                 reinterpret_cast<const void*>(std::uintptr_t(level.first) * 4));
}

// A mesh in one colour (and texture, 0: none), not a level material: the
// horizon and terrain tiles. Draws all of it unless `ranges` are given.
void MeshDrawer::DrawPlain(const GpuMesh& mesh, const Eigen::Matrix4f& model,
                           const Eigen::Vector4f& color, GLuint texture,
                           const std::vector<std::pair<std::uint32_t, std::uint32_t>>* ranges) {
  if (state_.pass == Pass::kShadow) {
    GlProgram& program = programs_.UseShadow(false, state_.view_proj);
    glUniformMatrix4fv(program.Uniform("model"), 1, GL_FALSE, model.data());
  } else {
    const bool textured = texture != 0 && mesh.uvs != 0;
    GlProgram& p =
        UseProgram(mesh.surface.value_or(scene::Surface::kPlain), textured ? kTexture : 0);
    glUniformMatrix4fv(p.Uniform("model"), 1, GL_FALSE, model.data());
    const Eigen::Vector3f base = Shading(color.head<3>(), false, state_.gamma);
    glUniform4f(p.Uniform("base_color"), base.x(), base.y(), base.z(), color.w());
    glUniform2f(p.Uniform("metal_rough"), 0.f, 1.f);
    textures_.Bind(GL_TEXTURE0, textured ? texture : 0, true, state_.gamma);
    glUniform1ui(p.Uniform("segment_base"), mesh.segment_base);
  }
  glBindVertexArray(mesh.vao);
  if (ranges == nullptr) {
    glDrawElements(GL_TRIANGLES, mesh.index_count, GL_UNSIGNED_INT, nullptr);
    return;
  }
  for (const auto& [a, b] : *ranges) {
    if (b <= a) continue;
    glDrawElements(GL_TRIANGLES, GLsizei(b - a), GL_UNSIGNED_INT,
                   reinterpret_cast<const void*>(std::uintptr_t(a) * 4));
  }
}

}  // namespace sandbox::render
