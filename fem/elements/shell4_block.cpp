// GCC 12 reports false maybe-uninitialized warnings inside its own AVX-512 intrinsics when it
// inlines std::experimental::simd (as in hex8_block.cpp).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
// Belytschko-Tsay shells: geometry, mass, stable step and the batched force kernel
// (fem/elements/shell4_block.hpp has the formulation).
#include "fem/elements/shell4_block.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "fem/elements/simd_batch.hpp"
#include "fem/errors.hpp"

namespace ncfsim::fem {

namespace {

// sqrt(a^2 + b^2) without hypot's overflow care (lengths here are far from overflow).
inline double len2(double a, double b) { return std::sqrt(a * a + b * b); }

// Elements per pass: the geometry of a chunk stays in L1 between the pass that hands the
// membrane law its deformation gradients and the pass that makes the forces.
constexpr std::size_t kChunk = 64;
// Drilling spring per node: this share of the membrane stiffness times the area (N m/rad).
constexpr double kDrillingRatio = 1e-3;

// The co-rotational frame of a shell with corners p[I] = (x, y, z): normal along the cross
// product of the diagonals, axis 1 on the bisector of the diagonals (the same frame whichever
// node comes first), local corner coordinates about the centre, projected area, and the
// centre gradients B[a][I] = dN_I/dx_a. False for a degenerate shell.
struct ShellFrame {
  double e[3][3];  // e[k] = axis k (global components)
  double xl[4], yl[4];
  double area;
  double B[2][4];
};

bool shell_frame(const double p[4][3], ShellFrame& f) {
  double a[3], b[3], n[3];
  for (int k = 0; k < 3; ++k) a[k] = p[2][k] - p[0][k], b[k] = p[3][k] - p[1][k];
  n[0] = a[1] * b[2] - a[2] * b[1];
  n[1] = a[2] * b[0] - a[0] * b[2];
  n[2] = a[0] * b[1] - a[1] * b[0];
  const double nn = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double na = std::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  const double nb = std::sqrt(b[0] * b[0] + b[1] * b[1] + b[2] * b[2]);
  if (!(nn > 0) || !(na > 0) || !(nb > 0)) return false;
  double e1[3], n1 = 0;
  for (int k = 0; k < 3; ++k) {
    f.e[2][k] = n[k] / nn;
    e1[k] = a[k] / na - b[k] / nb;
    n1 += e1[k] * e1[k];
  }
  n1 = std::sqrt(n1);
  if (!(n1 > 0)) return false;
  for (int k = 0; k < 3; ++k) f.e[0][k] = e1[k] / n1;
  const double* e3 = f.e[2];
  const double* ea = f.e[0];
  f.e[1][0] = e3[1] * ea[2] - e3[2] * ea[1];
  f.e[1][1] = e3[2] * ea[0] - e3[0] * ea[2];
  f.e[1][2] = e3[0] * ea[1] - e3[1] * ea[0];
  double c[3];
  for (int k = 0; k < 3; ++k) c[k] = 0.25 * (p[0][k] + p[1][k] + p[2][k] + p[3][k]);
  for (int I = 0; I < 4; ++I) {
    double d[3];
    for (int k = 0; k < 3; ++k) d[k] = p[I][k] - c[k];
    f.xl[I] = d[0] * f.e[0][0] + d[1] * f.e[0][1] + d[2] * f.e[0][2];
    f.yl[I] = d[0] * f.e[1][0] + d[1] * f.e[1][1] + d[2] * f.e[1][2];
  }
  const double* x = f.xl;
  const double* y = f.yl;
  const double two_a =
      x[0] * (y[1] - y[3]) + x[1] * (y[2] - y[0]) + x[2] * (y[3] - y[1]) + x[3] * (y[0] - y[2]);
  if (!(two_a > 0)) return false;
  f.area = 0.5 * two_a;
  const double s = 1.0 / two_a;
  f.B[0][0] = (y[1] - y[3]) * s, f.B[0][1] = (y[2] - y[0]) * s;
  f.B[0][2] = (y[3] - y[1]) * s, f.B[0][3] = (y[0] - y[2]) * s;
  f.B[1][0] = (x[3] - x[1]) * s, f.B[1][1] = (x[0] - x[2]) * s;
  f.B[1][2] = (x[1] - x[3]) * s, f.B[1][3] = (x[2] - x[0]) * s;
  return true;
}

void gather(const Shell4Block& b, std::size_t e, const double* x, double p[4][3]) {
  for (std::size_t I = 0; I < 4; ++I) {
    const auto node = static_cast<std::size_t>(b.conn[I * b.n + e]);
    for (int k = 0; k < 3; ++k) p[I][k] = x[3 * node + static_cast<std::size_t>(k)];
  }
}

// F = dx/dX at the centre from the current local corners and the reference gradients.
void inplane_gradient(const Shell4Block& b, std::size_t e, const ShellFrame& f, double F[4]) {
  F[0] = F[1] = F[2] = F[3] = 0;
  for (std::size_t I = 0; I < 4; ++I) {
    const double b1 = b.b0[I * b.n + e], b2 = b.b0[(4 + I) * b.n + e];
    F[0] += f.xl[I] * b1, F[1] += f.xl[I] * b2;
    F[2] += f.yl[I] * b1, F[3] += f.yl[I] * b2;
  }
}

// Symmetric 2x2 tensor (11, 22, 12) rotated: R^T T R (to the reference frame) or R T R^T.
inline void to_reference(double c, double s, const double t[3], double out[3]) {
  out[0] = c * c * t[0] + 2 * c * s * t[2] + s * s * t[1];
  out[1] = s * s * t[0] - 2 * c * s * t[2] + c * c * t[1];
  out[2] = -c * s * t[0] + (c * c - s * s) * t[2] + c * s * t[1];
}
inline void to_current(double c, double s, const double t[3], double out[3]) {
  to_reference(c, -s, t, out);
}

// Gauss-Legendre points and weights on [-1, 1].
struct GaussRule {
  int n;
  double xi[5], w[5];
};
GaussRule gauss_rule(int n) {
  switch (n) {
    case 1:
      return {1, {0}, {2}};
    case 2:
      return {2, {-1 / std::sqrt(3.0), 1 / std::sqrt(3.0)}, {1, 1}};
    case 3:
      return {3, {-std::sqrt(0.6), 0, std::sqrt(0.6)}, {5.0 / 9, 8.0 / 9, 5.0 / 9}};
    case 4: {
      const double a = std::sqrt(3.0 / 7 - 2.0 / 7 * std::sqrt(1.2)),
                   c = std::sqrt(3.0 / 7 + 2.0 / 7 * std::sqrt(1.2));
      const double wa = (18 + std::sqrt(30.0)) / 36, wc = (18 - std::sqrt(30.0)) / 36;
      return {4, {-c, -a, a, c}, {wc, wa, wa, wc}};
    }
    default: {
      const double a = std::sqrt(5 - 2 * std::sqrt(10.0 / 7)) / 3,
                   c = std::sqrt(5 + 2 * std::sqrt(10.0 / 7)) / 3;
      const double wa = (322 + 13 * std::sqrt(70.0)) / 900, wc = (322 - 13 * std::sqrt(70.0)) / 900;
      return {5, {-c, -a, 0, a, c}, {wc, wa, 128.0 / 225, wa, wc}};
    }
  }
}

[[noreturn]] void degenerate(const Shell4Block& b, std::size_t e, const char* where) {
  std::ostringstream os;
  os << "shell " << b.user_id[e] << " of part " << b.part << " is degenerate " << where
     << " (zero area, or its diagonals parallel)";
  throw NumericalError(os.str());
}

}  // namespace

void shell4_initialise(Shell4Block& b, const double* x_ref, const double axis[3]) {
  const std::size_t n = b.n;
  b.area0.assign(n, 0);
  b.b0.assign(8 * n, 0);
  b.axes0.assign(4 * n, 0);
  if (b.mass_scale.size() != n) b.mass_scale.assign(n, 1.0);
  for (auto* v : {&b.strain, &b.curvature, &b.resultant, &b.moment}) v->assign(3 * n, 0);
  for (auto* v : {&b.shear, &b.shear_force}) v->assign(2 * n, 0);
  b.hg_force.assign(5 * n, 0);
  b.drill_moment.assign(4 * n, 0);
  b.polar_angle.assign(2 * n, 0);
  for (std::size_t e = 0; e < n; ++e) b.polar_angle[2 * e] = 1;
  const MembraneLaw* law = b.section.law;
  b.history.assign(law ? static_cast<std::size_t>(law->n_history()) * n : 0, 0);

  const double t = b.section.thickness;
  if (law) {
    b.membrane_stiffness = law->membrane_stiffness();
    b.bending_stiffness = law->bending_stiffness();
    // Transverse shear as in a plate of that bending stiffness with G = E / 2 (nu = 0): stiff
    // enough that the fabric bends as a Kirchhoff plate, no stiffer.
    b.shear_stiffness = 5.0 * b.bending_stiffness / (t * t);
    b.areal_density = law->areal_density();
    b.poisson = 0;
  } else {
    const double E = b.section.youngs_modulus, nu = b.section.poisson_ratio;
    b.membrane_stiffness = E * t / (1 - nu * nu);
    b.bending_stiffness = E * t * t * t / (12 * (1 - nu * nu));
    b.shear_stiffness = 5.0 / 6.0 * E / (2 * (1 + nu)) * t;
    b.areal_density = b.section.density * t;
    b.poisson = nu;
  }

  for (std::size_t e = 0; e < n; ++e) {
    double p[4][3];
    gather(b, e, x_ref, p);
    ShellFrame f;
    if (!shell_frame(p, f)) degenerate(b, e, "in the reference shape");
    b.area0[e] = f.area;
    for (std::size_t I = 0; I < 4; ++I) {
      b.b0[I * n + e] = f.B[0][I];
      b.b0[(4 + I) * n + e] = f.B[1][I];
    }
    // Material axis 1 projected on the element's plane, axis 2 a right angle from it.
    double a1 = axis[0] * f.e[0][0] + axis[1] * f.e[0][1] + axis[2] * f.e[0][2];
    double a2 = axis[0] * f.e[1][0] + axis[1] * f.e[1][1] + axis[2] * f.e[1][2];
    const double na = len2(a1, a2);
    if (!(na > 1e-6)) {
      std::ostringstream os;
      os << "shell " << b.user_id[e] << " of part " << b.part
         << ": the material axis 1 is normal to the shell (give an axis in its plane)";
      throw InputError("", "part.material_axis_1", os.str());
    }
    a1 /= na, a2 /= na;
    b.axes0[e] = a1, b.axes0[n + e] = a2, b.axes0[2 * n + e] = -a2, b.axes0[3 * n + e] = a1;
  }
}

void shell4_lumped_mass(const Shell4Block& b, double* mass) {
  for (std::size_t e = 0; e < b.n; ++e) {
    const double m = 0.25 * b.areal_density * b.mass_scale[e] * b.area0[e];
    for (std::size_t I = 0; I < 4; ++I) {
      const auto node = static_cast<std::size_t>(b.conn[I * b.n + e]);
      for (int k = 0; k < 3; ++k) mass[3 * node + static_cast<std::size_t>(k)] += m;
    }
  }
}

void shell4_rotary_inertia(const Shell4Block& b, double* inertia) {
  const double t = b.section.thickness;
  for (std::size_t e = 0; e < b.n; ++e) {
    const double m = 0.25 * b.areal_density * b.mass_scale[e] * b.area0[e];
    const double r2 = t * t / 12 + b.area0[e] / 8;
    for (std::size_t I = 0; I < 4; ++I) inertia[b.conn[I * b.n + e]] += m * r2;
  }
}

void shell4_element_steps(const Shell4Block& b, const double* x, std::vector<double>& dt) {
  dt.assign(b.n, 0.0);
  for (std::size_t e = 0; e < b.n; ++e) {
    double p[4][3];
    gather(b, e, x, p);
    ShellFrame f;
    if (!shell_frame(p, f)) continue;  // step 0: the solver stops and names the element
    double lmin = 1e300, lmax = 0;
    for (int I = 0; I < 4; ++I) {
      const int J = (I + 1) % 4;
      const double l = len2(f.xl[J] - f.xl[I], f.yl[J] - f.yl[I]);
      lmin = std::min(lmin, l), lmax = std::max(lmax, l);
    }
    const double L = std::min(lmin, f.area / lmax);
    dt[e] = L * std::sqrt(b.areal_density * b.mass_scale[e] / b.membrane_stiffness);
  }
}

namespace {

using batch::VD;
using batch::W;
namespace stdx = std::experimental;

// The co-rotational frame of W shells at once (shell_frame in lanes). `ok` false for a
// degenerate lane, whose values are finite stand-ins.
struct FrameLanes {
  VD e[3][3];
  VD xl[4], yl[4];
  VD area, B[2][4];
  stdx::simd_mask<double, stdx::simd_abi::native<double>> ok;
};

// Node coordinates of lanes [0, cnt) of elements e0.. (the last lane repeated past cnt).
inline void gather_lanes(const Shell4Block& b, std::size_t e0, int cnt, const double* x,
                         VD p[4][3]) {
  for (std::size_t I = 0; I < 4; ++I) {
    const std::int32_t* c = b.conn.data() + I * b.n + e0;
    alignas(64) std::size_t base[W];
    for (int l = 0; l < W; ++l) base[l] = 3 * static_cast<std::size_t>(c[l < cnt ? l : cnt - 1]);
    for (std::size_t k = 0; k < 3; ++k)
      p[I][k] = VD([&](auto l) { return x[base[static_cast<int>(l)] + k]; });
  }
}

// The same for three nodal arrays at once (positions, velocities, rotation velocities).
inline void gather_lanes3(const Shell4Block& b, std::size_t e0, int cnt, const double* x,
                          const double* v, const double* w, VD p[4][3], VD vv[4][3], VD ww[4][3]) {
  for (std::size_t I = 0; I < 4; ++I) {
    const std::int32_t* c = b.conn.data() + I * b.n + e0;
    alignas(64) std::size_t base[W];
    for (int l = 0; l < W; ++l) base[l] = 3 * static_cast<std::size_t>(c[l < cnt ? l : cnt - 1]);
    for (std::size_t k = 0; k < 3; ++k) {
      p[I][k] = VD([&](auto l) { return x[base[static_cast<int>(l)] + k]; });
      vv[I][k] = VD([&](auto l) { return v[base[static_cast<int>(l)] + k]; });
      ww[I][k] = VD([&](auto l) { return w[base[static_cast<int>(l)] + k]; });
    }
  }
}

inline void frame_lanes(const VD p[4][3], FrameLanes& f) {
  VD a[3], bb[3];
  for (int k = 0; k < 3; ++k) a[k] = p[2][k] - p[0][k], bb[k] = p[3][k] - p[1][k];
  const VD n0 = a[1] * bb[2] - a[2] * bb[1], n1 = a[2] * bb[0] - a[0] * bb[2],
           n2 = a[0] * bb[1] - a[1] * bb[0];
  VD nn = stdx::sqrt(n0 * n0 + n1 * n1 + n2 * n2);
  VD na = stdx::sqrt(a[0] * a[0] + a[1] * a[1] + a[2] * a[2]);
  VD nb = stdx::sqrt(bb[0] * bb[0] + bb[1] * bb[1] + bb[2] * bb[2]);
  f.ok = (nn > 0.0) && (na > 0.0) && (nb > 0.0);
  stdx::where(!f.ok, nn) = 1.0;
  stdx::where(!f.ok, na) = 1.0;
  stdx::where(!f.ok, nb) = 1.0;
  const VD inn = 1.0 / nn, ina = 1.0 / na, inb = 1.0 / nb;
  f.e[2][0] = n0 * inn, f.e[2][1] = n1 * inn, f.e[2][2] = n2 * inn;
  VD e1[3];
  for (int k = 0; k < 3; ++k) e1[k] = a[k] * ina - bb[k] * inb;
  VD m1 = stdx::sqrt(e1[0] * e1[0] + e1[1] * e1[1] + e1[2] * e1[2]);
  f.ok = f.ok && (m1 > 0.0);
  stdx::where(!(m1 > 0.0), m1) = 1.0;
  const VD im1 = 1.0 / m1;
  for (int k = 0; k < 3; ++k) f.e[0][k] = e1[k] * im1;
  const VD* e3 = f.e[2];
  const VD* ea = f.e[0];
  f.e[1][0] = e3[1] * ea[2] - e3[2] * ea[1];
  f.e[1][1] = e3[2] * ea[0] - e3[0] * ea[2];
  f.e[1][2] = e3[0] * ea[1] - e3[1] * ea[0];
  VD c[3];
  for (int k = 0; k < 3; ++k) c[k] = 0.25 * (p[0][k] + p[1][k] + p[2][k] + p[3][k]);
  for (int I = 0; I < 4; ++I) {
    const VD d0 = p[I][0] - c[0], d1 = p[I][1] - c[1], d2 = p[I][2] - c[2];
    f.xl[I] = d0 * f.e[0][0] + d1 * f.e[0][1] + d2 * f.e[0][2];
    f.yl[I] = d0 * f.e[1][0] + d1 * f.e[1][1] + d2 * f.e[1][2];
  }
  const VD* xx = f.xl;
  const VD* yy = f.yl;
  VD two_a = xx[0] * (yy[1] - yy[3]) + xx[1] * (yy[2] - yy[0]) + xx[2] * (yy[3] - yy[1]) +
             xx[3] * (yy[0] - yy[2]);
  f.ok = f.ok && (two_a > 0.0);
  stdx::where(!(two_a > 0.0), two_a) = 1.0;
  f.area = 0.5 * two_a;
  const VD s = 1.0 / two_a;
  f.B[0][0] = (yy[1] - yy[3]) * s, f.B[0][1] = (yy[2] - yy[0]) * s;
  f.B[0][2] = (yy[3] - yy[1]) * s, f.B[0][3] = (yy[0] - yy[2]) * s;
  f.B[1][0] = (xx[3] - xx[1]) * s, f.B[1][1] = (xx[0] - xx[2]) * s;
  f.B[1][2] = (xx[1] - xx[3]) * s, f.B[1][3] = (xx[2] - xx[0]) * s;
}

inline void gradient_lanes(const Shell4Block& b, std::size_t e0, int cnt, const FrameLanes& f,
                           VD F[4]) {
  F[0] = F[1] = F[2] = F[3] = 0.0;
  for (std::size_t I = 0; I < 4; ++I) {
    const VD b1 = batch::load(b.b0.data() + I * b.n + e0, cnt),
             b2 = batch::load(b.b0.data() + (4 + I) * b.n + e0, cnt);
    F[0] += f.xl[I] * b1, F[1] += f.xl[I] * b2;
    F[2] += f.yl[I] * b1, F[3] += f.yl[I] * b2;
  }
}

}  // namespace

void shell4_internal_forces(Shell4Block& b, const double* x, const double* v, const double* w,
                            double dt, double* fo, double* mo, ElementEnergyIncrement& energy,
                            StableStep& step) {
  const std::size_t n = b.n;
  const MembraneLaw* law = b.section.law;
  const double t = b.section.thickness;
  const double Ks = b.shear_stiffness, D = b.bending_stiffness, nu = b.poisson;
  const double hg = b.section.hourglass_stiffness;
  const GaussRule gr = gauss_rule(std::clamp(b.section.integration_points, 1, 5));
  const double E = b.section.youngs_modulus;
  const double Q11 = law ? 0.0 : E / (1 - nu * nu), Q12 = nu * Q11, G2 = E / (1 + nu);
  const double slowness = std::sqrt(b.areal_density / b.membrane_stiffness);  // 1 / wave speed
  const double kdr_share = kDrillingRatio * b.membrane_stiffness;
  const double kmem_s = hg * b.membrane_stiffness / 8, kben_s = hg * D / 16,
               kw_s = hg * Ks * t * t / 12;
  VD w_int = 0.0, w_hg = 0.0;
  auto st = [&](std::vector<double>& a, int k) {
    return a.data() + static_cast<std::size_t>(k) * n;
  };

  // Membrane-law sections: the law sees a chunk's deformation gradients at once.
  alignas(64) double Fc[4][kChunk], Nc[3][kChunk], axes[4][kChunk];
  std::vector<double> hist_scratch;
  for (std::size_t c0 = 0; c0 < n; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, n - c0);
    if (law) {
      for (std::size_t j0 = 0; j0 < m; j0 += W) {
        const int cnt = static_cast<int>(std::min<std::size_t>(W, m - j0));
        VD p[4][3];
        gather_lanes(b, c0 + j0, cnt, x, p);
        FrameLanes f;
        frame_lanes(p, f);
        VD F[4];
        gradient_lanes(b, c0 + j0, cnt, f, F);
        for (int k = 0; k < 4; ++k) {
          stdx::where(!f.ok, F[k]) = (k == 0 || k == 3) ? 1.0 : 0.0;
          batch::store(&Fc[k][j0], F[k], cnt);
        }
      }
      for (int k = 0; k < 4; ++k)
        std::copy_n(b.axes0.data() + static_cast<std::size_t>(k) * n + c0, m, axes[k]);
      const auto nh = static_cast<std::size_t>(law->n_history());
      hist_scratch.resize(nh * kChunk);
      for (std::size_t r = 0; r < nh; ++r)
        std::copy_n(b.history.data() + r * n + c0, m, hist_scratch.data() + r * kChunk);
      MembraneBatch mb;
      mb.n = m, mb.stride = kChunk, mb.F = &Fc[0][0], mb.axes = &axes[0][0];
      mb.resultant = &Nc[0][0], mb.history = hist_scratch.data();
      law->update(mb);
      for (std::size_t r = 0; r < nh; ++r)
        std::copy_n(hist_scratch.data() + r * kChunk, m, b.history.data() + r * n + c0);
    }

    for (std::size_t j0 = 0; j0 < m; j0 += W) {
      const std::size_t e0 = c0 + j0;
      const int cnt = static_cast<int>(std::min<std::size_t>(W, m - j0));
      VD p[4][3], vv[4][3], ww[4][3];
      gather_lanes3(b, e0, cnt, x, v, w, p, vv, ww);
      FrameLanes f;
      frame_lanes(p, f);
      const VD A = f.area;
      VD F[4];
      gradient_lanes(b, e0, cnt, f, F);
      for (int k = 0; k < 4; ++k) stdx::where(!f.ok, F[k]) = (k == 0 || k == 3) ? 1.0 : 0.0;
      // Local velocities.
      VD vl[4][3], wl[4][3];
      for (int I = 0; I < 4; ++I)
        for (int k = 0; k < 3; ++k) {
          vl[I][k] = vv[I][0] * f.e[k][0] + vv[I][1] * f.e[k][1] + vv[I][2] * f.e[k][2];
          wl[I][k] = ww[I][0] * f.e[k][0] + ww[I][1] * f.e[k][1] + ww[I][2] * f.e[k][2];
        }
      // Polar rotation of F (no trigonometry) and its mid-step value.
      const VD r = stdx::sqrt((F[0] + F[3]) * (F[0] + F[3]) + (F[2] - F[1]) * (F[2] - F[1]));
      const VD c = (F[0] + F[3]) / r, s = (F[2] - F[1]) / r;
      VD co, so;
      co = VD([&](auto l) {
        const int j = static_cast<int>(l) < cnt ? static_cast<int>(l) : cnt - 1;
        return b.polar_angle[2 * (e0 + static_cast<std::size_t>(j))];
      });
      so = VD([&](auto l) {
        const int j = static_cast<int>(l) < cnt ? static_cast<int>(l) : cnt - 1;
        return b.polar_angle[2 * (e0 + static_cast<std::size_t>(j)) + 1];
      });
      VD rm = stdx::sqrt((c + co) * (c + co) + (s + so) * (s + so));
      const auto small = rm <= 1e-12;
      stdx::where(small, rm) = 1.0;
      VD cm = (c + co) / rm, sm = (s + so) / rm;
      stdx::where(small, cm) = c;
      stdx::where(small, sm) = s;
      {
        alignas(64) double cb[W], sb[W];
        c.copy_to(cb, stdx::vector_aligned);
        s.copy_to(sb, stdx::vector_aligned);
        for (int l = 0; l < cnt; ++l) {
          b.polar_angle[2 * (e0 + static_cast<std::size_t>(l))] = cb[l];
          b.polar_angle[2 * (e0 + static_cast<std::size_t>(l)) + 1] = sb[l];
        }
      }

      // Rates over the step (current frame), hourglass vectors, in-plane spin.
      VD dk[3] = {0.0, 0.0, 0.0}, dg[2] = {0.0, 0.0}, dq[5] = {0.0, 0.0, 0.0, 0.0, 0.0};
      const VD hx = f.xl[0] - f.xl[1] + f.xl[2] - f.xl[3],
               hy = f.yl[0] - f.yl[1] + f.yl[2] - f.yl[3];
      VD gam[4], bb = 0.0, spin = 0.0;
      for (int I = 0; I < 4; ++I) {
        const VD b1 = f.B[0][I], b2 = f.B[1][I];
        const double h = (I % 2 == 0) ? 1.0 : -1.0;
        spin += 0.5 * (b1 * vl[I][1] - b2 * vl[I][0]);
        bb += b1 * b1 + b2 * b2;
        dk[0] += b1 * wl[I][1];
        dk[1] -= b2 * wl[I][0];
        dk[2] += 0.5 * (b2 * wl[I][1] - b1 * wl[I][0]);
        dg[0] += b1 * vl[I][2] + 0.25 * wl[I][1];
        dg[1] += b2 * vl[I][2] - 0.25 * wl[I][0];
        gam[I] = 0.25 * (h - hx * b1 - hy * b2);
        dq[0] += gam[I] * vl[I][0], dq[1] += gam[I] * vl[I][1], dq[2] += gam[I] * vl[I][2];
        dq[3] += gam[I] * wl[I][0], dq[4] += gam[I] * wl[I][1];
      }
      for (VD& d : dk) d *= dt;
      for (VD& d : dg) d *= dt;
      for (VD& d : dq) d *= dt;
      // ... to the reference frame (R^T at mid-step).
      const VD cm2 = cm * cm, sm2 = sm * sm, csm = cm * sm;
      const VD dkr[3] = {cm2 * dk[0] + 2.0 * csm * dk[2] + sm2 * dk[1],
                         sm2 * dk[0] - 2.0 * csm * dk[2] + cm2 * dk[1],
                         -csm * dk[0] + (cm2 - sm2) * dk[2] + csm * dk[1]};
      const VD dgr[2] = {cm * dg[0] + sm * dg[1], -sm * dg[0] + cm * dg[1]};
      const VD dqr[5] = {cm * dq[0] + sm * dq[1], -sm * dq[0] + cm * dq[1], dq[2],
                         cm * dq[3] + sm * dq[4], -sm * dq[3] + cm * dq[4]};

      VD kap[3], gsh[2], kold[3], gold[2];
      for (int k = 0; k < 3; ++k) {
        kold[k] = batch::load(st(b.curvature, k) + e0, cnt);
        kap[k] = kold[k] + dkr[k];
      }
      for (int k = 0; k < 2; ++k) {
        gold[k] = batch::load(st(b.shear, k) + e0, cnt);
        gsh[k] = gold[k] + dgr[k];
      }
      const VD Em[3] = {0.5 * (F[0] * F[0] + F[2] * F[2] - 1.0),
                        0.5 * (F[1] * F[1] + F[3] * F[3] - 1.0), 0.5 * (F[0] * F[1] + F[2] * F[3])};
      const VD J = F[0] * F[3] - F[1] * F[2];
      const VD iJ = 1.0 / J;

      VD Nr[3], Ncur[3], Mr[3];
      if (law) {
        for (int k = 0; k < 3; ++k) Ncur[k] = batch::load(&Nc[k][j0], cnt);
        const VD Fi0 = F[3] * iJ, Fi1 = -F[1] * iJ, Fi2 = -F[2] * iJ, Fi3 = F[0] * iJ;
        const VD a11 = Fi0 * Ncur[0] + Fi1 * Ncur[2], a12 = Fi0 * Ncur[2] + Fi1 * Ncur[1];
        const VD a21 = Fi2 * Ncur[0] + Fi3 * Ncur[2], a22 = Fi2 * Ncur[2] + Fi3 * Ncur[1];
        Nr[0] = J * (a11 * Fi0 + a12 * Fi1);
        Nr[1] = J * (a21 * Fi2 + a22 * Fi3);
        Nr[2] = J * (a11 * Fi2 + a12 * Fi3);
        Mr[0] = D * kap[0], Mr[1] = D * kap[1], Mr[2] = D * kap[2];
      } else {
        for (int k = 0; k < 3; ++k) Nr[k] = 0.0, Mr[k] = 0.0;
        for (int q = 0; q < gr.n; ++q) {
          const double z = 0.5 * t * gr.xi[q], wz = 0.5 * t * gr.w[q];
          const VD e11 = Em[0] + z * kap[0], e22 = Em[1] + z * kap[1], e12 = Em[2] + z * kap[2];
          const VD S0 = Q11 * e11 + Q12 * e22, S1 = Q12 * e11 + Q11 * e22, S2 = G2 * e12;
          Nr[0] += wz * S0, Nr[1] += wz * S1, Nr[2] += wz * S2;
          Mr[0] += (wz * z) * S0, Mr[1] += (wz * z) * S1, Mr[2] += (wz * z) * S2;
        }
        const VD a11 = F[0] * Nr[0] + F[1] * Nr[2], a12 = F[0] * Nr[2] + F[1] * Nr[1];
        const VD a21 = F[2] * Nr[0] + F[3] * Nr[2], a22 = F[2] * Nr[2] + F[3] * Nr[1];
        Ncur[0] = iJ * (a11 * F[0] + a12 * F[1]);
        Ncur[1] = iJ * (a21 * F[2] + a22 * F[3]);
        Ncur[2] = iJ * (a11 * F[2] + a12 * F[3]);
      }
      const VD Qr[2] = {Ks * gsh[0], Ks * gsh[1]};
      const VD kq[5] = {kmem_s * A * bb, kmem_s * A * bb, kw_s * bb, kben_s * A * bb,
                        kben_s * A * bb};
      VD Qh[5];
      VD whg = 0.0;
      for (int k = 0; k < 5; ++k) {
        const VD old = batch::load(st(b.hg_force, k) + e0, cnt);
        Qh[k] = old + kq[k] * dqr[k];
        whg += 0.5 * (old + Qh[k]) * dqr[k];
        batch::store(st(b.hg_force, k) + e0, Qh[k], cnt);
      }
      // Drilling springs (see the scalar description in docs/theory.md, "Shells").
      const VD kdr = kdr_share * A;
      VD Md[4], Msum = 0.0;
      for (int I = 0; I < 4; ++I) {
        const VD old = batch::load(st(b.drill_moment, I) + e0, cnt);
        const VD d = (wl[I][2] - spin) * dt;
        Md[I] = old + kdr * d;
        whg += 0.5 * (old + Md[I]) * d;
        batch::store(st(b.drill_moment, I) + e0, Md[I], cnt);
        Msum += Md[I];
      }
      // Work over the step (trapezoid in the reference frame), state stored.
      VD wm = 0.0, wb = 0.0, ws = 0.0;
      for (int k = 0; k < 3; ++k) {
        const double fac = k == 2 ? 2.0 : 1.0;
        const VD Nold = batch::load(st(b.resultant, k) + e0, cnt);
        const VD Mold = batch::load(st(b.moment, k) + e0, cnt);
        const VD Eold = batch::load(st(b.strain, k) + e0, cnt);
        wm += fac * 0.5 * (Nold + Nr[k]) * (Em[k] - Eold);
        wb += fac * 0.5 * (Mold + Mr[k]) * dkr[k];
        batch::store(st(b.strain, k) + e0, Em[k], cnt);
        batch::store(st(b.curvature, k) + e0, kap[k], cnt);
        batch::store(st(b.resultant, k) + e0, Nr[k], cnt);
        batch::store(st(b.moment, k) + e0, Mr[k], cnt);
      }
      for (int k = 0; k < 2; ++k) {
        const VD Qold = batch::load(st(b.shear_force, k) + e0, cnt);
        ws += 0.5 * (Qold + Qr[k]) * dgr[k];
        batch::store(st(b.shear, k) + e0, gsh[k], cnt);
        batch::store(st(b.shear_force, k) + e0, Qr[k], cnt);
      }
      const VD area0 = batch::load(b.area0.data() + e0, cnt);
      VD wint = area0 * wm + A * (wb + ws);
      stdx::where(!f.ok, wint) = 0.0;
      stdx::where(!f.ok, whg) = 0.0;
      w_int += batch::live(wint, cnt);
      w_hg += batch::live(whg, cnt);

      // Current-frame section forces, nodal forces and moments (local, then global).
      const VD c2 = c * c, s2 = s * s, cs = c * s;
      const VD Mc[3] = {c2 * Mr[0] - 2.0 * cs * Mr[2] + s2 * Mr[1],
                        s2 * Mr[0] + 2.0 * cs * Mr[2] + c2 * Mr[1],
                        cs * Mr[0] + (c2 - s2) * Mr[2] - cs * Mr[1]};
      const VD Qc[2] = {c * Qr[0] - s * Qr[1], s * Qr[0] + c * Qr[1]};
      const VD Hc[5] = {c * Qh[0] - s * Qh[1], s * Qh[0] + c * Qh[1], Qh[2], c * Qh[3] - s * Qh[4],
                        s * Qh[3] + c * Qh[4]};
      alignas(64) double fg[4][6][W];  // per node: force xyz, moment xyz; lanes last
      for (int I = 0; I < 4; ++I) {
        const VD b1 = f.B[0][I], b2 = f.B[1][I], g = gam[I];
        const VD fl0 = A * (b1 * Ncur[0] + b2 * Ncur[2]) + g * Hc[0] + 0.5 * b2 * Msum;
        const VD fl1 = A * (b2 * Ncur[1] + b1 * Ncur[2]) + g * Hc[1] - 0.5 * b1 * Msum;
        const VD fl2 = A * (b1 * Qc[0] + b2 * Qc[1]) + g * Hc[2];
        const VD ml0 = A * (-b2 * Mc[1] - b1 * Mc[2] - 0.25 * Qc[1]) + g * Hc[3];
        const VD ml1 = A * (b1 * Mc[0] + b2 * Mc[2] + 0.25 * Qc[0]) + g * Hc[4];
        for (int k = 0; k < 3; ++k) {
          (fl0 * f.e[0][k] + fl1 * f.e[1][k] + fl2 * f.e[2][k])
              .copy_to(fg[I][k], stdx::vector_aligned);
          (ml0 * f.e[0][k] + ml1 * f.e[1][k] + Md[I] * f.e[2][k])
              .copy_to(fg[I][3 + k], stdx::vector_aligned);
        }
      }
      // Stable step at the current shape (squared lengths: two roots per element).
      VD l2min = 1e300, l2max = 0.0;
      for (int I = 0; I < 4; ++I) {
        const int Jn = (I + 1) % 4;
        const VD dx = f.xl[Jn] - f.xl[I], dy = f.yl[Jn] - f.yl[I];
        const VD l2 = dx * dx + dy * dy;
        l2min = stdx::min(l2min, l2), l2max = stdx::max(l2max, l2);
      }
      const VD ms = batch::load(b.mass_scale.data() + e0, cnt);
      VD dte = stdx::sqrt(stdx::min(l2min, A * A / l2max) * ms) * slowness;
      stdx::where(!f.ok, dte) = 0.0;
      alignas(64) double dtb[W];
      dte.copy_to(dtb, stdx::vector_aligned);
      // Scatter, lane by lane (nodes are shared between lanes).
      for (int l = 0; l < cnt; ++l) {
        const std::size_t e = e0 + static_cast<std::size_t>(l);
        if (dtb[l] < step.dt) step = {dtb[l], b.user_id[e], ElementKind::Quad4};
        if (!(dtb[l] > 0)) continue;  // a degenerate shell: no force (the solver stops on its step)
        for (std::size_t I = 0; I < 4; ++I) {
          const auto node = static_cast<std::size_t>(b.conn[I * n + e]);
          double* fi = fo + 3 * node;
          double* mi = mo + 3 * node;
          for (int k = 0; k < 3; ++k) fi[k] -= fg[I][k][l], mi[k] -= fg[I][3 + k][l];
        }
      }
    }
  }
  const double wi = stdx::reduce(w_int), wh = stdx::reduce(w_hg);
  energy.internal += wi + wh;
  energy.stabilisation += wh;
}

