#pragma once
// OpenGL 4.5 core as the renderer's parts see it (OSMesa's llvmpipe). Only
// the renderer's own files include this; the rest of the program sees view.h.
// Calls libOSMesa does not export (glClipControl) go through GlContext.

#define GL_GLEXT_PROTOTYPES
#include <GL/gl.h>
#include <GL/glext.h>
