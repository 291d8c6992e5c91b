// OpenGL entry points defined in the executable, forwarded to the system libGL or to OSMesa.
//
// Why (see gl_forward.hpp and /work/shared/rendering.md): with stock Debian VTK 9.1 the GL calls
// go through GLVND, which dispatches to EGL and GLX contexts but not to an OSMesa context. When
// the executable exports the functions below (ENABLE_EXPORTS, as for the glewInit shim), the
// dynamic linker binds every call that libvtkRendering*OpenGL2 makes to one of them:
//   - the OpenGL 1.x functions VTK links directly (the list below) call the system libGL's
//     function (the next definition in lookup order, dlsym(RTLD_NEXT)) or OSMesa's;
//   - glXGetProcAddressARB / glXGetProcAddress, through which GLEW's glewInit fetches every later
//     function (glGenFramebuffers, glDrawArraysInstanced, ...), answer with OSMesa's function when
//     OSMesa is routed; names starting with "glX" always go to the real GLX, so that GLEW finds
//     no GLX display and the glewInit shim maps that one error to GLEW_OK, as on EGL.
// The list: every gl* symbol that the libraries of the ncfsim executable import, today those of
// libvtkRenderingOpenGL2 and libvtkRenderingContextOpenGL2. After a VTK upgrade, regenerate with
//   for f in $(ldd build/release/workflow/ncfsim | awk '/=>/{print $3}'); do
//     nm -D --undefined-only $f | awk '{print $2}' | grep -E '^gl[A-Z]' | grep -v -E '^gl(X|ew)';
//   done | sort -u
// A function missing here would reach GLVND with no context: OSMesa renders would come out wrong,
// which the pixel test on the OSMesa back end catches.
#include "gl_forward.hpp"

#include <GL/gl.h>
#include <dlfcn.h>

#include <array>
#include <atomic>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>

