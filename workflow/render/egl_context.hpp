// Internal to ncfsim_render: a Mesa EGL surfaceless OpenGL context (desktop GL, core 3.2+) with a
// pbuffer surface, made current on the calling thread for the lifetime of the object.
#pragma once

#include <string>

namespace ncfsim::render::detail {

class EglContext {
public:
  // Creates the context and makes it current; throws std::runtime_error saying what failed.
  EglContext(int width, int height);
  ~EglContext(); // releases (not current any more), destroys surface and context
  EglContext(const EglContext&) = delete;
  EglContext& operator=(const EglContext&) = delete;

  // "OpenGL 4.5 (Core Profile) Mesa 22.3.6, renderer llvmpipe (...)"
  const std::string& description() const { return description_; }

private:
  void* display_ = nullptr; // EGLDisplay (initialised once per process, never terminated)
  void* surface_ = nullptr; // EGLSurface
  void* context_ = nullptr; // EGLContext
  std::string description_;
};

} // namespace ncfsim::render::detail