void shell4_output_fields(const Shell4Block& b, const double* x, double* shear_angle_deg,
                          double* membrane_force, double* bending_moment, double* fibre_direction) {
  const std::size_t n = b.n;
  std::array<double, 2> fam{0.0, 0.5 * M_PI};
  if (b.section.law) fam = b.section.law->fibre_angles();
  for (std::size_t e = 0; e < n; ++e) {
    double p[4][3];
    gather(b, e, x, p);
    ShellFrame f;
    const double nan = std::nan("");
    if (!shell_frame(p, f)) {
      if (shear_angle_deg) shear_angle_deg[e] = nan;
      if (membrane_force) std::fill(membrane_force + 6 * e, membrane_force + 6 * e + 6, nan);
      if (bending_moment) std::fill(bending_moment + 6 * e, bending_moment + 6 * e + 6, nan);
      if (fibre_direction) std::fill(fibre_direction + 3 * e, fibre_direction + 3 * e + 3, nan);
      continue;
    }
    double F[4];
    inplane_gradient(b, e, f, F);
    const double a1 = b.axes0[e], a2 = b.axes0[n + e];
    double dir[2][2];
    for (int k = 0; k < 2; ++k) {
      const double ck = std::cos(fam[static_cast<std::size_t>(k)]),
                   sk = std::sin(fam[static_cast<std::size_t>(k)]);
      const double A1 = ck * a1 - sk * a2, A2 = sk * a1 + ck * a2;  // family k, reference
      const double d1 = F[0] * A1 + F[1] * A2, d2 = F[2] * A1 + F[3] * A2;
      const double nd = len2(d1, d2);
      dir[k][0] = d1 / nd, dir[k][1] = d2 / nd;
    }
    if (shear_angle_deg) {
      const double cosang = std::clamp(dir[0][0] * dir[1][0] + dir[0][1] * dir[1][1], -1.0, 1.0);
      shear_angle_deg[e] = 90.0 - std::acos(cosang) * 180.0 / M_PI;
    }
    if (fibre_direction)
      for (int k = 0; k < 3; ++k)
        fibre_direction[3 * e + static_cast<std::size_t>(k)] =
            dir[0][0] * f.e[0][k] + dir[0][1] * f.e[1][k];
    // Tensors to global axes: T = sum_ab T_ab e_a e_b (in-plane a, b).
    const double c = b.polar_angle[2 * e], s = b.polar_angle[2 * e + 1];
    auto to_global = [&](const double tc[3], double* out) {
      const double T[2][2] = {{tc[0], tc[2]}, {tc[2], tc[1]}};
      const int ij[6][2] = {{0, 0}, {1, 1}, {2, 2}, {0, 1}, {1, 2}, {0, 2}};
      for (int q = 0; q < 6; ++q) {
        double sum = 0;
        for (int a = 0; a < 2; ++a)
          for (int bq = 0; bq < 2; ++bq) sum += T[a][bq] * f.e[a][ij[q][0]] * f.e[bq][ij[q][1]];
        out[q] = sum;
      }
    };
    if (membrane_force) {
      const double J = F[0] * F[3] - F[1] * F[2];
      const double Nr[3] = {b.resultant[e], b.resultant[n + e], b.resultant[2 * n + e]};
      const double a11 = F[0] * Nr[0] + F[1] * Nr[2], a12 = F[0] * Nr[2] + F[1] * Nr[1];
      const double a21 = F[2] * Nr[0] + F[3] * Nr[2], a22 = F[2] * Nr[2] + F[3] * Nr[1];
      const double Nc[3] = {(a11 * F[0] + a12 * F[1]) / J, (a21 * F[2] + a22 * F[3]) / J,
                            (a11 * F[2] + a12 * F[3]) / J};
      to_global(Nc, membrane_force + 6 * e);
    }
    if (bending_moment) {
      const double Mr[3] = {b.moment[e], b.moment[n + e], b.moment[2 * n + e]};
      double Mc[3];
      to_current(c, s, Mr, Mc);
      to_global(Mc, bending_moment + 6 * e);
    }
  }
}

}  // namespace ncfsim::fem
