#include "sensors/render/screen_passes.h"

#include "sensors/render/shaders.h"

namespace sandbox::render {

ScreenPasses::ScreenPasses()
    : sky_("sky", shaders::kFullScreenVertex, shaders::kSkyFragment),
      edge_filter_("edge filter", shaders::kFullScreenVertex, shaders::kEdgeFilterFragment),
      overlay_("overlay", shaders::kOverlayVertex, shaders::kOverlayFragment) {
  glGenVertexArrays(1, &vao_);
  glGenBuffers(2, overlay_buffers_);
}

void ScreenPasses::DrawSky(const Eigen::Matrix4f& clip_to_world, const Eigen::Vector3f& horizon,
                           const Eigen::Vector3f& zenith, const Eigen::Vector3f& sun) {
  sky_.Use();
  glUniformMatrix4fv(sky_.Uniform("clip_to_world"), 1, GL_FALSE, clip_to_world.data());
  glUniform3f(sky_.Uniform("horizon"), horizon.x(), horizon.y(), horizon.z());
  glUniform3f(sky_.Uniform("zenith"), zenith.x(), zenith.y(), zenith.z());
  glUniform3f(sky_.Uniform("sun"), sun.x(), sun.y(), sun.z());
  // At the far plane (depth 0): only where no surface was drawn.
  glDepthMask(GL_FALSE);
  glDepthFunc(GL_GEQUAL);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_TRUE);
}

void ScreenPasses::FilterEdges(GLuint color_buffer, int width, int height) {
  if (edge_source_ == 0) glGenTextures(1, &edge_source_);
  glBindTexture(GL_TEXTURE_2D, edge_source_);
  if (edge_source_size_ != Eigen::Vector2i(width, height)) {
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    edge_source_size_ = {width, height};
  }
  glCopyImageSubData(color_buffer, GL_RENDERBUFFER, 0, 0, 0, 0, edge_source_, GL_TEXTURE_2D, 0, 0,
                     0, 0, width, height, 1);
  const GLenum color_only[] = {GL_COLOR_ATTACHMENT0};
  glDrawBuffers(1, color_only);
  edge_filter_.Use();
  glUniform1i(edge_filter_.Uniform("image"), 0);
  glActiveTexture(GL_TEXTURE0);
  glBindSampler(0, 0);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_BLEND);
  glBindVertexArray(vao_);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEnable(GL_DEPTH_TEST);
}

void ScreenPasses::DrawOverlay(const Overlay& overlay, const Eigen::Vector3d& camera_W,
                               const Eigen::Matrix4f& view_proj) {
  positions_.clear();
  colors_.clear();
  for (std::size_t i = 0; i < overlay.points_W.size(); ++i) {
    positions_.push_back((overlay.points_W[i] - camera_W).cast<float>());
    colors_.push_back(overlay.point_rgb[i]);
  }
  for (std::size_t i = 0; i < overlay.lines_W.size(); ++i) {
    positions_.push_back((overlay.lines_W[i] - camera_W).cast<float>());
    colors_.push_back(overlay.line_rgb[i / 2]);
  }
  overlay_.Use();
  glUniformMatrix4fv(overlay_.Uniform("view_proj"), 1, GL_FALSE, view_proj.data());
  glBindVertexArray(vao_);
  const std::pair<GLuint, const std::vector<Eigen::Vector3f>*> attributes[] = {
      {overlay_buffers_[0], &positions_}, {overlay_buffers_[1], &colors_}};
  for (GLuint location = 0; location < 2; ++location) {
    glBindBuffer(GL_ARRAY_BUFFER, attributes[location].first);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(attributes[location].second->size() * 12),
                 attributes[location].second->data(), GL_STREAM_DRAW);
    glEnableVertexAttribArray(location);
    glVertexAttribPointer(location, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  }
  glDisable(GL_BLEND);
  glPointSize(overlay.point_size_px);
  glDrawArrays(GL_POINTS, 0, GLsizei(overlay.points_W.size()));
  glDrawArrays(GL_LINES, GLsizei(overlay.points_W.size()), GLsizei(overlay.lines_W.size()));
  glBindVertexArray(0);
}

}  // namespace sandbox::render
