#pragma once
// The framebuffers a frame is drawn into, sized to the view: the data buffer
// (colour, segment, normal and depth at pixel centres), the multisampled
// colour buffer, deferred shading's G-buffer layers (the nearest opaque and
// translucent surfaces' albedo and normal, each also in a lean framebuffer
// without segment and normal: llvmpipe pays for every target attached) and
// the overlay's target.

#include <cstddef>
#include <vector>

#include "sensors/render/deferred_shading.h"
#include "sensors/render/gl.h"

namespace sandbox::render {

class FrameTargets {
 public:
  // Makes the framebuffers of this size current: those of a size drawn
  // before are kept (up to kSizesKept, the least recently drawn dropped
  // first), so views of different sizes in turn (a renderer's cameras, a
  // lens's source) do not reallocate every frame (GL's names go with the
  // context). Throws std::runtime_error naming a framebuffer that is incomplete.
  void Resize(int width, int height, int samples);
  static constexpr std::size_t kSizesKept = 4;

  // Colour 0 RGBA8, 1 segment (R32UI), 2 normal (RGBA32F); depth.
  GLuint data() const { return current().fbo; }
  GLuint color_buffer() const { return current().buffers[0]; }  // a renderbuffer
  GLuint multisampled() const { return current().msaa_fbo; }
  // Deferred shading's layers: colour 0 albedo, 3 normal and material, with
  // (full) or without (lean) the data buffer's segment and normal.
  GLuint opaque(bool full) const {
    return full ? current().gbuffer_fbo : current().gbuffer_lean_fbo;
  }
  GLuint translucent(bool full) const {
    return full ? current().translucent_fbo : current().translucent_lean_fbo;
  }
  GLuint overlay() const { return current().overlay_fbo; }

  // A G-buffer layer read back (rows bottom first).
  void ReadLayer(bool opaque, int width, int height, SurfaceLayer* layer) const;

 private:
  struct Targets {
    int width{0}, height{0}, samples{-1};
    GLuint fbo{0}, buffers[4]{0, 0, 0, 0}, msaa_fbo{0}, msaa_buffers[2]{0, 0};
    GLuint gbuffer_fbo{0}, translucent_fbo{0}, overlay_fbo{0}, layer_buffers[5]{0, 0, 0, 0, 0};
    GLuint gbuffer_lean_fbo{0}, translucent_lean_fbo{0};
  };
  static void Allocate(Targets* targets);
  static void Free(const Targets& targets);
  const Targets& current() const { return sizes_.back(); }  // after the first Resize

  std::vector<Targets> sizes_;  // the current last
};

}  // namespace sandbox::render
