// GCC 12 reports false maybe-uninitialized warnings inside its own AVX-512 intrinsics (the
// undefined pass-through operand of the masked sqrt) when it inlines std::experimental::simd.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include "fem/elements/hex8_block.hpp"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "fem/elements/element_kind.hpp"
#include "fem/elements/hex8_basis.hpp"
#include "fem/elements/simd_batch.hpp"
#include "fem/errors.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::fem {
namespace stdx = std::experimental;
namespace {

constexpr int CH = static_cast<int>(kHex8Chunk);  // elements per chunk: the chunk scratch (~20 KB) stays in L1

constexpr const auto& S = kHex8Sign;

using Vec3 = V3;  // the scalar paths (set-up, steps, checks); the kernel has its SIMD V3v below

// Geometry of one element from its 8 nodes: basis vectors a_k (k=1..7), volume derivative vectors
// d_k (k=1..6) with b_I = sum_k S[k][I] d_k / V, and the volume.
struct HexGeometry {
  Vec3 a[8];
  Vec3 d[7];
  double V;
};

inline void hex_geometry(const Vec3 x[8], HexGeometry& g) {
  for (int k = 1; k < 8; ++k) {
    Vec3 s{0, 0, 0};
    for (int I = 0; I < 8; ++I) s = s + S[k][I] * x[I];
    g.a[k] = 0.125 * s;
  }
  const Vec3* a = g.a;
  constexpr double third = 1.0 / 3.0;
  g.d[1] = cross(a[2], a[3]) + third * cross(a[6], a[5]);
  g.d[2] = cross(a[3], a[1]) + third * cross(a[4], a[6]);
  g.d[3] = cross(a[1], a[2]) + third * cross(a[5], a[4]);
  g.d[4] = third * (cross(a[6], a[2]) + cross(a[3], a[5]));
  g.d[5] = third * (cross(a[4], a[3]) + cross(a[1], a[6]));
  g.d[6] = third * (cross(a[2], a[4]) + cross(a[5], a[1]));
  double s = 0;
  for (int k = 1; k < 7; ++k) s += dot(a[k], g.d[k]);
  g.V = 8.0 * third * s;
}

// Element frame: e1 along the xi edge direction, e2 in the xi-eta plane, e3 normal; half lengths.
inline void hex_frame(const HexGeometry& g, double R[9], double l[3]) {
  const Vec3 a1 = g.a[1], a2 = g.a[2], a3 = g.a[3];
  const double n1 = std::sqrt(dot(a1, a1));
  const Vec3 e1 = (1.0 / n1) * a1;
  const Vec3 w = a2 - dot(a2, e1) * e1;
  const double n2 = std::sqrt(dot(w, w));
  const Vec3 e2 = (1.0 / n2) * w;
  const Vec3 e3 = cross(e1, e2);
  R[0] = e1.x, R[1] = e2.x, R[2] = e3.x;
  R[3] = e1.y, R[4] = e2.y, R[5] = e3.y;
  R[6] = e1.z, R[7] = e2.z, R[8] = e3.z;
  l[0] = n1;
  l[1] = n2;
  l[2] = std::abs(dot(a3, e3));
}

inline double max_face_area_sq(const Vec3 x[8]) {
  double m = 0;
  for (const auto& face : kHex8Faces) {
    const auto& f = face.corner;
    const Vec3 c = cross(x[f[2]] - x[f[0]], x[f[3]] - x[f[1]]);
    m = std::max(m, 0.25 * dot(c, c));
  }
  return m;
}

[[noreturn]] void throw_bad_volume(const Hex8Block& b, std::size_t e, const Vec3 x[8], double V) {
  Vec3 c{0, 0, 0};
  for (int I = 0; I < 8; ++I) c = c + 0.125 * x[I];
  std::ostringstream os;
  os << "hexahedron " << b.user_id[e] << " (part " << b.part << ") has "
     << (std::isfinite(V) ? "a non-positive volume " : "a non-finite volume ") << V << " m^3 at ("
     << c.x << ", " << c.y << ", " << c.z << ") m";
  throw NumericalError(os.str());
}

inline void gather(const Hex8Block& b, std::size_t e, const double* x, Vec3 out[8]) {
  for (int I = 0; I < 8; ++I) {
    const std::size_t node = static_cast<std::size_t>(b.conn[I * b.n + e]);
    out[I] = {x[3 * node], x[3 * node + 1], x[3 * node + 2]};
  }
}

// Modulus that bounds the highest frequency of the uniform-strain hexahedron: for a box of
// smallest edge h, omega_max^2 <= 4 M / (rho h^2) with M the larger of the largest eigenvalue of
// the normal block of C and twice the largest shear modulus (Flanagan-Belytschko 1984). For an
// isotropic solid M = 3K = E/(1-2nu), above the p-wave modulus by (1+nu)/(1-nu): the plain
// V/A_max over the dilatational speed overestimates the critical step of a cube by ~27 % (nu=0.3).
double uniform_strain_modulus(const Voigt6x6& C) {
  Eigen::Matrix3d Cn;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) Cn(i, j) = 0.5 * (C[6 * i + j] + C[6 * j + i]);
  const double normal = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(Cn, Eigen::EigenvaluesOnly)
                            .eigenvalues()
                            .maxCoeff();
  const double shear = 2.0 * std::max({C[6 * 3 + 3], C[6 * 4 + 4], C[6 * 5 + 5]});
  return std::max(normal, shear);
}

// Largest eigenvalue of C G, G the 6x6 Gram matrix of the rows of the uniform-strain operator
// (Voigt 11 22 33 12 23 13, engineering shear) of nodal gradients whose Gram matrix is D = sum_I
// b_I b_I^T (row-major 3x3, in the axes of C), e.g. <eps11, gamma12> = D12: the stiffness of the
// strain modes per unit mass is 8/rho times it. Computed as that of G^1/2 C G^1/2.
double strain_operator_eigenvalue(const Voigt6x6& Cv, const double D[9]) {
  const double D11 = D[0], D22 = D[4], D33 = D[8], D12 = D[1], D23 = D[5], D13 = D[2];
  Eigen::Matrix<double, 6, 6> G = Eigen::Matrix<double, 6, 6>::Zero(), C;
  auto set = [&](int a, int b, double v) { G(a, b) = G(b, a) = v; };
  set(0, 0, D11), set(1, 1, D22), set(2, 2, D33);
  set(3, 3, D11 + D22), set(4, 4, D22 + D33), set(5, 5, D11 + D33);
  set(0, 3, D12), set(0, 5, D13), set(1, 3, D12), set(1, 4, D23), set(2, 4, D23), set(2, 5, D13);
  set(3, 4, D13), set(3, 5, D23), set(4, 5, D12);
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b) C(a, b) = 0.5 * (Cv[6 * a + b] + Cv[6 * b + a]);
  const Eigen::Matrix<double, 6, 6> Gh =
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(G).operatorSqrt();
  const Eigen::Matrix<double, 6, 6> A = Gh * C * Gh;
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>>(A, Eigen::EigenvaluesOnly)
      .eigenvalues()
      .maxCoeff();
}

