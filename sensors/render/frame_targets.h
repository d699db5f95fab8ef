#pragma once
// The framebuffers a frame is drawn into, sized to the view: the data buffer
// (colour, segment, normal and depth at pixel centres), the multisampled
// colour buffer, deferred shading's G-buffer layers (the nearest opaque and
// translucent surfaces' albedo and normal, each also in a lean framebuffer
// without segment and normal: llvmpipe pays for every target attached) and
// the overlay's target.

#include "sensors/render/deferred_shading.h"
#include "sensors/render/gl.h"

namespace sandbox::render {

class FrameTargets {
 public:
  // Throws std::runtime_error naming a framebuffer that is incomplete.
  void Resize(int width, int height, int samples);

  // Colour 0 RGBA8, 1 segment (R32UI), 2 normal (RGBA32F); depth.
  GLuint data() const { return fbo_; }
  GLuint color_buffer() const { return buffers_[0]; }  // a renderbuffer
  GLuint multisampled() const { return msaa_fbo_; }
  // Deferred shading's layers: colour 0 albedo, 3 normal and material, with
  // (full) or without (lean) the data buffer's segment and normal.
  GLuint opaque(bool full) const { return full ? gbuffer_fbo_ : gbuffer_lean_fbo_; }
  GLuint translucent(bool full) const { return full ? translucent_fbo_ : translucent_lean_fbo_; }
  GLuint overlay() const { return overlay_fbo_; }

  // A G-buffer layer read back (rows bottom first).
  void ReadLayer(bool opaque, int width, int height, SurfaceLayer* layer) const;

 private:
  int width_{0}, height_{0}, samples_{-1};
  GLuint fbo_{0}, buffers_[4]{0, 0, 0, 0}, msaa_fbo_{0}, msaa_buffers_[2]{0, 0};
  GLuint gbuffer_fbo_{0}, translucent_fbo_{0}, overlay_fbo_{0}, layer_buffers_[5]{0, 0, 0, 0, 0};
  GLuint gbuffer_lean_fbo_{0}, translucent_lean_fbo_{0};
};

}  // namespace sandbox::render
