// Internal to ncfsim_render: an off-screen OpenGL context made current on the calling thread, from
// one of two back ends (render.hpp, RenderBackend): OSMesa (osmesa_context.hpp) or Mesa EGL
// surfaceless (egl_context.hpp). Both are Mesa's llvmpipe software renderer; VTK draws into either
// through vtkGenericOpenGLRenderWindow.
#pragma once

#include <memory>
#include <string>

#include "render.hpp"

namespace ncfsim::render::detail {

class GlContext;
std::unique_ptr<GlContext> make_gl_context(int width, int height);

class GlContext {
 public:
  virtual ~GlContext() = default;
  GlContext(const GlContext&) = delete;
  GlContext& operator=(const GlContext&) = delete;

  // The back end and the driver: "OSMesa: OpenGL 4.5 (Core Profile) Mesa 22.3.6, renderer
  // llvmpipe (...)", "EGL: ...", or "EGL (fallback; <why OSMesa failed>): ..." when auto fell
  // back.
  const std::string& description() const { return description_; }

 protected:
  GlContext() = default;
  std::string description_;

 private:
  friend std::unique_ptr<GlContext> make_gl_context(int width, int height);
};

// Creates a width x height context of the requested back end (requested_render_backend) and makes
// it current. Auto: OSMesa; if that fails, EGL (the OSMesa failure is remembered for the process
// and named in the description). Throws std::runtime_error saying what failed. Call with the render
// lock held.
std::unique_ptr<GlContext> make_gl_context(int width, int height);

}  // namespace ncfsim::render::detail