// Largest eigenvalue of the right Cauchy-Green tensor, bounded by its largest Gershgorin row.
inline double cauchy_green_bound(double C11, double C22, double C33, double C12, double C23,
                                 double C13) {
  const double a = std::abs(C12), b = std::abs(C23), c = std::abs(C13);
  return std::max({C11 + a + c, C22 + a + b, C33 + b + c});
}

// Isotropic stiffness (within round-off): the directional bound is not used for it. On a cube it
// equals the Flanagan-Belytschko bound anyway, and the margin that bound leaves on thin isotropic
// elements is what penalty contacts up to penalty_scale 0.5 rely on (fem/contact/README.md).
bool is_isotropic(const Voigt6x6& C) {
  const double c11 = C[0], c12 = C[1], tol = 1e-9 * std::abs(c11);
  auto eq = [&](double a, double b) { return std::abs(a - b) <= tol; };
  bool iso = eq(C[7], c11) && eq(C[14], c11) && eq(C[2], c12) && eq(C[8], c12);
  for (int k = 3; k < 6; ++k) iso = iso && eq(C[6 * k + k], 0.5 * (c11 - c12));
  for (int a = 0; a < 6; ++a)
    for (int b = 0; b < 6; ++b) {
      if (a == b || (a < 3 && b < 3)) continue;
      iso = iso && eq(C[6 * a + b], 0.0);
    }
  return iso;
}

// Step of the directional bound in the current shape (see Hex8Block::step_modulus).
inline double directional_step(double rho, double cg_bound, double step_modulus, double lc0,
                               double lc) {
  return std::min(lc0, lc) * std::sqrt(rho / (std::max(cg_bound, 1.0) * step_modulus));
}

}  // namespace

std::array<double, 3> hex8_axis_lengths(const double (&x)[8][3], const std::array<double, 9>& M) {
  // Face area vectors (half the cross product of the diagonals); the projection of the element
  // on the plane normal to an axis has half the sum of their |components| along it.
  double V = 0;
  {
    Vec3 xe[8];
    for (int I = 0; I < 8; ++I) xe[I] = {x[I][0], x[I][1], x[I][2]};
    HexGeometry g;
    hex_geometry(xe, g);
    V = g.V;
  }
  double projected[3] = {0, 0, 0};
  for (const auto& f : kHex8Faces) {
    const auto& c = f.corner;
    const Vec3 d1{x[c[2]][0] - x[c[0]][0], x[c[2]][1] - x[c[0]][1], x[c[2]][2] - x[c[0]][2]};
    const Vec3 d2{x[c[3]][0] - x[c[1]][0], x[c[3]][1] - x[c[1]][1], x[c[3]][2] - x[c[1]][2]};
    const Vec3 A = 0.5 * cross(d1, d2);
    for (std::size_t k = 0; k < 3; ++k)
      projected[k] += 0.5 * std::abs(A.x * M[k] + A.y * M[3 + k] + A.z * M[6 + k]);
  }
  std::array<double, 3> L{};
  for (std::size_t k = 0; k < 3; ++k) L[k] = projected[k] > 0 ? V / projected[k] : 0.0;
  return L;
}

// Largest hourglass vector of a reference shape, relative to its smallest half edge, that still
// counts as a parallelepiped for the directional step bound.
constexpr double kParallelepipedTolerance = 0.1;

void hex8_initialise(Hex8Block& b, const double* x_ref, const std::array<double, 9>& part_axes,
                     const double* element_axes) {
  const std::size_t n = b.n;
  b.axis_length.assign(3 * n, 0.0);
  b.stress.assign(6 * n, 0.0);
  b.strain.assign(6 * n, 0.0);
  b.history.assign(static_cast<std::size_t>(b.material->n_history()) * n, 0.0);
  b.hg_force.assign(12 * n, 0.0);
  b.hg_viscous.assign(12 * n, 0.0);
  b.mat_axes.assign(9 * n, 0.0);
  b.jac_inv0.assign(9 * n, 0.0);
  b.jac_inv0_axes.assign(9 * n, 0.0);
  b.hg_moduli.assign(6 * n, 0.0);
  b.volume.assign(n, 0.0);
  b.volume0.assign(n, 0.0);
  b.density.assign(n, b.material->density());
  b.p_modulus = uniform_strain_modulus(b.material->stable_step_stiffness());
  const Voigt6x6 C_step = b.material->stable_step_stiffness();
  const bool directional = !is_isotropic(C_step);
  b.step_modulus.assign(directional ? n : 0, 0.0);
  b.step_length0.assign(directional ? n : 0, 0.0);
  const Voigt6x6 C = b.material->bending_stiffness();
  std::array<double, 9> last_T{};
  std::array<double, 6> last_moduli{};
  bool have_last = false;
  std::array<double, 9> M = part_axes;
  for (std::size_t e = 0; e < n; ++e) {
    if (element_axes)
      for (int k = 0; k < 9; ++k) M[static_cast<std::size_t>(k)] = element_axes[k * n + e];
    Vec3 xe[8];
    gather(b, e, x_ref, xe);
    HexGeometry g;
    hex_geometry(xe, g);
    if (!(g.V > 0)) throw_bad_volume(b, e, xe, g.V);
    b.volume[e] = g.V;
    {
      double xr[8][3];
      for (int I = 0; I < 8; ++I) xr[I][0] = xe[I].x, xr[I][1] = xe[I].y, xr[I][2] = xe[I].z;
      const auto L = hex8_axis_lengths(xr, M);
      for (int c = 0; c < 3; ++c)
        b.axis_length[static_cast<std::size_t>(c) * n + e] = L[static_cast<std::size_t>(c)];
    }
    double R[9], l[3];
    hex_frame(g, R, l);
    // Inverse of the centre Jacobian [a1 a2 a3]: F = J J_ref^{-1} exactly for homogeneous motion.
    const Vec3 c0 = cross(g.a[2], g.a[3]), c1 = cross(g.a[3], g.a[1]), c2 = cross(g.a[1], g.a[2]);
    const double detJ = dot(g.a[1], c0);
    const double Ji[9] = {c0.x / detJ, c0.y / detJ, c0.z / detJ, c1.x / detJ, c1.y / detJ,
                          c1.z / detJ, c2.x / detJ, c2.y / detJ, c2.z / detJ};
    for (int k = 0; k < 9; ++k) b.jac_inv0[k * n + e] = Ji[k];
    for (int k = 0; k < 9; ++k) b.mat_axes[k * n + e] = M[k];
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c)
        b.jac_inv0_axes[(3 * r + c) * n + e] =
            Ji[3 * r] * M[c] + Ji[3 * r + 1] * M[3 + c] + Ji[3 * r + 2] * M[6 + c];
    b.volume0[e] = g.V;
    if (directional) {
      // Gram matrix of the reference nodal gradients, D = 8/V^2 sum_k d_k d_k^T, in the material
      // axes (M^T D M), for the directional step bound.
      double Dg[9] = {};
      for (int k = 1; k < 7; ++k) {
        const double dk[3] = {g.d[k].x, g.d[k].y, g.d[k].z};
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c) Dg[3 * r + c] += 8.0 / (g.V * g.V) * dk[r] * dk[c];
      }
      double Dm[9] = {};
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          for (int i = 0; i < 3; ++i)
            for (int j = 0; j < 3; ++j)
              Dm[3 * r + c] += M[3 * i + r] * Dg[3 * i + j] * M[3 * j + c];
      const double lc0 = g.V / std::sqrt(max_face_area_sq(xe));
      b.step_length0[e] = lc0;
      b.step_modulus[e] = 2.0 * strain_operator_eigenvalue(C_step, Dm) * lc0 * lc0;
      // The bound is exact for a parallelepiped only: a reference shape with hourglass content
      // (tapered, warped: a formed part's tows at a fillet) takes the V / A_max bound, which a
      // stiff fibre direction otherwise exceeded (an impregnated formed hemisphere blew up at
      // rest).
      double half_min = 1e300, hg_max = 0;
      for (int k = 1; k < 4; ++k) half_min = std::min(half_min, std::sqrt(dot(g.a[k], g.a[k])));
      for (int k = 4; k < 8; ++k) hg_max = std::max(hg_max, std::sqrt(dot(g.a[k], g.a[k])));
      if (hg_max > kParallelepipedTolerance * half_min) b.step_modulus[e] = 0.0;
    }
    std::array<double, 9> T{};  // element axes in the material frame: T = M^T R
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        double s = 0;
        for (int k = 0; k < 3; ++k) s += M[3 * k + i] * R[3 * k + j];
        T[3 * i + j] = std::abs(s) < 1e-14 ? 0.0 : s;
      }
    if (!have_last || T != last_T) {
      last_moduli = directional_moduli(C, T);
      last_T = T;
      have_last = true;
    }
    for (int k = 0; k < 6; ++k) b.hg_moduli[k * n + e] = last_moduli[k];
  }
}