// X(return type, name, parameters, arguments): the signatures as <GL/gl.h> declares them, so a
// mismatch is a compile error.
#define NCFSIM_GL_FORWARDED(X)                                                                   \
  X(void, glBindTexture, (GLenum target, GLuint texture), (target, texture))                     \
  X(void, glClear, (GLbitfield mask), (mask))                                                    \
  X(void, glClearColor, (GLclampf r, GLclampf g, GLclampf b, GLclampf a), (r, g, b, a))          \
  X(void, glClearDepth, (GLclampd depth), (depth))                                               \
  X(void, glClearStencil, (GLint s), (s))                                                        \
  X(void, glColorMask, (GLboolean r, GLboolean g, GLboolean b, GLboolean a), (r, g, b, a))       \
  X(void, glCopyTexImage2D,                                                                      \
    (GLenum target, GLint level, GLenum internal_format, GLint x, GLint y, GLsizei width,        \
     GLsizei height, GLint border),                                                              \
    (target, level, internal_format, x, y, width, height, border))                               \
  X(void, glCullFace, (GLenum mode), (mode))                                                     \
  X(void, glDeleteTextures, (GLsizei n, const GLuint* textures), (n, textures))                  \
  X(void, glDepthFunc, (GLenum func), (func))                                                    \
  X(void, glDepthMask, (GLboolean flag), (flag))                                                 \
  X(void, glDisable, (GLenum cap), (cap))                                                        \
  X(void, glDrawArrays, (GLenum mode, GLint first, GLsizei count), (mode, first, count))         \
  X(void, glDrawElements, (GLenum mode, GLsizei count, GLenum type, const GLvoid* indices),      \
    (mode, count, type, indices))                                                                \
  X(void, glEnable, (GLenum cap), (cap))                                                         \
  X(void, glFinish, (void), ())                                                                  \
  X(void, glFlush, (void), ())                                                                   \
  X(void, glGenTextures, (GLsizei n, GLuint * textures), (n, textures))                          \
  X(void, glGetBooleanv, (GLenum pname, GLboolean * params), (pname, params))                    \
  X(void, glGetDoublev, (GLenum pname, GLdouble * params), (pname, params))                      \
  X(GLenum, glGetError, (void), ())                                                              \
  X(void, glGetFloatv, (GLenum pname, GLfloat * params), (pname, params))                        \
  X(void, glGetIntegerv, (GLenum pname, GLint * params), (pname, params))                        \
  X(const GLubyte*, glGetString, (GLenum name), (name))                                          \
  X(void, glGetTexImage,                                                                         \
    (GLenum target, GLint level, GLenum format, GLenum type, GLvoid * pixels),                   \
    (target, level, format, type, pixels))                                                       \
  X(void, glGetTexLevelParameteriv, (GLenum target, GLint level, GLenum pname, GLint * params),  \
    (target, level, pname, params))                                                              \
  X(GLboolean, glIsEnabled, (GLenum cap), (cap))                                                 \
  X(void, glLineWidth, (GLfloat width), (width))                                                 \
  X(void, glPixelStorei, (GLenum pname, GLint param), (pname, param))                            \
  X(void, glPointSize, (GLfloat size), (size))                                                   \
  X(void, glReadBuffer, (GLenum mode), (mode))                                                   \
  X(void, glReadPixels,                                                                          \
    (GLint x, GLint y, GLsizei width, GLsizei height, GLenum format, GLenum type,                \
     GLvoid * pixels),                                                                           \
    (x, y, width, height, format, type, pixels))                                                 \
  X(void, glScissor, (GLint x, GLint y, GLsizei width, GLsizei height), (x, y, width, height))   \
  X(void, glTexEnvi, (GLenum target, GLenum pname, GLint param), (target, pname, param))         \
  X(void, glTexImage1D,                                                                          \
    (GLenum target, GLint level, GLint internal_format, GLsizei width, GLint border,             \
     GLenum format, GLenum type, const GLvoid* pixels),                                          \
    (target, level, internal_format, width, border, format, type, pixels))                       \
  X(void, glTexImage2D,                                                                          \
    (GLenum target, GLint level, GLint internal_format, GLsizei width, GLsizei height,           \
     GLint border, GLenum format, GLenum type, const GLvoid* pixels),                            \
    (target, level, internal_format, width, height, border, format, type, pixels))               \
  X(void, glTexParameterf, (GLenum target, GLenum pname, GLfloat param), (target, pname, param)) \
  X(void, glTexParameterfv, (GLenum target, GLenum pname, const GLfloat* params),                \
    (target, pname, params))                                                                     \
  X(void, glTexParameteri, (GLenum target, GLenum pname, GLint param), (target, pname, param))   \
  X(void, glViewport, (GLint x, GLint y, GLsizei width, GLsizei height), (x, y, width, height))

namespace ncfsim::render::detail {
namespace {

#define NCFSIM_GL_INDEX(ret, name, params, args) k_##name,
enum GlIndex : int { NCFSIM_GL_FORWARDED(NCFSIM_GL_INDEX) kNumForwarded };
#undef NCFSIM_GL_INDEX

#define NCFSIM_GL_NAME(ret, name, params, args) #name,
constexpr std::array<const char*, kNumForwarded> kNames = {NCFSIM_GL_FORWARDED(NCFSIM_GL_NAME)};
#undef NCFSIM_GL_NAME

using Table = std::array<GlProc, kNumForwarded>;

// The system libGL's functions, looked up once (the next definition after the executable's).
const Table& native_table() {
  static const Table table = [] {
    Table t{};
    for (int i = 0; i < kNumForwarded; ++i) {
      t[i] = reinterpret_cast<GlProc>(dlsym(RTLD_NEXT, kNames[i]));
    }
    return t;
  }();
  return table;
}

Table osmesa_table{};                       // filled by route_gl_calls
std::atomic<const Table*> active{nullptr};  // nullptr = native
std::atomic<GlProcLookup> osmesa_lookup{nullptr};

[[noreturn]] void missing(const char* name) {
  std::fprintf(stderr, "ncfsim render: OpenGL function %s not found in the system libGL\n", name);
  std::abort();
}

GlProc proc(int index) {
  const Table* t = active.load(std::memory_order_acquire);
  GlProc p = (t != nullptr ? *t : native_table())[index];
  if (p == nullptr) {
    missing(kNames[index]);
  }
  return p;
}

using GlxLookup = GlProc (*)(const GLubyte*);

// real: the system GLX's lookup function of the same name (nullptr when there is none).
GlProc glx_lookup(GlxLookup real, const GLubyte* name) {
  const GlProcLookup os = osmesa_lookup.load(std::memory_order_acquire);
  if (os != nullptr && name != nullptr &&
      std::strncmp(reinterpret_cast<const char*>(name), "glX", 3) != 0) {
    return os(reinterpret_cast<const char*>(name));
  }
  return real != nullptr ? real(name) : nullptr;
}

}  // namespace
}  // namespace ncfsim::render::detail

