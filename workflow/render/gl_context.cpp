#include "gl_context.hpp"

#include <atomic>
#include <cstdlib>
#include <optional>
#include <stdexcept>
#include <string>

#include "egl_context.hpp"
#include "osmesa_context.hpp"

namespace ncfsim::render::detail {
namespace {

// -1: none set, read the environment; otherwise a RenderBackend.
std::atomic<int> backend_override{-1};

// Auto mode: why OSMesa failed, once it has (it is not tried again in this process).
std::optional<std::string>& osmesa_failure() {
  static std::optional<std::string> why;
  return why;
}

}  // namespace

std::unique_ptr<GlContext> make_gl_context(int width, int height) {
  switch (requested_render_backend()) {
    case RenderBackend::OSMesa:
      return std::make_unique<OsMesaContext>(width, height);
    case RenderBackend::Egl:
      return std::make_unique<EglContext>(width, height);
    case RenderBackend::Auto:
      break;
  }
  std::optional<std::string>& failed = osmesa_failure();
  if (!failed) {
    try {
      return std::make_unique<OsMesaContext>(width, height);
    } catch (const std::exception& e) {
      failed = e.what();
    }
  }
  auto egl = std::make_unique<EglContext>(width, height);
  egl->description_ = "EGL (fallback; " + *failed +
                      "): " + egl->description().substr(egl->description().find(": ") + 2);
  return egl;
}

}  // namespace ncfsim::render::detail

namespace ncfsim::render {

void set_render_backend(std::optional<RenderBackend> backend) {
  detail::backend_override.store(backend ? static_cast<int>(*backend) : -1);
}

RenderBackend requested_render_backend() {
  if (const int set = detail::backend_override.load(); set >= 0) {
    return static_cast<RenderBackend>(set);
  }
  const char* env = std::getenv("NCFSIM_RENDER_BACKEND");
  const std::string value = env != nullptr ? env : "";
  if (value.empty() || value == "auto") {
    return RenderBackend::Auto;
  }
  if (value == "osmesa") {
    return RenderBackend::OSMesa;
  }
  if (value == "egl") {
    return RenderBackend::Egl;
  }
  throw std::runtime_error("off-screen rendering: NCFSIM_RENDER_BACKEND='" + value +
                           "' is not one of osmesa, egl, auto");
}

}  // namespace ncfsim::render
