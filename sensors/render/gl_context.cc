#include "sensors/render/gl_context.h"

#include <GL/osmesa.h>

#include <stdexcept>

namespace sandbox::render {

GlContext::GlContext() {
  const int attributes[] = {OSMESA_FORMAT,
                            OSMESA_RGBA,
                            OSMESA_DEPTH_BITS,
                            24,
                            OSMESA_PROFILE,
                            OSMESA_CORE_PROFILE,
                            OSMESA_CONTEXT_MAJOR_VERSION,
                            4,
                            OSMESA_CONTEXT_MINOR_VERSION,
                            5,
                            0};
  context_ = OSMesaCreateContextAttribs(attributes, nullptr);
  if (context_ == nullptr)
    throw std::runtime_error("GlContext::GlContext(): cannot create an OSMesa GL 4.5 context");
  backing_.resize(4);
  MakeCurrent();
  description_ = std::string("OpenGL ") + reinterpret_cast<const char*>(glGetString(GL_VERSION)) +
                 ", " + reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  // GL 4.5 calls libOSMesa does not export are found through it.
  clip_control_ = reinterpret_cast<PFNGLCLIPCONTROLPROC>(OSMesaGetProcAddress("glClipControl"));
  if (clip_control_ == nullptr) {
    OSMesaDestroyContext(context_);
    throw std::runtime_error("GlContext::GlContext(): no glClipControl");
  }
}

GlContext::~GlContext() { OSMesaDestroyContext(context_); }

void GlContext::MakeCurrent() {
  if (OSMesaGetCurrentContext() == context_) return;
  if (!OSMesaMakeCurrent(context_, backing_.data(), GL_UNSIGNED_BYTE, 1, 1)) {
    throw std::runtime_error("GlContext::MakeCurrent(): cannot make the OSMesa context current");
  }
}

}  // namespace sandbox::render