void hex8_lumped_mass(const Hex8Block& b, double* mass) {
  for (std::size_t e = 0; e < b.n; ++e) {
    const double m = b.density[e] * b.volume[e] / 8.0;
    for (int I = 0; I < 8; ++I) {
      const std::size_t node = static_cast<std::size_t>(b.conn[I * b.n + e]);
      for (int c = 0; c < 3; ++c) mass[3 * node + c] += m;
    }
  }
}

void hex8_element_steps(const Hex8Block& b, const double* x, std::vector<double>& dt,
                        std::vector<double>* corner_jacobian, bool in_range, double min_density) {
  // The three edges leaving each corner, right-handed (bottom face 0-3, top 4-7 above them).
  constexpr int kEdges[8][3] = {{1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7},
                                {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}};
  dt.resize(b.n);
  if (corner_jacobian) corner_jacobian->resize(b.n);
  const std::size_t e_begin = in_range ? std::min(b.n, b.range_begin) : 0;
  const std::size_t e_end = in_range ? std::min(b.n, b.range_end) : b.n;
  for (std::size_t e = 0; e < b.n; ++e) {
    if ((b.n_eroded && b.eroded[e]) || e < e_begin || e >= e_end || b.density[e] < min_density) {
      dt[e] = 1e300;
      if (corner_jacobian) (*corner_jacobian)[e] = 1.0;
      continue;
    }
    Vec3 xe[8];
    gather(b, e, x, xe);
    HexGeometry g;
    hex_geometry(xe, g);
    const double lc = g.V / std::sqrt(max_face_area_sq(xe));
    dt[e] = lc / std::sqrt(b.p_modulus / b.density[e]);
    if (!b.step_modulus.empty() && b.step_modulus[e] > 0) {
      // F M = J jac_inv0_axes with J = [a1 a2 a3]; Cg = (F M)^T (F M) in the material axes.
      double FM[9];
      const Vec3 col[3] = {g.a[1], g.a[2], g.a[3]};
      for (int c = 0; c < 3; ++c) {
        const double j0 = b.jac_inv0_axes[(0 + c) * b.n + e],
                     j1 = b.jac_inv0_axes[(3 + c) * b.n + e],
                     j2 = b.jac_inv0_axes[(6 + c) * b.n + e];
        FM[c] = col[0].x * j0 + col[1].x * j1 + col[2].x * j2;
        FM[3 + c] = col[0].y * j0 + col[1].y * j1 + col[2].y * j2;
        FM[6 + c] = col[0].z * j0 + col[1].z * j1 + col[2].z * j2;
      }
      auto cg = [&](int p, int q) {
        return FM[p] * FM[q] + FM[3 + p] * FM[3 + q] + FM[6 + p] * FM[6 + q];
      };
      const double s =
          cauchy_green_bound(cg(0, 0), cg(1, 1), cg(2, 2), cg(0, 1), cg(1, 2), cg(0, 2));
      dt[e] = std::max(dt[e],
                       directional_step(b.density[e], s, b.step_modulus[e], b.step_length0[e], lc));
    }
    if (!corner_jacobian) continue;
    double j = 1e300;
    for (int c = 0; c < 8; ++c) {
      const Vec3 o = xe[c];
      j = std::min(j, dot(cross(xe[kEdges[c][0]] - o, xe[kEdges[c][1]] - o), xe[kEdges[c][2]] - o));
    }
    (*corner_jacobian)[e] = j / b.volume0[e];
  }
}

