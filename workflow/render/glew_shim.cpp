// glewInit shim for off-screen rendering with Debian's GLX-only GLEW (see /work/shared/rendering.md).
//
// Debian's libGLEW is a GLX build: on a Mesa EGL context its glewInit() loads every OpenGL entry
// point and then returns GLEW_ERROR_NO_GLX_DISPLAY (4) because there is no X display, which VTK's
// vtkOpenGLRenderWindow treats as fatal. This file defines glewInit in the *executable*: when the
// executable exports it (ENABLE_EXPORTS / --export-dynamic-symbol, see CMakeLists.txt), the dynamic
// linker binds libvtkRenderingOpenGL2's call to this definition, which calls the real glewInit
// (the next definition in lookup order, found with dlsym(RTLD_NEXT)) and maps that one error code
// to GLEW_OK. Every other result passes through unchanged.
//
// The object file is pulled out of the static library ncfsim_render by the reference render.cpp
// makes to ncfsim_render_glew_shim_marker, so it is in every executable that uses the renderer.

#include <GL/glew.h>
#include <dlfcn.h>

namespace {
using GlewInitFn = GLenum (*)();

GlewInitFn real_glew_init()
{
  // Resolved on every call (cheap, called once per render window): no static state to race on.
  return reinterpret_cast<GlewInitFn>(dlsym(RTLD_NEXT, "glewInit"));
}
} // namespace

extern "C" {

// Referenced from render.cpp so that the linker extracts this object from the static library.
__attribute__((visibility("default"))) extern const int ncfsim_render_glew_shim_marker = 1;

__attribute__((visibility("default"))) GLenum glewInit(void)
{
  const GlewInitFn real = real_glew_init();
  if (real == nullptr) {
    return GLEW_ERROR_NO_GL_VERSION; // libGLEW not loaded: report a GLEW failure to VTK
  }
  const GLenum result = real();
  return result == GLEW_ERROR_NO_GLX_DISPLAY ? static_cast<GLenum>(GLEW_OK) : result;
}

// True when the process-wide (global scope) glewInit is this shim, i.e. the executable exports it
// and VTK's call will land here.
__attribute__((visibility("default"))) int ncfsim_render_glew_shim_active(void)
{
  void* global = dlsym(RTLD_DEFAULT, "glewInit");
  return global == reinterpret_cast<void*>(&glewInit) ? 1 : 0;
}

} // extern "C"
