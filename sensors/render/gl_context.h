#pragma once
// An offscreen OpenGL 4.5 core context (OSMesa), made current on the calling
// thread when asked: a renderer's, one each.

#include <cstdint>
#include <string>
#include <vector>

#include "sensors/render/gl.h"

struct osmesa_context;

namespace sandbox::render {

class GlContext {
 public:
  // Throws std::runtime_error when OSMesa cannot make a GL 4.5 core context
  // or lacks glClipControl.
  GlContext();
  ~GlContext();
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // This context, current on the calling thread (another context made
  // current on it since, or destroyed, leaves it not current).
  void MakeCurrent();
  // "OpenGL 4.5 (Core Profile) Mesa ..., llvmpipe ..."
  const std::string& description() const { return description_; }
  // glClipControl (GL 4.5; found through OSMesaGetProcAddress).
  void ClipControl(GLenum origin, GLenum depth) const { clip_control_(origin, depth); }

 private:
  osmesa_context* context_{nullptr};
  std::vector<std::uint8_t> backing_;  // a 1 x 1 default framebuffer: all drawing is into FBOs
  std::string description_;
  PFNGLCLIPCONTROLPROC clip_control_{nullptr};
};

}  // namespace sandbox::render
