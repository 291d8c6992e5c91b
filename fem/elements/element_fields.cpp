#include "fem/elements/element_fields.hpp"

#include <algorithm>
#include <cmath>

#include "fem/elements/hex8_basis.hpp"

namespace ncfsim::fem {

namespace {

// F M of element e (deformation gradient at the centre times the reference material axes, the
// kernel's F = J J_ref^{-1}), row-major; returns det F.
double centre_FM(const Hex8Block& b, const double* x, std::size_t e, double FM[9]) {
  const std::size_t n = b.n;
  double J[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
  for (int I = 0; I < 8; ++I) {
    const std::size_t node = static_cast<std::size_t>(b.conn[static_cast<std::size_t>(I) * n + e]);
    for (int r = 0; r < 3; ++r)
      for (int k = 0; k < 3; ++k) J[3 * r + k] += 0.125 * kHex8Sign[k + 1][I] * x[3 * node + static_cast<std::size_t>(r)];
  }
  double F[9];
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += J[3 * r + k] * b.jac_inv0[static_cast<std::size_t>(3 * k + c) * n + e];
      F[3 * r + c] = s;
    }
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += F[3 * r + k] * b.mat_axes[static_cast<std::size_t>(3 * k + c) * n + e];
      FM[3 * r + c] = s;
    }
  return F[0] * (F[4] * F[8] - F[5] * F[7]) - F[1] * (F[3] * F[8] - F[5] * F[6]) + F[2] * (F[3] * F[7] - F[4] * F[6]);
}

}  // namespace

double von_mises(const double s[6]) {
  const double a = s[0] - s[1], b = s[1] - s[2], c = s[2] - s[0];
  return std::sqrt(0.5 * (a * a + b * b + c * c) + 3.0 * (s[3] * s[3] + s[4] * s[4] + s[5] * s[5]));
}

void hex8_output_fields(const Hex8Block& b, const double* x, double* cauchy, double* vm, double* fibre) {
  const std::size_t n = b.n;
  for (std::size_t e = 0; e < n; ++e) {
    double FM[9];
    const double detF = centre_FM(b, x, e, FM);
    const double* st = b.stress.data();
    const double Sm[9] = {st[e], st[3 * n + e], st[5 * n + e], st[3 * n + e], st[n + e],
                          st[4 * n + e], st[5 * n + e], st[4 * n + e], st[2 * n + e]};
    double sg[9];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) {
        double s = 0;
        for (int i = 0; i < 3; ++i)
          for (int j = 0; j < 3; ++j) s += FM[3 * r + i] * Sm[3 * i + j] * FM[3 * c + j];
        sg[3 * r + c] = s / detF;
      }
    double* out = cauchy + 6 * e;
    out[0] = sg[0], out[1] = sg[4], out[2] = sg[8], out[3] = sg[1], out[4] = sg[5], out[5] = sg[2];
    if (b.n_eroded && b.eroded[e]) std::fill(out, out + 6, 0.0);  // carries nothing
    vm[e] = von_mises(out);
    const double fx = FM[0], fy = FM[3], fz = FM[6];
    const double len = std::sqrt(fx * fx + fy * fy + fz * fz);
    fibre[3 * e] = fx / len, fibre[3 * e + 1] = fy / len, fibre[3 * e + 2] = fz / len;
  }
}

void hex8_fibre_direction(const Hex8Block& b, const double* x, std::size_t e, double out[3]) {
  double FM[9];
  centre_FM(b, x, e, FM);
  const double len = std::sqrt(FM[0] * FM[0] + FM[3] * FM[3] + FM[6] * FM[6]);
  out[0] = FM[0] / len, out[1] = FM[3] / len, out[2] = FM[6] / len;
}

}  // namespace ncfsim::fem