void hex8_element_force(const Hex8Block& b, std::size_t e, const double* x, const double* v,
                        double f[24]) {
  // A one-element copy of the block on local nodes 0..7, through the batched kernel.
  Hex8Block one;
  one.part = b.part;
  one.material = b.material;
  one.n = 1;
  one.hourglass_stiffness = b.hourglass_stiffness;
  one.hourglass_viscosity = b.hourglass_viscosity;
  one.p_modulus = b.p_modulus;
  if (!b.step_modulus.empty()) {
    one.step_modulus = {b.step_modulus[e]};
    one.step_length0 = {b.step_length0[e]};
  }
  auto take = [&](const std::vector<double>& from, std::vector<double>& to) {
    const std::size_t rows = b.n ? from.size() / b.n : 0;
    to.resize(rows);
    for (std::size_t r = 0; r < rows; ++r) to[r] = from[r * b.n + e];
  };
  take(b.stress, one.stress);
  take(b.strain, one.strain);
  take(b.history, one.history);
  take(b.hg_force, one.hg_force);
  take(b.hg_viscous, one.hg_viscous);
  take(b.mat_axes, one.mat_axes);
  take(b.jac_inv0, one.jac_inv0);
  take(b.jac_inv0_axes, one.jac_inv0_axes);
  take(b.hg_moduli, one.hg_moduli);
  take(b.volume, one.volume);
  take(b.volume0, one.volume0);
  take(b.density, one.density);
  one.user_id = {b.user_id[e]};
  one.conn = {0, 1, 2, 3, 4, 5, 6, 7};
  double xl[24], vl[24];
  for (int I = 0; I < 8; ++I) {
    const auto node = static_cast<std::size_t>(b.conn[static_cast<std::size_t>(I) * b.n + e]);
    for (int c = 0; c < 3; ++c) xl[3 * I + c] = x[3 * node + c], vl[3 * I + c] = v[3 * node + c];
  }
  std::fill(f, f + 24, 0.0);
  ElementEnergyIncrement inc;
  StableStep st;
  hex8_internal_forces(one, xl, vl, 0.0, f, inc, st);
  for (int k = 0; k < 24; ++k) f[k] = -f[k];  // the kernel subtracts internal forces
}

double hex8_erode(Hex8Block& b, std::size_t e) {
  const std::size_t n = b.n;
  if (b.eroded.empty()) b.eroded.assign(n, 0);
  if (b.eroded[e]) return 0.0;
  b.eroded[e] = 1;
  ++b.n_eroded;
  double w = 0;
  for (int c = 0; c < 6; ++c) w += b.stress[c * n + e] * b.strain[c * n + e];
  for (int c = 0; c < 6; ++c) b.stress[c * n + e] = 0.0, b.strain[c * n + e] = 0.0;
  for (int k = 0; k < 12; ++k) b.hg_force[k * n + e] = 0.0, b.hg_viscous[k * n + e] = 0.0;
  return 0.5 * w * b.volume0[e];
}

StableStep hex8_stable_step(const Hex8Block& b, const double* x) {
  std::vector<double> dt;
  hex8_element_steps(b, x, dt);
  StableStep s;
  for (std::size_t e = 0; e < b.n; ++e)
    if (dt[e] < s.dt) s = {dt[e], b.user_id[e], ElementKind::Hex8};
  return s;
}