extern "C" {

#define NCFSIM_GL_DEFINE(ret, name, params, args)                                               \
  __attribute__((visibility("default"))) ret GLAPIENTRY name params {                           \
    using Fn = ret(GLAPIENTRY*) params;                                                         \
    return reinterpret_cast<Fn>(ncfsim::render::detail::proc(ncfsim::render::detail::k_##name)) \
        args;                                                                                   \
  }
NCFSIM_GL_FORWARDED(NCFSIM_GL_DEFINE)
#undef NCFSIM_GL_DEFINE

// <GL/glx.h> is not included (it pulls in Xlib); the signatures are GLX 1.4's.
__attribute__((visibility("default"))) ncfsim::render::detail::GlProc glXGetProcAddressARB(
    const GLubyte* name) {
  using ncfsim::render::detail::GlxLookup;
  static const auto real = reinterpret_cast<GlxLookup>(dlsym(RTLD_NEXT, "glXGetProcAddressARB"));
  return ncfsim::render::detail::glx_lookup(real, name);
}

__attribute__((visibility("default"))) ncfsim::render::detail::GlProc glXGetProcAddress(
    const GLubyte* name) {
  using ncfsim::render::detail::GlxLookup;
  static const auto real = reinterpret_cast<GlxLookup>(dlsym(RTLD_NEXT, "glXGetProcAddress"));
  return ncfsim::render::detail::glx_lookup(real, name);
}

}  // extern "C"

namespace ncfsim::render::detail {

void route_gl_calls(GlProcLookup lookup) {
  if (lookup == nullptr) {
    const Table& native = native_table();
    for (int i = 0; i < kNumForwarded; ++i) {
      if (native[i] == nullptr) {
        throw std::runtime_error(std::string("OpenGL function ") + kNames[i] +
                                 " not found in the system libGL");
      }
    }
    osmesa_lookup.store(nullptr, std::memory_order_release);
    active.store(nullptr, std::memory_order_release);
    return;
  }
  Table t{};
  for (int i = 0; i < kNumForwarded; ++i) {
    t[i] = lookup(kNames[i]);
    if (t[i] == nullptr) {
      throw std::runtime_error(std::string("OSMesaGetProcAddress(\"") + kNames[i] +
                               "\") returned nothing");
    }
  }
  osmesa_table = t;
  osmesa_lookup.store(lookup, std::memory_order_release);
  active.store(&osmesa_table, std::memory_order_release);
}

std::string gl_forwarding_problem() {
#define NCFSIM_GL_CHECK(ret, name, params, args)                                          \
  if (dlsym(RTLD_DEFAULT, #name) != reinterpret_cast<void*>(&::name)) {                   \
    return std::string("the process-wide ") + #name +                                     \
           " is not the executable's forwarding function (build the executable with the " \
           "CMake function ncfsim_enable_offscreen_rendering, ENABLE_EXPORTS ON)";        \
  }
  NCFSIM_GL_FORWARDED(NCFSIM_GL_CHECK)
  NCFSIM_GL_CHECK(GlProc, glXGetProcAddressARB, (), ())
#undef NCFSIM_GL_CHECK
  return {};
}

}  // namespace ncfsim::render::detail
