// Internal to ncfsim_render: where the process's OpenGL calls go (see gl_forward.cpp).
//
// Debian's VTK 9.1 calls the OpenGL 1.x entry points (glClear, glReadPixels, ...) straight from
// libGL (GLVND) and fetches every later one through GLEW, which asks glXGetProcAddressARB. GLVND
// only dispatches to EGL and GLX contexts. The executable therefore defines those entry points
// itself (gl_forward.cpp, exported like the glewInit shim) and sends each call either to the
// system libGL (the EGL back end) or to OSMesa's functions (the OSMesa back end).
#pragma once

#include <string>

namespace ncfsim::render::detail {

using GlProc = void (*)();
using GlProcLookup = GlProc (*)(const char* name);  // OSMesaGetProcAddress's type

// Routes the forwarded entry points (and the non-GLX names asked of glXGetProcAddressARB) to
// osmesa_lookup's functions, or with nullptr to the system libGL as linked. Resolves every
// forwarded entry point first and throws std::runtime_error naming one that is missing.
// Not thread-safe: call with the render lock held, before making the context current.
void route_gl_calls(GlProcLookup osmesa_lookup);

// Empty when the process-wide definition of every forwarded entry point is the executable's (so
// that VTK's and GLEW's calls land in gl_forward.cpp); otherwise what is wrong.
std::string gl_forwarding_problem();

}  // namespace ncfsim::render::detail