namespace {

// Batched kernel: W elements at a time in the lanes of one SIMD register (8 with AVX-512, 4 with
// AVX2), every quantity of the per-element algorithm a vector over those elements. The state
// arrays are [component][n], so element e..e+W of a component is one contiguous load or store;
// only the node gathers and the force scatter are per lane.
using batch::load;
using batch::load_a;
using batch::store;
using batch::store_a;
using batch::VD;
using batch::W;
static_assert(CH % W == 0, "chunk must hold whole SIMD batches");

struct V3v {
  VD x, y, z;
};
inline V3v operator+(const V3v& a, const V3v& b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3v operator-(const V3v& a, const V3v& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3v operator*(const VD& s, const V3v& a) { return {s * a.x, s * a.y, s * a.z}; }
inline VD dot(const V3v& a, const V3v& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3v cross(const V3v& a, const V3v& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

// The 7 trilinear basis combinations c_k = sum_I S[k][I] u_I of 8 nodal values, k = 1..7, by a
// butterfly (23 additions instead of 49). Bottom face nodes 0-3, top face 4-7 above them.
inline void basis_transform(const VD u[8], VD c[8]) {
  VD p[4], m[4];
  for (int i = 0; i < 4; ++i) p[i] = u[i + 4] + u[i], m[i] = u[i + 4] - u[i];
  // face corners 0 (-,-), 1 (+,-), 2 (+,+), 3 (-,+) in (xi, eta)
  const VD pu = p[0] + p[2], pw = p[1] + p[3], pr = p[2] - p[0], pt = p[1] - p[3];
  const VD mu = m[0] + m[2], mw = m[1] + m[3], mr = m[2] - m[0], mt = m[1] - m[3];
  c[1] = pr + pt;  // xi
  c[2] = pr - pt;  // eta
  c[6] = pu - pw;  // xi eta
  c[3] = mu + mw;  // zeta
  c[5] = mr + mt;  // zeta xi
  c[4] = mr - mt;  // eta zeta
  c[7] = mu - mw;  // xi eta zeta
}

// Transpose: nodal values f_I = sum_{k=1..7} S[k][I] w_k.
inline void basis_transpose(const VD w[8], VD f[8]) {
  // zeta-even part from w1 (xi), w2 (eta), w6 (xi eta); zeta-odd from w3, w5, w4, w7.
  const VD pc = w[1] + w[2], pd = w[1] - w[2];
  const VD P0 = w[6] - pc, P2 = w[6] + pc, P1 = pd - w[6], P3 = -(w[6] + pd);
  const VD mA = w[3] + w[7], mB = w[3] - w[7], mc = w[5] + w[4], md = w[5] - w[4];
  const VD M0 = mA - mc, M2 = mA + mc, M1 = mB + md, M3 = mB - md;
  f[0] = P0 - M0, f[1] = P1 - M1, f[2] = P2 - M2, f[3] = P3 - M3;
  f[4] = P0 + M0, f[5] = P1 + M1, f[6] = P2 + M2, f[7] = P3 + M3;
}

// M = sum_{k=1..6} u_k (x) w_k, row-major (a velocity gradient times V/8).
inline void sum_outer(const V3v* u, const V3v* w, VD (&M)[9]) {
  M[0] = u[1].x * w[1].x, M[1] = u[1].x * w[1].y, M[2] = u[1].x * w[1].z;
  M[3] = u[1].y * w[1].x, M[4] = u[1].y * w[1].y, M[5] = u[1].y * w[1].z;
  M[6] = u[1].z * w[1].x, M[7] = u[1].z * w[1].y, M[8] = u[1].z * w[1].z;
  for (int k = 2; k < 7; ++k) {
    M[0] += u[k].x * w[k].x, M[1] += u[k].x * w[k].y, M[2] += u[k].x * w[k].z;
    M[3] += u[k].y * w[k].x, M[4] += u[k].y * w[k].y, M[5] += u[k].y * w[k].z;
    M[6] += u[k].z * w[k].x, M[7] += u[k].z * w[k].y, M[8] += u[k].z * w[k].z;
  }
}

}  // namespace

// A kernel, long by design (issue #44): one pass over a batch of SIMD lanes with the gradients,
// strains, stresses and forces in registers; cut into functions it would spill them.
void hex8_internal_forces(Hex8Block& b, const double* x, const double* v, double dt, double* f,
                          ElementEnergyIncrement& energy, StableStep& step, const double* x_ref) {
  const std::size_t n = b.n;
  const std::uint8_t* dead = b.n_eroded ? b.eroded.data() : nullptr;
  if (dead && !x_ref) throw std::logic_error("hex8_internal_forces: eroded elements need x_ref");
  // Chunk scratch, [component][CH]: what the force pass needs from the kinematics pass.
  alignas(64) double deps[6][CH];
  alignas(64) double sig_old[6][CH];
  alignas(64) double Rm[9][CH];  // element frame (columns e1 e2 e3)
  alignas(64) double Qm[9][CH];  // F M: deformation gradient times reference material axes
  alignas(64) double Vol[CH];
  alignas(64) double iVol[CH];
  alignas(64) double Dk[6][3][CH];  // d_1..d_6
  alignas(64) double Ak[4][3][CH];  // a_4..a_7
  alignas(64) double qdot[12][CH];  // hourglass rates, element frame, [3*mode+axis]
  alignas(64) double ilen[3][CH];   // reciprocal half lengths of the element frame
  alignas(64) double dtc[CH];

  VD e_int = 0.0, e_stab = 0.0, e_hg = 0.0;
  const double kappa = b.hourglass_stiffness, zeta = b.hourglass_viscosity;
  const double third = 1.0 / 3.0, ninth = 1.0 / 9.0;
  const double p_mod = b.p_modulus;
  const std::int32_t* conn = b.conn.data();
  const double* jm = b.jac_inv0_axes.data();
  const double* hgm = b.hg_moduli.data();
  const bool directional = !b.step_modulus.empty();
  const double* smod = b.step_modulus.data();
  const double* slen = b.step_length0.data();
  const double* rho = b.density.data();
  const double* vol0 = b.volume0.data();
  double* strain = b.strain.data();
  double* stress = b.stress.data();
  double* hgf = b.hg_force.data();
  double* hgv = b.hg_viscous.data();

  // The element state is ~50 separate [component][n] streams, more than the hardware prefetchers
  // follow: every stream of the chunk kAhead chunks ahead is requested (into L2) while this one
  // computes, the material's history with them, and the chunk's nodes.
  auto prefetch_chunk = [&](std::size_t c0) {
    if (c0 >= std::min(n, b.range_end)) return;
    const std::size_t cn = std::min<std::size_t>(CH, n - c0);
    auto rows = [&]<int rw>(const auto* base, int n_rows, std::integral_constant<int, rw>) {
      constexpr std::size_t per_line = 64 / sizeof(*base);
      for (int r = 0; r < n_rows; ++r)
        for (std::size_t k = 0; k < cn; k += per_line)
          __builtin_prefetch(base + r * n + c0 + k, rw, 2);
    };
    constexpr std::integral_constant<int, 0> read{};
    constexpr std::integral_constant<int, 1> write{};
    rows(conn, 8, read);
    rows(jm, 9, read);
    rows(hgm, 6, read);
    if (directional) rows(smod, 1, read), rows(slen, 1, read);
    rows(rho, 1, read);
    rows(vol0, 1, read);
    rows(strain, 6, write);
    rows(stress, 6, write);
    rows(hgf, 12, write);
    if (zeta != 0) rows(hgv, 12, write);
    rows(b.volume.data(), 1, write);
    if (!b.history.empty()) rows(b.history.data(), b.material->n_history(), write);
    // The nodes, gathered through conn: each element's corners 0, 3, 4 and 7 start the four
    // runs of node numbers its corners lie on (a tow's nodes are numbered along it), so these
    // four bring in the lines of the others. 4-6 % of the paper model's cycle (bench_forming).
    for (int I : {0, 3, 4, 7})
      for (std::size_t k = 0; k < cn; ++k) {
        const std::size_t i = 3 * static_cast<std::size_t>(conn[I * n + c0 + k]);
        __builtin_prefetch(x + i, 0, 2);
        __builtin_prefetch(v + i, 0, 2);
      }
  };
  constexpr std::size_t kAhead = 4;  // chunks
  const std::size_t e_begin = b.range_begin, e_end = std::min(n, b.range_end);
  for (std::size_t k = 0; k < kAhead; ++k) prefetch_chunk(e_begin + k * CH);

  for (std::size_t e0 = e_begin; e0 < e_end; e0 += CH) {
    const int m = static_cast<int>(std::min<std::size_t>(CH, e_end - e0));
    prefetch_chunk(e0 + kAhead * CH);

    // Pass A: kinematics, W elements at a time.
    for (int j = 0; j < m; j += W) {
      const int cnt = std::min(W, m - j);
      const std::size_t e = e0 + static_cast<std::size_t>(j);
      VD xu[3][8], vu[3][8];  // [component][node]
      for (int I = 0; I < 8; ++I) {
        const std::int32_t* ci = conn + I * n + e;
        std::size_t idx[W];
        for (int l = 0; l < W; ++l)
          idx[l] = 3 * static_cast<std::size_t>(ci[l < cnt ? l : cnt - 1]);
        for (int c = 0; c < 3; ++c) {
          xu[c][I] = VD([&](auto l) { return x[idx[l] + c]; });
          vu[c][I] = VD([&](auto l) { return v[idx[l] + c]; });
        }
      }
      if (dead) {  // eroded lanes: at rest in the reference shape, so F = I and nothing moves
        for (int l = 0; l < cnt; ++l) {
          if (!dead[e + static_cast<std::size_t>(l)]) continue;
          for (int I = 0; I < 8; ++I) {
            const std::size_t i =
                3 * static_cast<std::size_t>(conn[I * n + e + static_cast<std::size_t>(l)]);
            for (int c = 0; c < 3; ++c) xu[c][I][l] = x_ref[i + c], vu[c][I][l] = 0.0;
          }
        }
      }
      // Largest face area (stable step), from the nodes before they are transformed.
      VD amax_sq = 0.0;
      {
        for (const auto& face : kHex8Faces) {
          const auto& fc = face.corner;
          const V3v d1{xu[0][fc[2]] - xu[0][fc[0]], xu[1][fc[2]] - xu[1][fc[0]],
                       xu[2][fc[2]] - xu[2][fc[0]]};
          const V3v d2{xu[0][fc[3]] - xu[0][fc[1]], xu[1][fc[3]] - xu[1][fc[1]],
                       xu[2][fc[3]] - xu[2][fc[1]]};
          const V3v cr = cross(d1, d2);
          amax_sq = stdx::max(amax_sq, 0.25 * dot(cr, cr));
        }
      }
      VD ac[3][8], vc[3][8];
      for (int c = 0; c < 3; ++c) basis_transform(xu[c], ac[c]), basis_transform(vu[c], vc[c]);
      V3v a[8], vh[8];
      for (int k = 1; k < 8; ++k) {
        a[k] = {0.125 * ac[0][k], 0.125 * ac[1][k], 0.125 * ac[2][k]};
        vh[k] = {0.125 * vc[0][k], 0.125 * vc[1][k], 0.125 * vc[2][k]};
      }
      V3v d[7];
      d[1] = cross(a[2], a[3]) + third * cross(a[6], a[5]);
      d[2] = cross(a[3], a[1]) + third * cross(a[4], a[6]);
      d[3] = cross(a[1], a[2]) + third * cross(a[5], a[4]);
      d[4] = third * (cross(a[6], a[2]) + cross(a[3], a[5]));
      d[5] = third * (cross(a[4], a[3]) + cross(a[1], a[6]));
      d[6] = third * (cross(a[2], a[4]) + cross(a[5], a[1]));
      VD s = 0.0;
      for (int k = 1; k < 7; ++k) s += dot(a[k], d[k]);
      const VD V = (8.0 * third) * s;
      if (!stdx::all_of(V > 0.0)) {
        for (int l = 0; l < cnt; ++l)
          if (!(V[l] > 0)) {
            Vec3 xe[8];
            gather(b, e + static_cast<std::size_t>(l), x, xe);
            throw_bad_volume(b, e + static_cast<std::size_t>(l), xe, V[l]);
          }
      }
      // Velocity gradient L = sum_k vhat_k (x) d_k * 8/V.
      const VD iV = 1.0 / V;
      const VD f8V = 8.0 * iV;
      VD L[9];
      sum_outer(vh, d, L);
      for (VD& l : L) l *= f8V;
      // Element frame: e1 along a1, e2 in the a1-a2 plane, e3 normal; half lengths.
      const VD in1 = 1.0 / stdx::sqrt(dot(a[1], a[1]));
      const V3v e1 = in1 * a[1];
      const V3v w = a[2] - dot(a[2], e1) * e1;
      const VD in2 = 1.0 / stdx::sqrt(dot(w, w));
      const V3v e2 = in2 * w;
      const V3v e3 = cross(e1, e2);
      const VD R[9] = {e1.x, e2.x, e3.x, e1.y, e2.y, e3.y, e1.z, e2.z, e3.z};
      // Deformation gradient F = J J_ref^{-1} in the reference material axes M (FM); its C
      // bounds the directional step.
      const VD J[9] = {a[1].x, a[2].x, a[3].x, a[1].y, a[2].y, a[3].y, a[1].z, a[2].z, a[3].z};
      VD JM[9], FM[9];
      for (int k = 0; k < 9; ++k) JM[k] = load(jm + k * n + e, cnt);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          FM[3 * r + c] = J[3 * r] * JM[c] + J[3 * r + 1] * JM[3 + c] + J[3 * r + 2] * JM[6 + c];
      const VD C11 = FM[0] * FM[0] + FM[3] * FM[3] + FM[6] * FM[6];
      const VD C22 = FM[1] * FM[1] + FM[4] * FM[4] + FM[7] * FM[7];
      const VD C33 = FM[2] * FM[2] + FM[5] * FM[5] + FM[8] * FM[8];
      const VD C12 = FM[0] * FM[1] + FM[3] * FM[4] + FM[6] * FM[7];
      const VD C23 = FM[1] * FM[2] + FM[4] * FM[5] + FM[7] * FM[8];
      const VD C13 = FM[0] * FM[2] + FM[3] * FM[5] + FM[6] * FM[8];
      // Green-Lagrange strain increment in the material axes, from the rate of deformation of
      // the uniform-gradient operator that makes the nodal forces: dE = (FM)^T sym(Lbar) (FM) dt,
      // both at the mid-step shape x - v dt/2. Then V0 S : dE = V sigma : Lbar dt, the work the
      // nodal forces do, on distorted elements too (dE from the centre F alone differs from it by
      // V sigma : (Lbar - L_centre), work no one books); and a rigid rotation gives dE = 0
      // exactly (the mid-step gradient of a rotation increment is skew).
      {
        const VD hdt = 0.5 * dt;
        V3v am[7];
        for (int k = 1; k < 7; ++k) am[k] = a[k] - hdt * vh[k];
        V3v dm[7];
        dm[1] = cross(am[2], am[3]) + third * cross(a[6] - hdt * vh[6], am[5]);
        dm[2] = cross(am[3], am[1]) + third * cross(am[4], a[6] - hdt * vh[6]);
        dm[3] = cross(am[1], am[2]) + third * cross(am[5], am[4]);
        dm[4] = third * (cross(a[6] - hdt * vh[6], am[2]) + cross(am[3], am[5]));
        dm[5] = third * (cross(am[4], am[3]) + cross(am[1], a[6] - hdt * vh[6]));
        dm[6] = third * (cross(am[2], am[4]) + cross(am[5], am[1]));
        VD sm = 0.0;
        for (int k = 1; k < 7; ++k) sm += dot(am[k], dm[k]);
        const VD f8Vm = 3.0 / sm;  // 8 / V at mid-step, V = 8/3 sum a_k . d_k
        VD Lm[9];
        sum_outer(vh, dm, Lm);
        const VD g = dt * f8Vm;
        const VD D[9] = {g * Lm[0],
                         0.5 * g * (Lm[1] + Lm[3]),
                         0.5 * g * (Lm[2] + Lm[6]),
                         0.5 * g * (Lm[1] + Lm[3]),
                         g * Lm[4],
                         0.5 * g * (Lm[5] + Lm[7]),
                         0.5 * g * (Lm[2] + Lm[6]),
                         0.5 * g * (Lm[5] + Lm[7]),
                         g * Lm[8]};
        const VD Jm[9] = {am[1].x, am[2].x, am[3].x, am[1].y, am[2].y,
                          am[3].y, am[1].z, am[2].z, am[3].z};
        VD Fm[9];
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            Fm[3 * r + c] =
                Jm[3 * r] * JM[c] + Jm[3 * r + 1] * JM[3 + c] + Jm[3 * r + 2] * JM[6 + c];
        VD DF[9];  // D (FM)
        for (int r = 0; r < 3; ++r)
          for (int c = 0; c < 3; ++c)
            DF[3 * r + c] = D[3 * r] * Fm[c] + D[3 * r + 1] * Fm[3 + c] + D[3 * r + 2] * Fm[6 + c];
        auto G = [&](int r, int c) {  // ((FM)^T D (FM))_rc
          return Fm[r] * DF[c] + Fm[3 + r] * DF[3 + c] + Fm[6 + r] * DF[6 + c];
        };
        const VD dE[6] = {G(0, 0), G(1, 1), G(2, 2), 2.0 * G(0, 1), 2.0 * G(1, 2), 2.0 * G(0, 2)};
        for (int c = 0; c < 6; ++c) {
          store_a(&deps[c][j], dE[c]);
          store_a(&sig_old[c][j], load(stress + c * n + e, cnt));
        }
      }
      for (int k = 0; k < 9; ++k) store_a(&Qm[k][j], FM[k]), store_a(&Rm[k][j], R[k]);
      // Hourglass rates q_alpha = vhat_{3+alpha} - L a_{3+alpha}, then into the element frame.
      for (int al = 0; al < 4; ++al) {
        const V3v& aa = a[4 + al];
        const V3v q{vh[4 + al].x - (L[0] * aa.x + L[1] * aa.y + L[2] * aa.z),
                    vh[4 + al].y - (L[3] * aa.x + L[4] * aa.y + L[5] * aa.z),
                    vh[4 + al].z - (L[6] * aa.x + L[7] * aa.y + L[8] * aa.z)};
        store_a(&qdot[3 * al][j], R[0] * q.x + R[3] * q.y + R[6] * q.z);
        store_a(&qdot[3 * al + 1][j], R[1] * q.x + R[4] * q.y + R[7] * q.z);
        store_a(&qdot[3 * al + 2][j], R[2] * q.x + R[5] * q.y + R[8] * q.z);
        store_a(&Ak[al][0][j], aa.x), store_a(&Ak[al][1][j], aa.y), store_a(&Ak[al][2][j], aa.z);
      }
      for (int k = 1; k < 7; ++k)
        store_a(&Dk[k - 1][0][j], d[k].x), store_a(&Dk[k - 1][1][j], d[k].y),
            store_a(&Dk[k - 1][2][j], d[k].z);
      store_a(&ilen[0][j], in1), store_a(&ilen[1][j], in2),
          store_a(&ilen[2][j], 1.0 / stdx::abs(dot(a[3], e3)));
      store_a(&Vol[j], V);
      store_a(&iVol[j], iV);
      // Characteristic length V / A_max over the wave speed sqrt(p_modulus / rho), or the
      // directional bound where that allows more (hex8_element_steps).
      const VD rho_e = load(rho + e, cnt);
      const VD lc = V / stdx::sqrt(amax_sq);
      VD step = lc * stdx::sqrt(rho_e / p_mod);
      if (directional) {
        const VD sm = load(smod + e, cnt), lc0 = load(slen + e, cnt);
        const VD a = stdx::abs(C12), bb = stdx::abs(C23), c = stdx::abs(C13);
        const VD cg =
            stdx::max(stdx::max(stdx::max(C11 + a + c, C22 + a + bb), C33 + bb + c), VD(1.0));
        VD dir = stdx::min(lc0, lc) * stdx::sqrt(rho_e / (cg * sm));
        stdx::where(!(sm > 0.0), dir) = 0.0;  // no bound (padding lanes)
        step = stdx::max(step, dir);
      }
      store_a(&dtc[j], step);
    }

    // Pass B: constitutive update for the whole batch (one call, no per-element dispatch).
    MaterialBatch batch;
    batch.n = static_cast<std::size_t>(m);
    batch.stride = n;
    batch.strain_stride = CH;
    batch.strain_increment = &deps[0][0];
    batch.stress = stress + e0;
    batch.history = b.history.empty() ? nullptr : b.history.data() + e0;
    batch.length = b.axis_length.empty() ? nullptr : b.axis_length.data() + e0;
    batch.dt = dt;
    b.material->update_stress(batch);

    // Pass C: nodal forces (stress + stabilisation), energies.
    for (int j = 0; j < m; j += W) {
      const int cnt = std::min(W, m - j);
      const std::size_t e = e0 + static_cast<std::size_t>(j);
      const auto live = [cnt](const VD& val) { return batch::live(val, cnt); };
      const VD V = load_a(&Vol[j]), iV = load_a(&iVol[j]);
      store(b.volume.data() + e, V, cnt);
      const VD V0 = load(vol0 + e, cnt);
      VD sm[6], wint = 0.0;
      for (int c = 0; c < 6; ++c) sm[c] = load(stress + c * n + e, cnt);
      if (dead)  // an eroded element carries no stress, whatever its material made of no strain
        for (int l = 0; l < cnt; ++l)
          if (dead[e + static_cast<std::size_t>(l)])
            for (VD& s : sm) s[l] = 0.0;
      for (int c = 0; c < 6; ++c) {
        const VD de = load_a(&deps[c][j]);
        wint += 0.5 * (sm[c] + load_a(&sig_old[c][j])) * de;
        store(strain + c * n + e, load(strain + c * n + e, cnt) + de, cnt);
      }
      e_int += live(V0 * wint);
      // Cauchy stress sigma = (FM) S (FM)^T / det F, with S the 2nd Piola-Kirchhoff stress in the
      // material axes; det F = V / V0 with the exact volumes.
      const VD Sm[9] = {sm[0], sm[3], sm[5], sm[3], sm[1], sm[4], sm[5], sm[4], sm[2]};
      VD Q[9], SQt[9], sg[9];
      for (int k = 0; k < 9; ++k) Q[k] = load_a(&Qm[k][j]);
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          SQt[3 * r + c] =
              Sm[3 * r] * Q[3 * c] + Sm[3 * r + 1] * Q[3 * c + 1] + Sm[3 * r + 2] * Q[3 * c + 2];
      const VD iJ = V0 * iV;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          sg[3 * r + c] =
              iJ * (Q[3 * r] * SQt[c] + Q[3 * r + 1] * SQt[3 + c] + Q[3 * r + 2] * SQt[6 + c]);

      // Physical stabilisation: incremental generalised forces in the element frame.
      const VD il1 = load_a(&ilen[0][j]), il2 = load_a(&ilen[1][j]), il3 = load_a(&ilen[2][j]);
      const VD E1 = load(hgm + e, cnt), E2 = load(hgm + n + e, cnt),
               E3 = load(hgm + 2 * n + e, cnt);
      const VD G12 = load(hgm + 3 * n + e, cnt), G23 = load(hgm + 4 * n + e, cnt),
               G13 = load(hgm + 5 * n + e, cnt);
      VD qd[12], dc[12];
      for (int k = 0; k < 12; ++k) qd[k] = load_a(&qdot[k][j]), dc[k] = dt * qd[k];
      const VD kV = kappa * V;
      VD dQ[12];
      // index [3*mode + axis]; modes 0: eta*zeta, 1: zeta*xi, 2: xi*eta, 3: xi*eta*zeta
      const VD k1 = kV * E1 * (il1 * il1), k2 = kV * E2 * (il2 * il2), k3 = kV * E3 * (il3 * il3);
      dQ[3 * 1 + 0] = third * k1 * dc[3 * 1 + 0];
      dQ[3 * 2 + 0] = third * k1 * dc[3 * 2 + 0];
      dQ[3 * 3 + 0] = ninth * k1 * dc[3 * 3 + 0];
      dQ[3 * 0 + 1] = third * k2 * dc[3 * 0 + 1];
      dQ[3 * 2 + 1] = third * k2 * dc[3 * 2 + 1];
      dQ[3 * 3 + 1] = ninth * k2 * dc[3 * 3 + 1];
      dQ[3 * 0 + 2] = third * k3 * dc[3 * 0 + 2];
      dQ[3 * 1 + 2] = third * k3 * dc[3 * 1 + 2];
      dQ[3 * 3 + 2] = ninth * k3 * dc[3 * 3 + 2];
      {  // twist modes, coupled through the shear strains they share
        const VD c11 = dc[0], c22 = dc[4], c33 = dc[8];
        const VD s12 = c11 * il2 + c22 * il1, s13 = c11 * il3 + c33 * il1,
                 s23 = c22 * il3 + c33 * il2;
        dQ[0] = third * kV * (G12 * s12 * il2 + G13 * s13 * il3);
        dQ[4] = third * kV * (G12 * s12 * il1 + G23 * s23 * il3);
        dQ[8] = third * kV * (G13 * s13 * il1 + G23 * s23 * il2);
      }
      // Viscous part: fraction zeta of the critical damping of the stiffest hourglass mode.
      const VD Emax = stdx::max(stdx::max(E1, E2), E3), ilmax = stdx::max(stdx::max(il1, il2), il3);
      const VD cv = zeta * 2.0 * V * stdx::sqrt(load(rho + e, cnt) * Emax * third) * ilmax;
      VD Qt[12], wst = 0.0, whg = 0.0;
      for (int k = 0; k < 12; ++k) {
        const VD qo = load(hgf + k * n + e, cnt);
        const VD qn = qo + dQ[k];
        store(hgf + k * n + e, qn, cnt);
        wst += 0.5 * (qo + qn) * dc[k];
        // Trapezoid over the increments around each force, as every other work is booked: the
        // increment before t^n carries half of this force and half of the last cycle's.
        const VD qv = cv * qd[k];
        if (zeta != 0) {
          whg += 0.5 * (qv + load(hgv + k * n + e, cnt)) * dc[k];
          store(hgv + k * n + e, qv, cnt);
        }
        Qt[k] = qn + qv;
      }
      e_stab += live(wst);
      e_hg += live(whg);
      // Generalised hourglass forces to global axes, H = sum_alpha Q_alpha (x) a_{3+alpha}
      VD R[9];
      for (int k = 0; k < 9; ++k) R[k] = load_a(&Rm[k][j]);
      V3v Qg[4];
      for (int al = 0; al < 4; ++al) {
        const VD* q = Qt + 3 * al;
        Qg[al] = {R[0] * q[0] + R[1] * q[1] + R[2] * q[2], R[3] * q[0] + R[4] * q[1] + R[5] * q[2],
                  R[6] * q[0] + R[7] * q[1] + R[8] * q[2]};
      }
      VD H[9];
      for (int al = 0; al < 4; ++al) {
        const VD ax = load_a(&Ak[al][0][j]), ay = load_a(&Ak[al][1][j]), az = load_a(&Ak[al][2][j]);
        if (al == 0) {
          H[0] = Qg[0].x * ax, H[1] = Qg[0].x * ay, H[2] = Qg[0].x * az;
          H[3] = Qg[0].y * ax, H[4] = Qg[0].y * ay, H[5] = Qg[0].y * az;
          H[6] = Qg[0].z * ax, H[7] = Qg[0].z * ay, H[8] = Qg[0].z * az;
        } else {
          H[0] += Qg[al].x * ax, H[1] += Qg[al].x * ay, H[2] += Qg[al].x * az;
          H[3] += Qg[al].y * ax, H[4] += Qg[al].y * ay, H[5] += Qg[al].y * az;
          H[6] += Qg[al].z * ax, H[7] += Qg[al].z * ay, H[8] += Qg[al].z * az;
        }
      }
      // W_k = (sigma - H/V) d_k (k=1..6) + Q_{k-3}/8 (k=4..7); f_int,I = sum_k S[k][I] W_k
      VD Mt[9];
      for (int k = 0; k < 9; ++k) Mt[k] = sg[k] - iV * H[k];
      VD Wc[3][8];  // [component][k]
      for (int k = 1; k < 7; ++k) {
        const VD dx = load_a(&Dk[k - 1][0][j]), dy = load_a(&Dk[k - 1][1][j]),
                 dz = load_a(&Dk[k - 1][2][j]);
        Wc[0][k] = Mt[0] * dx + Mt[1] * dy + Mt[2] * dz;
        Wc[1][k] = Mt[3] * dx + Mt[4] * dy + Mt[5] * dz;
        Wc[2][k] = Mt[6] * dx + Mt[7] * dy + Mt[8] * dz;
      }
      Wc[0][7] = 0.0, Wc[1][7] = 0.0, Wc[2][7] = 0.0;
      for (int al = 0; al < 4; ++al) {
        Wc[0][4 + al] += 0.125 * Qg[al].x;
        Wc[1][4 + al] += 0.125 * Qg[al].y;
        Wc[2][4 + al] += 0.125 * Qg[al].z;
      }
      alignas(64) double fl[8][3][W];  // [node][component][lane]
      for (int c = 0; c < 3; ++c) {
        VD fc[8];
        basis_transpose(Wc[c], fc);
        for (int I = 0; I < 8; ++I) store_a(fl[I][c], fc[I]);
      }
      for (int l = 0; l < cnt; ++l)  // element order, as the scalar kernel
        for (int I = 0; I < 8; ++I) {
          const std::size_t node =
              static_cast<std::size_t>(conn[I * n + e + static_cast<std::size_t>(l)]);
          f[3 * node] -= fl[I][0][l];
          f[3 * node + 1] -= fl[I][1][l];
          f[3 * node + 2] -= fl[I][2][l];
        }
    }
    for (int j = 0; j < m; ++j)
      if (dtc[j] < step.dt && !(dead && dead[e0 + static_cast<std::size_t>(j)]))
        step = {dtc[j], b.user_id[e0 + static_cast<std::size_t>(j)], ElementKind::Hex8};
  }
  energy.internal += stdx::reduce(e_int) + stdx::reduce(e_stab);
  energy.stabilisation += stdx::reduce(e_stab);
  energy.hourglass += stdx::reduce(e_hg);
}

}  // namespace ncfsim::fem
