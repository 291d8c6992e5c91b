// Internal to ncfsim_render: an OSMesa (Mesa off-screen, software) OpenGL context, core profile
// 3.2+, rendering into a buffer in memory, made current on the calling thread for the lifetime of
// the object. libOSMesa is opened at run time (dlopen, never closed), so that a machine without it
// still renders through EGL. Makes the executable's GL entry points call OSMesa (gl_forward.hpp).
#pragma once

#include <vector>

#include "gl_context.hpp"

namespace ncfsim::render::detail {

class OsMesaContext final : public GlContext {
 public:
  // Creates the context and makes it current; throws std::runtime_error saying what failed.
  OsMesaContext(int width, int height);
  ~OsMesaContext() override;  // releases (not current any more) and destroys the context

 private:
  void* context_ = nullptr;            // OSMesaContext
  std::vector<unsigned char> buffer_;  // RGBA8 colour buffer: [4 * width * height]
};

}  // namespace ncfsim::render::detail
