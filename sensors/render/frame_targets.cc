#include "sensors/render/frame_targets.h"

#include <stdexcept>
#include <string>

namespace sandbox::render {

void FrameTargets::Resize(int width, int height, int samples) {
  if (width == width_ && height == height_ && samples == samples_) return;
  if (fbo_ == 0) {
    glGenFramebuffers(1, &fbo_);
    glGenRenderbuffers(4, buffers_);
    glGenFramebuffers(1, &msaa_fbo_);
    glGenRenderbuffers(2, msaa_buffers_);
    glGenFramebuffers(1, &gbuffer_fbo_);
    glGenFramebuffers(1, &translucent_fbo_);
    glGenFramebuffers(1, &gbuffer_lean_fbo_);
    glGenFramebuffers(1, &translucent_lean_fbo_);
    glGenFramebuffers(1, &overlay_fbo_);
    glGenRenderbuffers(5, layer_buffers_);
  }
  auto attach = [&](GLuint fbo, GLuint buffer, GLenum format, GLenum attachment, int n) {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glBindRenderbuffer(GL_RENDERBUFFER, buffer);
    glRenderbufferStorageMultisample(GL_RENDERBUFFER, n, format, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, buffer);
  };
  auto check = [&](const char* what) {
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error(std::string("FrameTargets::Resize(): ") + what + " framebuffer of " +
                               std::to_string(width) + " x " + std::to_string(height) +
                               " is incomplete");
    }
  };
  attach(fbo_, buffers_[0], GL_RGBA8, GL_COLOR_ATTACHMENT0, 0);
  attach(fbo_, buffers_[1], GL_R32UI, GL_COLOR_ATTACHMENT1, 0);
  attach(fbo_, buffers_[2], GL_RGBA32F, GL_COLOR_ATTACHMENT2, 0);
  attach(fbo_, buffers_[3], GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT, 0);
  check("the");
  // Deferred shading's layers (SurfaceLayer): the opaque surfaces' and the
  // translucent ones', each in a framebuffer with the segment, normal and
  // depth buffers and in a lean one with the depth alone; the overlay's target.
  auto share = [&](GLenum attachment, GLuint buffer) {
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, buffer);
  };
  for (int layer = 0; layer < 2; ++layer) {
    const GLuint albedo = layer_buffers_[2 * layer], normal = layer_buffers_[2 * layer + 1];
    attach(layer == 0 ? gbuffer_fbo_ : translucent_fbo_, albedo, GL_RGBA8, GL_COLOR_ATTACHMENT0, 0);
    attach(layer == 0 ? gbuffer_fbo_ : translucent_fbo_, normal, GL_RGBA8, GL_COLOR_ATTACHMENT3, 0);
    share(GL_COLOR_ATTACHMENT1, buffers_[1]);
    share(GL_COLOR_ATTACHMENT2, buffers_[2]);
    share(GL_DEPTH_ATTACHMENT, buffers_[3]);
    check("a deferred shading layer's");
    glBindFramebuffer(GL_FRAMEBUFFER, layer == 0 ? gbuffer_lean_fbo_ : translucent_lean_fbo_);
    share(GL_COLOR_ATTACHMENT0, albedo);
    share(GL_COLOR_ATTACHMENT3, normal);
    share(GL_DEPTH_ATTACHMENT, buffers_[3]);
    check("a lean deferred shading layer's");
  }
  attach(overlay_fbo_, layer_buffers_[4], GL_RGBA8, GL_COLOR_ATTACHMENT0, 0);
  share(GL_DEPTH_ATTACHMENT, buffers_[3]);
  check("the overlay's");
  if (samples > 0) {
    attach(msaa_fbo_, msaa_buffers_[0], GL_RGBA8, GL_COLOR_ATTACHMENT0, samples);
    attach(msaa_fbo_, msaa_buffers_[1], GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT, samples);
    check("the multisampled");
  }
  width_ = width, height_ = height, samples_ = samples;
}

void FrameTargets::ReadLayer(bool opaque, int width, int height, SurfaceLayer* layer) const {
  const std::size_t count = std::size_t(width) * std::size_t(height);
  layer->width = width;
  layer->height = height;
  layer->albedo.resize(count);
  layer->normal.resize(count);
  layer->depth.resize(count);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, opaque ? gbuffer_lean_fbo_ : translucent_lean_fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, layer->albedo.data());
  glReadBuffer(GL_COLOR_ATTACHMENT3);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, layer->normal.data());
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, layer->depth.data());
}

}  // namespace sandbox::render
