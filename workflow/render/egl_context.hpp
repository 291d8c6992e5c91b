// Internal to ncfsim_render: a Mesa EGL surfaceless OpenGL context (desktop GL, core 3.2+) with a
// pbuffer surface, made current on the calling thread for the lifetime of the object.
#pragma once

#include "gl_context.hpp"

namespace ncfsim::render::detail {

class EglContext final : public GlContext {
public:
  // Creates the context and makes it current; throws std::runtime_error saying what failed.
  // The executable's GL entry points call the system libGL (gl_forward.hpp).
  EglContext(int width, int height);
  ~EglContext() override; // releases (not current any more), destroys surface and context

private:
  void* display_ = nullptr; // EGLDisplay (initialised once per process, never terminated)
  void* surface_ = nullptr; // EGLSurface
  void* context_ = nullptr; // EGLContext
};

} // namespace ncfsim::render::detail
