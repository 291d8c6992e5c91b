#include "egl_context.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <mutex>
#include <stdexcept>
#include <string>

#include "gl_forward.hpp"

// Not in <GL/gl.h> on every system; the values are fixed by the OpenGL specification.
#ifndef GL_VENDOR
#define GL_VENDOR 0x1F00
#define GL_RENDERER 0x1F01
#define GL_VERSION 0x1F02
#endif

namespace ncfsim::render::detail {
namespace {

std::string egl_error_name(EGLint code)
{
  switch (code) {
  case EGL_SUCCESS: return "EGL_SUCCESS";
  case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
  case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
  case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
  case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
  case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
  case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
  case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
  case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
  case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
  case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
  case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
  case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
  case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
  case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
  default: return "EGL error " + std::to_string(code);
  }
}

[[noreturn]] void fail(const std::string& what)
{
  throw std::runtime_error("off-screen rendering (EGL): " + what + " (" +
                           egl_error_name(eglGetError()) +
                           "); needs Mesa EGL with the surfaceless platform (libegl-mesa0)");
}

// The surfaceless display is shared by every context of the process; it is initialised once and
// left initialised (terminating it while another thread renders would pull it from under it).
EGLDisplay surfaceless_display()
{
  static std::once_flag once;
  static EGLDisplay display = EGL_NO_DISPLAY;
  static std::string error;
  std::call_once(once, [] {
    const char* client_ext = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (client_ext == nullptr || std::strstr(client_ext, "EGL_MESA_platform_surfaceless") == nullptr) {
      error = "EGL client extension EGL_MESA_platform_surfaceless not available";
      return;
    }
    auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
        eglGetProcAddress("eglGetPlatformDisplayEXT"));
    if (get_platform_display == nullptr) {
      error = "eglGetPlatformDisplayEXT not available";
      return;
    }
    EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d == EGL_NO_DISPLAY) {
      error = "eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA) returned no display";
      return;
    }
    EGLint major = 0, minor = 0;
    if (eglInitialize(d, &major, &minor) != EGL_TRUE) {
      error = "eglInitialize on the surfaceless display failed";
      return;
    }
    display = d;
  });
  if (display == EGL_NO_DISPLAY) {
    fail(error);
  }
  return display;
}

} // namespace

EglContext::EglContext(int width, int height)
{
  if (width <= 0 || height <= 0) {
    throw std::runtime_error("off-screen rendering: image size must be positive, got " +
                             std::to_string(width) + "x" + std::to_string(height));
  }
  EGLDisplay display = surfaceless_display();
  display_ = display;

  const EGLint config_attribs[] = {EGL_SURFACE_TYPE, EGL_PBUFFER_BIT, EGL_RENDERABLE_TYPE,
                                   EGL_OPENGL_BIT,   EGL_RED_SIZE,    8,
                                   EGL_GREEN_SIZE,   8,               EGL_BLUE_SIZE,
                                   8,                EGL_ALPHA_SIZE,  8,
                                   EGL_DEPTH_SIZE,   24,              EGL_NONE};
  EGLConfig config = nullptr;
  EGLint n_configs = 0;
  if (eglChooseConfig(display, config_attribs, &config, 1, &n_configs) != EGL_TRUE || n_configs < 1) {
    fail("no EGL config with a pbuffer surface, desktop OpenGL and RGBA8 + depth 24");
  }
  if (eglBindAPI(EGL_OPENGL_API) != EGL_TRUE) {
    fail("eglBindAPI(EGL_OPENGL_API) failed");
  }
  const EGLint surface_attribs[] = {EGL_WIDTH, width, EGL_HEIGHT, height, EGL_NONE};
  EGLSurface surface = eglCreatePbufferSurface(display, config, surface_attribs);
  if (surface == EGL_NO_SURFACE) {
    fail("eglCreatePbufferSurface " + std::to_string(width) + "x" + std::to_string(height) +
         " failed");
  }
  surface_ = surface;
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,
                                    3,
                                    EGL_CONTEXT_MINOR_VERSION,
                                    2,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT) {
    eglDestroySurface(display, surface);
    fail("eglCreateContext (desktop OpenGL 3.2 core profile) failed");
  }
  context_ = context;
  if (eglMakeCurrent(display, surface, surface, context) != EGL_TRUE) {
    eglDestroyContext(display, context);
    eglDestroySurface(display, surface);
    fail("eglMakeCurrent failed");
  }

  try {
    route_gl_calls(nullptr);
  } catch (const std::exception& e) {
    eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display, context);
    eglDestroySurface(display, surface);
    throw std::runtime_error(std::string("off-screen rendering (EGL): ") + e.what());
  }

  // glGetString through EGL's loader, so this file needs no OpenGL link of its own.
  using GetStringFn = const unsigned char* (*)(unsigned int);
  auto get_string = reinterpret_cast<GetStringFn>(eglGetProcAddress("glGetString"));
  auto str = [&](unsigned int name) -> std::string {
    const unsigned char* s = get_string != nullptr ? get_string(name) : nullptr;
    return s != nullptr ? reinterpret_cast<const char*>(s) : "?";
  };
  description_ = "EGL: OpenGL " + str(GL_VERSION) + ", renderer " + str(GL_RENDERER);
}

EglContext::~EglContext()
{
  auto display = static_cast<EGLDisplay>(display_);
  eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
  eglDestroyContext(display, static_cast<EGLContext>(context_));
  eglDestroySurface(display, static_cast<EGLSurface>(surface_));
  eglReleaseThread();
}

} // namespace ncfsim::render::detail
