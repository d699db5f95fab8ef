#pragma once
// The passes that are not the scene's meshes: the sky (a full-screen
// triangle where no surface was drawn), the edge filter (FXAA, from a copy of
// the colour buffer back into it) and the debug overlay's points and lines.
// Each leaves its own program in use.

#include <Eigen/Geometry>
#include <vector>

#include "sensors/render/gl.h"
#include "sensors/render/gl_program.h"
#include "sensors/render/view.h"

namespace sandbox::render {

class ScreenPasses {
 public:
  ScreenPasses();  // in the current context

  // Into the bound framebuffer's colour, at depth 0 (the far plane) only.
  void DrawSky(const Eigen::Matrix4f& clip_to_world, const Eigen::Vector3f& horizon,
               const Eigen::Vector3f& zenith, const Eigen::Vector3f& sun);
  // The bound framebuffer's colour 0, whose storage is `color_buffer`.
  void FilterEdges(GLuint color_buffer, int width, int height);
  // Relative to `camera_W`, depth-tested, into the bound framebuffer.
  void DrawOverlay(const Overlay& overlay, const Eigen::Vector3d& camera_W,
                   const Eigen::Matrix4f& view_proj);

 private:
  GlProgram sky_, edge_filter_, overlay_;
  GLuint vao_{0}, overlay_buffers_[2]{0, 0};
  GLuint edge_source_{0};  // the filter reads a copy of the colour
  Eigen::Vector2i edge_source_size_{0, 0};
  std::vector<Eigen::Vector3f> positions_, colors_;
};

}  // namespace sandbox::render
