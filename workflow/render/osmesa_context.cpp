#include "osmesa_context.hpp"

#include <GL/osmesa.h>
#include <dlfcn.h>

#include <cstdlib>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "gl_forward.hpp"

namespace ncfsim::render::detail {
namespace {

// libOSMesa's entry points, resolved once per process from a handle that is never closed.
struct OsMesaLibrary {
  decltype(&::OSMesaCreateContextAttribs) create = nullptr;
  decltype(&::OSMesaMakeCurrent) make_current = nullptr;
  decltype(&::OSMesaDestroyContext) destroy = nullptr;
  decltype(&::OSMesaGetProcAddress) get_proc = nullptr;
};

[[noreturn]] void fail(const std::string& what) {
  throw std::runtime_error("off-screen rendering (OSMesa): " + what);
}

const OsMesaLibrary& osmesa_library() {
  static std::once_flag once;
  static OsMesaLibrary lib;
  static std::string error;
  std::call_once(once, [] {
    // RTLD_LOCAL: OSMesa's own gl* symbols stay out of the global scope (the EGL back end keeps
    // the system libGL's); the executable reaches them through OSMesaGetProcAddress.
    // NCFSIM_OSMESA_LIBRARY: another libOSMesa (a newer Mesa), or a missing one to test the
    // fallback to EGL.
    const char* env = std::getenv("NCFSIM_OSMESA_LIBRARY");
    const std::string chosen = env != nullptr ? env : "";
    std::vector<std::string> names = {"libOSMesa.so.8", "libOSMesa.so"};
    if (!chosen.empty()) {
      names = {chosen};
    }
    void* handle = nullptr;
    for (const std::string& name : names) {
      if ((handle = dlopen(name.c_str(), RTLD_NOW | RTLD_LOCAL)) != nullptr) {
        break;
      }
    }
    if (handle == nullptr) {
      const char* why = dlerror();
      error = "cannot load " + names.front() +
              (chosen.empty() ? " (package libosmesa6)" : " (NCFSIM_OSMESA_LIBRARY)") + ": " +
              (why != nullptr ? why : "unknown dlopen error");
      return;
    }
    OsMesaLibrary l;
    l.create = reinterpret_cast<decltype(l.create)>(dlsym(handle, "OSMesaCreateContextAttribs"));
    l.make_current = reinterpret_cast<decltype(l.make_current)>(dlsym(handle, "OSMesaMakeCurrent"));
    l.destroy = reinterpret_cast<decltype(l.destroy)>(dlsym(handle, "OSMesaDestroyContext"));
    l.get_proc = reinterpret_cast<decltype(l.get_proc)>(dlsym(handle, "OSMesaGetProcAddress"));
    if (l.create == nullptr || l.make_current == nullptr || l.destroy == nullptr ||
        l.get_proc == nullptr) {
      error =
          "libOSMesa lacks OSMesaCreateContextAttribs, OSMesaMakeCurrent, "
          "OSMesaDestroyContext or OSMesaGetProcAddress (needs Mesa >= 12)";
      return;
    }
    lib = l;
  });
  if (lib.create == nullptr) {
    fail(error);
  }
  return lib;
}

}  // namespace

OsMesaContext::OsMesaContext(int width, int height) {
  if (width <= 0 || height <= 0) {
    fail("image size must be positive, got " + std::to_string(width) + "x" +
         std::to_string(height));
  }
  if (const std::string problem = gl_forwarding_problem(); !problem.empty()) {
    fail(problem);
  }
  const OsMesaLibrary& lib = osmesa_library();

  const int attribs[] = {OSMESA_FORMAT,
                         OSMESA_RGBA,
                         OSMESA_DEPTH_BITS,
                         24,
                         OSMESA_STENCIL_BITS,
                         8,
                         OSMESA_ACCUM_BITS,
                         0,
                         OSMESA_PROFILE,
                         OSMESA_CORE_PROFILE,
                         OSMESA_CONTEXT_MAJOR_VERSION,
                         3,
                         OSMESA_CONTEXT_MINOR_VERSION,
                         2,
                         0};
  OSMesaContext context = lib.create(attribs, nullptr);
  if (context == nullptr) {
    fail("OSMesaCreateContextAttribs (RGBA8, depth 24, OpenGL 3.2 core profile) failed");
  }
  context_ = context;
  buffer_.assign(4 * static_cast<std::size_t>(width) * static_cast<std::size_t>(height), 0);
  if (lib.make_current(context, buffer_.data(), GL_UNSIGNED_BYTE, width, height) != GL_TRUE) {
    lib.destroy(context);
    fail("OSMesaMakeCurrent " + std::to_string(width) + "x" + std::to_string(height) + " failed");
  }
  try {
    route_gl_calls(lib.get_proc);
  } catch (const std::exception& e) {
    lib.make_current(nullptr, nullptr, 0, 0, 0);
    lib.destroy(context);
    fail(e.what());
  }

  using GetStringFn = const GLubyte* (*)(GLenum);
  auto get_string = reinterpret_cast<GetStringFn>(lib.get_proc("glGetString"));
  auto str = [&](GLenum name) -> std::string {
    const GLubyte* s = get_string != nullptr ? get_string(name) : nullptr;
    return s != nullptr ? reinterpret_cast<const char*>(s) : "?";
  };
  description_ = "OSMesa: OpenGL " + str(GL_VERSION) + ", renderer " + str(GL_RENDERER);
}

OsMesaContext::~OsMesaContext() {
  const OsMesaLibrary& lib = osmesa_library();  // loaded: the constructor succeeded
  lib.make_current(nullptr, nullptr, 0, 0, 0);
  lib.destroy(static_cast<OSMesaContext>(context_));
}

}  // namespace ncfsim::render::detail
