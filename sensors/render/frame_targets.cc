#include "sensors/render/frame_targets.h"

#include <algorithm>
#include <iterator>
#include <stdexcept>
#include <string>

namespace sandbox::render {

void FrameTargets::Resize(int width, int height, int samples) {
  for (std::size_t i = 0; i < sizes_.size(); ++i) {
    const Targets& t = sizes_[i];
    if (t.width == width && t.height == height && t.samples == samples) {
      std::rotate(sizes_.begin() + std::ptrdiff_t(i), sizes_.begin() + std::ptrdiff_t(i) + 1,
                  sizes_.end());  // now the current, the last
      return;
    }
  }
  Targets targets;
  targets.width = width, targets.height = height, targets.samples = samples;
  try {
    Allocate(&targets);
  } catch (...) {
    Free(targets);
    throw;
  }
  if (sizes_.size() == kSizesKept) {
    Free(sizes_.front());
    sizes_.erase(sizes_.begin());
  }
  sizes_.push_back(targets);
}

void FrameTargets::Free(const Targets& t) {
  const GLuint fbos[] = {t.fbo,
                         t.msaa_fbo,
                         t.gbuffer_fbo,
                         t.translucent_fbo,
                         t.gbuffer_lean_fbo,
                         t.translucent_lean_fbo,
                         t.overlay_fbo};
  glDeleteFramebuffers(GLsizei(std::size(fbos)), fbos);
  glDeleteRenderbuffers(4, t.buffers);
  glDeleteRenderbuffers(2, t.msaa_buffers);
  glDeleteRenderbuffers(5, t.layer_buffers);
}

void FrameTargets::Allocate(Targets* t) {
  const int width = t->width, height = t->height, samples = t->samples;
  glGenFramebuffers(1, &t->fbo);
  glGenRenderbuffers(4, t->buffers);
  glGenFramebuffers(1, &t->msaa_fbo);
  glGenRenderbuffers(2, t->msaa_buffers);
  glGenFramebuffers(1, &t->gbuffer_fbo);
  glGenFramebuffers(1, &t->translucent_fbo);
  glGenFramebuffers(1, &t->gbuffer_lean_fbo);
  glGenFramebuffers(1, &t->translucent_lean_fbo);
  glGenFramebuffers(1, &t->overlay_fbo);
  glGenRenderbuffers(5, t->layer_buffers);
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
  attach(t->fbo, t->buffers[0], GL_RGBA8, GL_COLOR_ATTACHMENT0, 0);
  attach(t->fbo, t->buffers[1], GL_R32UI, GL_COLOR_ATTACHMENT1, 0);
  attach(t->fbo, t->buffers[2], GL_RGBA32F, GL_COLOR_ATTACHMENT2, 0);
  attach(t->fbo, t->buffers[3], GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT, 0);
  check("the");
  // Deferred shading's layers (SurfaceLayer): the opaque surfaces' and the
  // translucent ones', each in a framebuffer with the segment, normal and
  // depth buffers and in a lean one with the depth alone; the overlay's target.
  auto share = [&](GLenum attachment, GLuint buffer) {
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, attachment, GL_RENDERBUFFER, buffer);
  };
  for (int layer = 0; layer < 2; ++layer) {
    const GLuint albedo = t->layer_buffers[2 * layer], normal = t->layer_buffers[2 * layer + 1];
    attach(layer == 0 ? t->gbuffer_fbo : t->translucent_fbo, albedo, GL_RGBA8, GL_COLOR_ATTACHMENT0,
           0);
    attach(layer == 0 ? t->gbuffer_fbo : t->translucent_fbo, normal, GL_RGBA8, GL_COLOR_ATTACHMENT3,
           0);
    share(GL_COLOR_ATTACHMENT1, t->buffers[1]);
    share(GL_COLOR_ATTACHMENT2, t->buffers[2]);
    share(GL_DEPTH_ATTACHMENT, t->buffers[3]);
    check("a deferred shading layer's");
    glBindFramebuffer(GL_FRAMEBUFFER, layer == 0 ? t->gbuffer_lean_fbo : t->translucent_lean_fbo);
    share(GL_COLOR_ATTACHMENT0, albedo);
    share(GL_COLOR_ATTACHMENT3, normal);
    share(GL_DEPTH_ATTACHMENT, t->buffers[3]);
    check("a lean deferred shading layer's");
  }
  attach(t->overlay_fbo, t->layer_buffers[4], GL_RGBA8, GL_COLOR_ATTACHMENT0, 0);
  share(GL_DEPTH_ATTACHMENT, t->buffers[3]);
  check("the overlay's");
  if (samples > 0) {
    attach(t->msaa_fbo, t->msaa_buffers[0], GL_RGBA8, GL_COLOR_ATTACHMENT0, samples);
    attach(t->msaa_fbo, t->msaa_buffers[1], GL_DEPTH_COMPONENT32F, GL_DEPTH_ATTACHMENT, samples);
    check("the multisampled");
  }
}

void FrameTargets::ReadLayer(bool opaque, int width, int height, SurfaceLayer* layer) const {
  const std::size_t count = std::size_t(width) * std::size_t(height);
  layer->width = width;
  layer->height = height;
  layer->albedo.resize(count);
  layer->normal.resize(count);
  layer->depth.resize(count);
  const Targets& t = current();
  glBindFramebuffer(GL_READ_FRAMEBUFFER, opaque ? t.gbuffer_lean_fbo : t.translucent_lean_fbo);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, layer->albedo.data());
  glReadBuffer(GL_COLOR_ATTACHMENT3);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, layer->normal.data());
  glReadPixels(0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT, layer->depth.data());
}

}  // namespace sandbox::render
