#pragma once
// Batched (SIMD over elements) helpers of the element kernels: one register holds one quantity
// of W consecutive elements, so that [component][n] state arrays load and store as whole vectors.
// W is the widest the build targets (8 doubles with AVX-512, 4 with AVX2, 2 with SSE2).
#include <experimental/simd>

namespace ncfsim::fem::batch {

namespace stdx = std::experimental;
using VD = stdx::native_simd<double>;
constexpr int W = static_cast<int>(VD::size());

/// Lanes [0, cnt) from p; lanes past cnt repeat the last element (computed, never stored).
inline VD load(const double* p, int cnt) {
  if (cnt == W) return VD(p, stdx::element_aligned);
  return VD([&](auto l) { return p[static_cast<int>(l) < cnt ? static_cast<int>(l) : cnt - 1]; });
}

/// Stores lanes [0, cnt) to p.
inline void store(double* p, const VD& v, int cnt) {
  if (cnt == W) {
    v.copy_to(p, stdx::element_aligned);
  } else {
    for (int l = 0; l < cnt; ++l) p[l] = v[l];
  }
}

/// Aligned load/store of chunk scratch (alignas(64), offsets multiple of W).
inline VD load_a(const double* p) { return VD(p, stdx::vector_aligned); }
inline void store_a(double* p, const VD& v) { v.copy_to(p, stdx::vector_aligned); }

/// `v` with the lanes past cnt set to zero (for sums over elements).
inline VD live(const VD& v, int cnt) {
  if (cnt == W) return v;
  VD r = v;
  stdx::where(VD([](auto l) { return static_cast<double>(l); }) >= static_cast<double>(cnt), r) = 0.0;
  return r;
}

}  // namespace ncfsim::fem::batch
