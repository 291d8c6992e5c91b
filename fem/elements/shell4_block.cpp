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
constexpr std::size_t kChunk = kShell4Chunk;
// Drilling spring per node: this share of the membrane stiffness times the area (N m/rad).
constexpr double kDrillingRatio = 1e-3;

// One shell's co-rotational frame (a lane of FrameLanes, below).
struct ShellFrame {
  double e[3][3];  // e[k] = axis k (global components)
  double xl[4], yl[4];
  double area;
  double B[2][4];
};

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
[[gnu::always_inline]] inline void gather_lanes3(const Shell4Block& b, std::size_t e0, int cnt,
                                                 const double* x, const double* v, const double* w,
                                                 VD p[4][3], VD vv[4][3], VD ww[4][3]) {
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

[[gnu::always_inline]] inline void frame_lanes(const VD p[4][3], FrameLanes& f) {
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

[[gnu::always_inline]] inline void gradient_lanes(const Shell4Block& b, std::size_t e0, int cnt,
                                                  const FrameLanes& f, VD F[4]) {
  F[0] = F[1] = F[2] = F[3] = 0.0;
  for (std::size_t I = 0; I < 4; ++I) {
    const VD b1 = batch::load(b.b0.data() + I * b.n + e0, cnt),
             b2 = batch::load(b.b0.data() + (4 + I) * b.n + e0, cnt);
    F[0] += f.xl[I] * b1, F[1] += f.xl[I] * b2;
    F[2] += f.yl[I] * b1, F[3] += f.yl[I] * b2;
  }
}

// Lane l of a FrameLanes as one shell's frame; false for a degenerate shell.
bool lane_frame(const FrameLanes& fl, int l, ShellFrame& f) {
  for (int a = 0; a < 3; ++a)
    for (int k = 0; k < 3; ++k) f.e[a][k] = fl.e[a][k][l];
  for (int I = 0; I < 4; ++I) {
    f.xl[I] = fl.xl[I][l], f.yl[I] = fl.yl[I][l];
    f.B[0][I] = fl.B[0][I][l], f.B[1][I] = fl.B[1][I][l];
  }
  f.area = fl.area[l];
  return fl.ok[l];
}

// Calls fn(e, frame, ok) for every shell at positions x; the frames are made in lanes, as the
// force kernel makes them.
template <class Fn>
void for_each_frame(const Shell4Block& b, const double* x, Fn&& fn) {
  for (std::size_t e0 = 0; e0 < b.n; e0 += W) {
    const int cnt = static_cast<int>(std::min<std::size_t>(W, b.n - e0));
    VD p[4][3];
    gather_lanes(b, e0, cnt, x, p);
    FrameLanes fl;
    frame_lanes(p, fl);
    for (int l = 0; l < cnt; ++l) {
      ShellFrame f;
      const bool ok = lane_frame(fl, l, f);
      fn(e0 + static_cast<std::size_t>(l), f, ok);
    }
  }
}

// Stable step of W shells: L / c with L = min(shortest side, area / longest side) (squared
// lengths: two roots per element), c = sqrt(membrane stiffness / areal density); 0 for a
// degenerate lane (the solver stops and names it).
[[gnu::always_inline]] inline VD step_lanes(const FrameLanes& f, const VD& mass_scale,
                                            double slowness) {
  VD l2min = 1e300, l2max = 0.0;
  for (int I = 0; I < 4; ++I) {
    const int Jn = (I + 1) % 4;
    const VD dx = f.xl[Jn] - f.xl[I], dy = f.yl[Jn] - f.yl[I];
    const VD l2 = dx * dx + dy * dy;
    l2min = stdx::min(l2min, l2), l2max = stdx::max(l2max, l2);
  }
  VD dte = stdx::sqrt(stdx::min(l2min, f.area * f.area / l2max) * mass_scale) * slowness;
  stdx::where(!f.ok, dte) = 0.0;
  return dte;
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
  std::fill_n(b.polar_angle.begin(), n, 1.0);  // cos = 1, sin = 0
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

  for_each_frame(b, x_ref, [&](std::size_t e, const ShellFrame& f, bool ok) {
    if (!ok) degenerate(b, e, "in the reference shape");
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
  });
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
  const double slowness = std::sqrt(b.areal_density / b.membrane_stiffness);
  for (std::size_t e0 = 0; e0 < b.n; e0 += W) {
    const int cnt = static_cast<int>(std::min<std::size_t>(W, b.n - e0));
    VD p[4][3];
    gather_lanes(b, e0, cnt, x, p);
    FrameLanes f;
    frame_lanes(p, f);
    batch::store(dt.data() + e0,
                 step_lanes(f, batch::load(b.mass_scale.data() + e0, cnt), slowness), cnt);
  }
}

namespace {

// What the force kernel reads of a block once per call.
struct KernelConstants {
  const MembraneLaw* law;
  double t, Ks, D, dt;
  GaussRule gauss;
  double Q11, Q12, G2;          // plane-stress stiffness (elastic sections)
  double slowness;              // 1 / wave speed
  double kdr_share;             // drilling spring per area
  double kmem_s, kben_s, kw_s;  // hourglass stiffness factors
};

KernelConstants kernel_constants(const Shell4Block& b, double dt) {
  KernelConstants k{};
  k.law = b.section.law;
  k.t = b.section.thickness, k.Ks = b.shear_stiffness, k.D = b.bending_stiffness, k.dt = dt;
  k.gauss = gauss_rule(std::clamp(b.section.integration_points, 1, 5));
  const double E = b.section.youngs_modulus, nu = b.poisson;
  k.Q11 = k.law ? 0.0 : E / (1 - nu * nu), k.Q12 = nu * k.Q11, k.G2 = E / (1 + nu);
  k.slowness = std::sqrt(b.areal_density / b.membrane_stiffness);
  k.kdr_share = kDrillingRatio * b.membrane_stiffness;
  const double hg = b.section.hourglass_stiffness;
  k.kmem_s = hg * b.membrane_stiffness / 8, k.kben_s = hg * k.D / 16;
  k.kw_s = hg * k.Ks * k.t * k.t / 12;
  return k;
}

// In-plane F of W shells with the identity in degenerate lanes.
[[gnu::always_inline]] inline void gradient_or_identity(const Shell4Block& b, std::size_t e0,
                                                        int cnt, const FrameLanes& f, VD F[4]) {
  gradient_lanes(b, e0, cnt, f, F);
  for (int k = 0; k < 4; ++k) stdx::where(!f.ok, F[k]) = (k == 0 || k == 3) ? 1.0 : 0.0;
}

// A membrane-law section: the law's membrane forces Nc [3][kChunk] (current frame) of the chunk
// of m shells from c0, from their deformation gradients at x, all at once.
void law_resultants(Shell4Block& b, const double* x, std::size_t c0, std::size_t m,
                    double (&Nc)[3][kChunk], std::vector<double>& hist) {
  const std::size_t n = b.n;
  alignas(64) double Fc[4][kChunk], axes[4][kChunk];
  for (std::size_t j0 = 0; j0 < m; j0 += W) {
    const int cnt = static_cast<int>(std::min<std::size_t>(W, m - j0));
    VD p[4][3];
    gather_lanes(b, c0 + j0, cnt, x, p);
    FrameLanes f;
    frame_lanes(p, f);
    VD F[4];
    gradient_or_identity(b, c0 + j0, cnt, f, F);
    for (int k = 0; k < 4; ++k) batch::store(&Fc[k][j0], F[k], cnt);
  }
  for (int k = 0; k < 4; ++k)
    std::copy_n(b.axes0.data() + static_cast<std::size_t>(k) * n + c0, m, axes[k]);
  const MembraneLaw* law = b.section.law;
  const auto nh = static_cast<std::size_t>(law->n_history());
  hist.resize(nh * kChunk);
  for (std::size_t r = 0; r < nh; ++r)
    std::copy_n(b.history.data() + r * n + c0, m, hist.data() + r * kChunk);
  MembraneBatch mb;
  mb.n = m, mb.stride = kChunk, mb.F = &Fc[0][0], mb.axes = &axes[0][0];
  mb.resultant = &Nc[0][0], mb.history = hist.data();
  law->update(mb);
  for (std::size_t r = 0; r < nh; ++r)
    std::copy_n(hist.data() + r * kChunk, m, b.history.data() + r * n + c0);
}

// The polar rotation of F (no trigonometry: cos, sin straight from F), stored for the next
// cycle, and its mid-step value (the bisector of the old and new rotations).
struct PolarLanes {
  VD c, s, cm, sm;
};
[[gnu::always_inline]] inline PolarLanes polar_lanes(Shell4Block& b, std::size_t e0, int cnt,
                                                     const VD F[4]) {
  PolarLanes r;
  const VD rr = stdx::sqrt((F[0] + F[3]) * (F[0] + F[3]) + (F[2] - F[1]) * (F[2] - F[1]));
  r.c = (F[0] + F[3]) / rr, r.s = (F[2] - F[1]) / rr;
  double* cos_old = b.polar_angle.data() + e0;
  double* sin_old = b.polar_angle.data() + b.n + e0;
  const VD co = batch::load(cos_old, cnt), so = batch::load(sin_old, cnt);
  VD rm = stdx::sqrt((r.c + co) * (r.c + co) + (r.s + so) * (r.s + so));
  const auto small = rm <= 1e-12;
  stdx::where(small, rm) = 1.0;
  r.cm = (r.c + co) / rm, r.sm = (r.s + so) / rm;
  stdx::where(small, r.cm) = r.c;
  stdx::where(small, r.sm) = r.s;
  batch::store(cos_old, r.c, cnt);
  batch::store(sin_old, r.s, cnt);
  return r;
}

// Increments over the step in the current frame: curvature dk, transverse shear dg, hourglass
// modes dq (x, y, w, wx, wy) with their vectors gam; B.B and the in-plane spin.
struct RateLanes {
  VD dk[3], dg[2], dq[5], gam[4], bb, spin;
};
[[gnu::always_inline]] inline RateLanes rate_lanes(const FrameLanes& f, const VD vl[4][3],
                                                   const VD wl[4][3], double dt) {
  RateLanes r;
  for (VD& d : r.dk) d = 0.0;
  for (VD& d : r.dg) d = 0.0;
  for (VD& d : r.dq) d = 0.0;
  r.bb = 0.0, r.spin = 0.0;
  const VD hx = f.xl[0] - f.xl[1] + f.xl[2] - f.xl[3], hy = f.yl[0] - f.yl[1] + f.yl[2] - f.yl[3];
  for (int I = 0; I < 4; ++I) {
    const VD b1 = f.B[0][I], b2 = f.B[1][I];
    const double h = (I % 2 == 0) ? 1.0 : -1.0;
    r.spin += 0.5 * (b1 * vl[I][1] - b2 * vl[I][0]);
    r.bb += b1 * b1 + b2 * b2;
    r.dk[0] += b1 * wl[I][1];
    r.dk[1] -= b2 * wl[I][0];
    r.dk[2] += 0.5 * (b2 * wl[I][1] - b1 * wl[I][0]);
    r.dg[0] += b1 * vl[I][2] + 0.25 * wl[I][1];
    r.dg[1] += b2 * vl[I][2] - 0.25 * wl[I][0];
    r.gam[I] = 0.25 * (h - hx * b1 - hy * b2);
    r.dq[0] += r.gam[I] * vl[I][0], r.dq[1] += r.gam[I] * vl[I][1], r.dq[2] += r.gam[I] * vl[I][2];
    r.dq[3] += r.gam[I] * wl[I][0], r.dq[4] += r.gam[I] * wl[I][1];
  }
  for (VD& d : r.dk) d *= dt;
  for (VD& d : r.dg) d *= dt;
  for (VD& d : r.dq) d *= dt;
  return r;
}

// Section forces: membrane N (reference, 2nd Piola-Kirchhoff) and Ncur (current frame), moments
// Mr (reference), from the law's current-frame forces Nlaw (membrane-law sections) or the Gauss
// points through the thickness (elastic sections).
[[gnu::always_inline]] inline void section_lanes(const KernelConstants& k, const VD F[4],
                                                 const VD Em[3], const VD kap[3], const VD Nlaw[3],
                                                 VD Nr[3], VD Ncur[3], VD Mr[3]) {
  const VD J = F[0] * F[3] - F[1] * F[2];
  const VD iJ = 1.0 / J;
  if (k.law) {
    for (int c = 0; c < 3; ++c) Ncur[c] = Nlaw[c];
    const VD Fi0 = F[3] * iJ, Fi1 = -F[1] * iJ, Fi2 = -F[2] * iJ, Fi3 = F[0] * iJ;
    const VD a11 = Fi0 * Ncur[0] + Fi1 * Ncur[2], a12 = Fi0 * Ncur[2] + Fi1 * Ncur[1];
    const VD a21 = Fi2 * Ncur[0] + Fi3 * Ncur[2], a22 = Fi2 * Ncur[2] + Fi3 * Ncur[1];
    Nr[0] = J * (a11 * Fi0 + a12 * Fi1);
    Nr[1] = J * (a21 * Fi2 + a22 * Fi3);
    Nr[2] = J * (a11 * Fi2 + a12 * Fi3);
    Mr[0] = k.D * kap[0], Mr[1] = k.D * kap[1], Mr[2] = k.D * kap[2];
    return;
  }
  for (int c = 0; c < 3; ++c) Nr[c] = 0.0, Mr[c] = 0.0;
  for (int q = 0; q < k.gauss.n; ++q) {
    const double z = 0.5 * k.t * k.gauss.xi[q], wz = 0.5 * k.t * k.gauss.w[q];
    const VD e11 = Em[0] + z * kap[0], e22 = Em[1] + z * kap[1], e12 = Em[2] + z * kap[2];
    const VD S0 = k.Q11 * e11 + k.Q12 * e22, S1 = k.Q12 * e11 + k.Q11 * e22, S2 = k.G2 * e12;
    Nr[0] += wz * S0, Nr[1] += wz * S1, Nr[2] += wz * S2;
    Mr[0] += (wz * z) * S0, Mr[1] += (wz * z) * S1, Mr[2] += (wz * z) * S2;
  }
  const VD a11 = F[0] * Nr[0] + F[1] * Nr[2], a12 = F[0] * Nr[2] + F[1] * Nr[1];
  const VD a21 = F[2] * Nr[0] + F[3] * Nr[2], a22 = F[2] * Nr[2] + F[3] * Nr[1];
  Ncur[0] = iJ * (a11 * F[0] + a12 * F[1]);
  Ncur[1] = iJ * (a21 * F[2] + a22 * F[3]);
  Ncur[2] = iJ * (a11 * F[2] + a12 * F[3]);
}

// W shells from e0: strains, section forces, state, work, and their nodal forces and moments
// (subtracted from fo, mo), the step lowered to theirs.
[[gnu::always_inline]] inline void shell_lanes(Shell4Block& b, const KernelConstants& k,
                                               std::size_t e0, int cnt, const double* x,
                                               const double* v, const double* w, const VD Nlaw[3],
                                               double* fo, double* mo, VD& w_int, VD& w_hg,
                                               StableStep& step) {
  const std::size_t n = b.n;
  auto st = [&](std::vector<double>& a, int row) {
    return a.data() + static_cast<std::size_t>(row) * n + e0;
  };
  VD p[4][3], vv[4][3], ww[4][3];
  gather_lanes3(b, e0, cnt, x, v, w, p, vv, ww);
  FrameLanes f;
  frame_lanes(p, f);
  const VD A = f.area;
  VD F[4];
  gradient_or_identity(b, e0, cnt, f, F);
  VD vl[4][3], wl[4][3];  // local velocities
  for (int I = 0; I < 4; ++I)
    for (int c = 0; c < 3; ++c) {
      vl[I][c] = vv[I][0] * f.e[c][0] + vv[I][1] * f.e[c][1] + vv[I][2] * f.e[c][2];
      wl[I][c] = ww[I][0] * f.e[c][0] + ww[I][1] * f.e[c][1] + ww[I][2] * f.e[c][2];
    }
  const PolarLanes R = polar_lanes(b, e0, cnt, F);
  const RateLanes r = rate_lanes(f, vl, wl, k.dt);
  // ... to the reference frame (R^T at mid-step).
  const VD cm = R.cm, sm = R.sm, cm2 = cm * cm, sm2 = sm * sm, csm = cm * sm;
  const VD dkr[3] = {cm2 * r.dk[0] + 2.0 * csm * r.dk[2] + sm2 * r.dk[1],
                     sm2 * r.dk[0] - 2.0 * csm * r.dk[2] + cm2 * r.dk[1],
                     -csm * r.dk[0] + (cm2 - sm2) * r.dk[2] + csm * r.dk[1]};
  const VD dgr[2] = {cm * r.dg[0] + sm * r.dg[1], -sm * r.dg[0] + cm * r.dg[1]};
  const VD dqr[5] = {cm * r.dq[0] + sm * r.dq[1], -sm * r.dq[0] + cm * r.dq[1], r.dq[2],
                     cm * r.dq[3] + sm * r.dq[4], -sm * r.dq[3] + cm * r.dq[4]};
  VD kap[3], gsh[2];
  for (int c = 0; c < 3; ++c) kap[c] = batch::load(st(b.curvature, c), cnt) + dkr[c];
  for (int c = 0; c < 2; ++c) gsh[c] = batch::load(st(b.shear, c), cnt) + dgr[c];
  const VD Em[3] = {0.5 * (F[0] * F[0] + F[2] * F[2] - 1.0),
                    0.5 * (F[1] * F[1] + F[3] * F[3] - 1.0), 0.5 * (F[0] * F[1] + F[2] * F[3])};
  VD Nr[3], Ncur[3], Mr[3];
  section_lanes(k, F, Em, kap, Nlaw, Nr, Ncur, Mr);
  const VD Qr[2] = {k.Ks * gsh[0], k.Ks * gsh[1]};
  const VD kq[5] = {k.kmem_s * A * r.bb, k.kmem_s * A * r.bb, k.kw_s * r.bb, k.kben_s * A * r.bb,
                    k.kben_s * A * r.bb};
  VD Qh[5];
  VD whg = 0.0;
  for (int c = 0; c < 5; ++c) {
    const VD old = batch::load(st(b.hg_force, c), cnt);
    Qh[c] = old + kq[c] * dqr[c];
    whg += 0.5 * (old + Qh[c]) * dqr[c];
    batch::store(st(b.hg_force, c), Qh[c], cnt);
  }
  // Drilling springs (docs/theory.md, "Shells").
  const VD kdr = k.kdr_share * A;
  VD Md[4], Msum = 0.0;
  for (int I = 0; I < 4; ++I) {
    const VD old = batch::load(st(b.drill_moment, I), cnt);
    const VD d = (wl[I][2] - r.spin) * k.dt;
    Md[I] = old + kdr * d;
    whg += 0.5 * (old + Md[I]) * d;
    batch::store(st(b.drill_moment, I), Md[I], cnt);
    Msum += Md[I];
  }
  // Work over the step (trapezoid in the reference frame), state stored.
  VD wm = 0.0, wb = 0.0, ws = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double fac = c == 2 ? 2.0 : 1.0;
    const VD Nold = batch::load(st(b.resultant, c), cnt);
    const VD Mold = batch::load(st(b.moment, c), cnt);
    const VD Eold = batch::load(st(b.strain, c), cnt);
    wm += fac * 0.5 * (Nold + Nr[c]) * (Em[c] - Eold);
    wb += fac * 0.5 * (Mold + Mr[c]) * dkr[c];
    batch::store(st(b.strain, c), Em[c], cnt);
    batch::store(st(b.curvature, c), kap[c], cnt);
    batch::store(st(b.resultant, c), Nr[c], cnt);
    batch::store(st(b.moment, c), Mr[c], cnt);
  }
  for (int c = 0; c < 2; ++c) {
    const VD Qold = batch::load(st(b.shear_force, c), cnt);
    ws += 0.5 * (Qold + Qr[c]) * dgr[c];
    batch::store(st(b.shear, c), gsh[c], cnt);
    batch::store(st(b.shear_force, c), Qr[c], cnt);
  }
  VD wint = batch::load(b.area0.data() + e0, cnt) * wm + A * (wb + ws);
  stdx::where(!f.ok, wint) = 0.0;
  stdx::where(!f.ok, whg) = 0.0;
  w_int += batch::live(wint, cnt);
  w_hg += batch::live(whg, cnt);

  // Current-frame section forces, nodal forces and moments (local, then global).
  const VD c = R.c, s = R.s, c2 = c * c, s2 = s * s, cs = c * s;
  const VD Mc[3] = {c2 * Mr[0] - 2.0 * cs * Mr[2] + s2 * Mr[1],
                    s2 * Mr[0] + 2.0 * cs * Mr[2] + c2 * Mr[1],
                    cs * Mr[0] + (c2 - s2) * Mr[2] - cs * Mr[1]};
  const VD Qc[2] = {c * Qr[0] - s * Qr[1], s * Qr[0] + c * Qr[1]};
  const VD Hc[5] = {c * Qh[0] - s * Qh[1], s * Qh[0] + c * Qh[1], Qh[2], c * Qh[3] - s * Qh[4],
                    s * Qh[3] + c * Qh[4]};
  alignas(64) double fg[4][6][W];  // per node: force xyz, moment xyz; lanes last
  for (int I = 0; I < 4; ++I) {
    const VD b1 = f.B[0][I], b2 = f.B[1][I], g = r.gam[I];
    const VD fl0 = A * (b1 * Ncur[0] + b2 * Ncur[2]) + g * Hc[0] + 0.5 * b2 * Msum;
    const VD fl1 = A * (b2 * Ncur[1] + b1 * Ncur[2]) + g * Hc[1] - 0.5 * b1 * Msum;
    const VD fl2 = A * (b1 * Qc[0] + b2 * Qc[1]) + g * Hc[2];
    const VD ml0 = A * (-b2 * Mc[1] - b1 * Mc[2] - 0.25 * Qc[1]) + g * Hc[3];
    const VD ml1 = A * (b1 * Mc[0] + b2 * Mc[2] + 0.25 * Qc[0]) + g * Hc[4];
    for (int q = 0; q < 3; ++q) {
      (fl0 * f.e[0][q] + fl1 * f.e[1][q] + fl2 * f.e[2][q]).copy_to(fg[I][q], stdx::vector_aligned);
      (ml0 * f.e[0][q] + ml1 * f.e[1][q] + Md[I] * f.e[2][q])
          .copy_to(fg[I][3 + q], stdx::vector_aligned);
    }
  }
  alignas(64) double dtb[W];
  step_lanes(f, batch::load(b.mass_scale.data() + e0, cnt), k.slowness)
      .copy_to(dtb, stdx::vector_aligned);
  // Scatter, lane by lane (nodes are shared between lanes).
  for (int l = 0; l < cnt; ++l) {
    const std::size_t e = e0 + static_cast<std::size_t>(l);
    if (dtb[l] < step.dt) step = {dtb[l], b.user_id[e], ElementKind::Quad4};
    if (!(dtb[l] > 0)) continue;  // a degenerate shell: no force (the solver stops on its step)
    for (std::size_t I = 0; I < 4; ++I) {
      const auto node = static_cast<std::size_t>(b.conn[I * n + e]);
      double* fi = fo + 3 * node;
      double* mi = mo + 3 * node;
      for (int q = 0; q < 3; ++q) fi[q] -= fg[I][q][l], mi[q] -= fg[I][3 + q][l];
    }
  }
}

}  // namespace

void shell4_internal_forces(Shell4Block& b, const double* x, const double* v, const double* w,
                            double dt, double* fo, double* mo, ElementEnergyIncrement& energy,
                            StableStep& step) {
  const KernelConstants k = kernel_constants(b, dt);
  VD w_int = 0.0, w_hg = 0.0;
  // Membrane-law sections: the law sees a chunk's deformation gradients at once.
  alignas(64) double Nc[3][kChunk];
  std::vector<double> hist;
  const std::size_t e_end = std::min(b.n, b.range_end);
  for (std::size_t c0 = b.range_begin; c0 < e_end; c0 += kChunk) {
    const std::size_t m = std::min(kChunk, e_end - c0);
    if (k.law) law_resultants(b, x, c0, m, Nc, hist);
    for (std::size_t j0 = 0; j0 < m; j0 += W) {
      const int cnt = static_cast<int>(std::min<std::size_t>(W, m - j0));
      VD Nlaw[3];
      if (k.law)
        for (int c = 0; c < 3; ++c) Nlaw[c] = batch::load(&Nc[c][j0], cnt);
      shell_lanes(b, k, c0 + j0, cnt, x, v, w, Nlaw, fo, mo, w_int, w_hg, step);
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
  for_each_frame(b, x, [&](std::size_t e, const ShellFrame& f, bool ok) {
    const double nan = std::nan("");
    if (!ok) {
      if (shear_angle_deg) shear_angle_deg[e] = nan;
      if (membrane_force) std::fill(membrane_force + 6 * e, membrane_force + 6 * e + 6, nan);
      if (bending_moment) std::fill(bending_moment + 6 * e, bending_moment + 6 * e + 6, nan);
      if (fibre_direction) std::fill(fibre_direction + 3 * e, fibre_direction + 3 * e + 3, nan);
      return;
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
    const double c = b.polar_angle[e], s = b.polar_angle[n + e];
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
  });
}

}  // namespace ncfsim::fem
