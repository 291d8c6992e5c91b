#include "fem/hex8_block.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "fem/errors.hpp"

namespace ncfsim::fem {
namespace {

constexpr int CH = 64;  // elements per batch: chunk arrays stay in L1/L2

// Sign vectors of the trilinear basis 1, xi, eta, zeta, eta*zeta, zeta*xi, xi*eta, xi*eta*zeta at
// the 8 nodes (VTK order).
constexpr double S[8][8] = {
    {1, 1, 1, 1, 1, 1, 1, 1},      {-1, 1, 1, -1, -1, 1, 1, -1},  {-1, -1, 1, 1, -1, -1, 1, 1},
    {-1, -1, -1, -1, 1, 1, 1, 1},  {1, 1, -1, -1, -1, -1, 1, 1},  {1, -1, -1, 1, -1, 1, 1, -1},
    {1, -1, 1, -1, 1, -1, 1, -1},  {-1, 1, -1, 1, 1, -1, 1, -1}};

struct Vec3 {
  double x, y, z;
};
inline Vec3 operator+(Vec3 a, Vec3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline Vec3 operator-(Vec3 a, Vec3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline Vec3 operator*(double s, Vec3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline double dot(Vec3 a, Vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline Vec3 cross(Vec3 a, Vec3 b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

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
  constexpr int F[6][4] = {{0, 1, 2, 3}, {4, 5, 6, 7}, {0, 1, 5, 4},
                           {1, 2, 6, 5}, {2, 3, 7, 6}, {3, 0, 4, 7}};
  double m = 0;
  for (const auto& f : F) {
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
     << (std::isfinite(V) ? "a non-positive volume " : "a non-finite volume ") << V
     << " m^3 at (" << c.x << ", " << c.y << ", " << c.z << ") m";
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

}  // namespace

void hex8_initialise(Hex8Block& b, const double* x_ref, const std::array<double, 9>& M) {
  const std::size_t n = b.n;
  b.stress.assign(6 * n, 0.0);
  b.strain.assign(6 * n, 0.0);
  b.history.assign(static_cast<std::size_t>(b.material->n_history()) * n, 0.0);
  b.hg_force.assign(12 * n, 0.0);
  b.mat_axes.assign(9 * n, 0.0);
  b.jac_inv0.assign(9 * n, 0.0);
  b.hg_moduli.assign(6 * n, 0.0);
  b.volume.assign(n, 0.0);
  b.volume0.assign(n, 0.0);
  b.density.assign(n, b.material->density());
  b.p_modulus = uniform_strain_modulus(b.material->elastic_stiffness());
  const Voigt6x6 C = b.material->elastic_stiffness();
  std::array<double, 9> last_T{};
  std::array<double, 6> last_moduli{};
  bool have_last = false;
  for (std::size_t e = 0; e < n; ++e) {
    Vec3 xe[8];
    gather(b, e, x_ref, xe);
    HexGeometry g;
    hex_geometry(xe, g);
    if (!(g.V > 0)) throw_bad_volume(b, e, xe, g.V);
    b.volume[e] = g.V;
    double R[9], l[3];
    hex_frame(g, R, l);
    // Inverse of the centre Jacobian [a1 a2 a3]: F = J J_ref^{-1} exactly for homogeneous motion.
    const Vec3 c0 = cross(g.a[2], g.a[3]), c1 = cross(g.a[3], g.a[1]), c2 = cross(g.a[1], g.a[2]);
    const double detJ = dot(g.a[1], c0);
    const double Ji[9] = {c0.x / detJ, c0.y / detJ, c0.z / detJ, c1.x / detJ, c1.y / detJ,
                          c1.z / detJ, c2.x / detJ, c2.y / detJ, c2.z / detJ};
    for (int k = 0; k < 9; ++k) b.jac_inv0[k * n + e] = Ji[k];
    for (int k = 0; k < 9; ++k) b.mat_axes[k * n + e] = M[k];
    b.volume0[e] = g.V;
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

void hex8_element_steps(const Hex8Block& b, const double* x, std::vector<double>& dt) {
  dt.resize(b.n);
  for (std::size_t e = 0; e < b.n; ++e) {
    Vec3 xe[8];
    gather(b, e, x, xe);
    HexGeometry g;
    hex_geometry(xe, g);
    const double lc = g.V / std::sqrt(max_face_area_sq(xe));
    dt[e] = lc / std::sqrt(b.p_modulus / b.density[e]);
  }
}

StableStep hex8_stable_step(const Hex8Block& b, const double* x) {
  std::vector<double> dt;
  hex8_element_steps(b, x, dt);
  StableStep s;
  for (std::size_t e = 0; e < b.n; ++e)
    if (dt[e] < s.dt) s = {dt[e], b.user_id[e], false};
  return s;
}

void hex8_internal_forces(Hex8Block& b, const double* x, const double* v, double dt, double* f,
                          ElementEnergyIncrement& energy, StableStep& step) {
  const std::size_t n = b.n;
  // Chunk scratch, [component][CH]
  alignas(64) double deps[6][CH];
  alignas(64) double sig_old[6][CH];
  alignas(64) double Rm[9][CH];   // element frame (columns e1 e2 e3)
  alignas(64) double Qm[9][CH];   // F M: deformation gradient times reference material axes
  alignas(64) double Vol[CH];
  alignas(64) double Dk[7][3][CH];
  alignas(64) double Ak[4][3][CH];  // a_4..a_7
  alignas(64) double qdot[12][CH];  // hourglass rates, element frame, [3*mode+axis]
  alignas(64) double len[3][CH];
  alignas(64) double dtc[CH];

  double e_int = 0, e_stab = 0, e_hg = 0;
  const double kappa = b.hourglass_stiffness, zeta = b.hourglass_viscosity;
  const double third = 1.0 / 3.0, ninth = 1.0 / 9.0;

  for (std::size_t e0 = 0; e0 < n; e0 += CH) {
    const int m = static_cast<int>(std::min<std::size_t>(CH, n - e0));

    // Pass A: kinematics.
    for (int j = 0; j < m; ++j) {
      const std::size_t e = e0 + j;
      Vec3 xe[8], ve[8];
      gather(b, e, x, xe);
      gather(b, e, v, ve);
      HexGeometry g;
      hex_geometry(xe, g);
      if (!(g.V > 0)) throw_bad_volume(b, e, xe, g.V);
      Vec3 vh[8];
      for (int k = 1; k < 8; ++k) {
        Vec3 s{0, 0, 0};
        for (int I = 0; I < 8; ++I) s = s + S[k][I] * ve[I];
        vh[k] = 0.125 * s;
      }
      const double f8V = 8.0 / g.V;
      double L[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      for (int k = 1; k < 7; ++k) {
        L[0] += vh[k].x * g.d[k].x, L[1] += vh[k].x * g.d[k].y, L[2] += vh[k].x * g.d[k].z;
        L[3] += vh[k].y * g.d[k].x, L[4] += vh[k].y * g.d[k].y, L[5] += vh[k].y * g.d[k].z;
        L[6] += vh[k].z * g.d[k].x, L[7] += vh[k].z * g.d[k].y, L[8] += vh[k].z * g.d[k].z;
      }
      for (double& l : L) l *= f8V;
      double R[9], l3[3];
      hex_frame(g, R, l3);
      // Deformation gradient F = J J_ref^{-1}, Green-Lagrange strain in the reference material
      // axes M: E_mat = M^T (F^T F - I) M / 2. The material sees exact increments of E_mat.
      const double J[9] = {g.a[1].x, g.a[2].x, g.a[3].x, g.a[1].y, g.a[2].y,
                           g.a[3].y, g.a[1].z, g.a[2].z, g.a[3].z};
      double Fm[9], FM[9];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          Fm[3 * r + c] = J[3 * r] * b.jac_inv0[c * n + e] + J[3 * r + 1] * b.jac_inv0[(3 + c) * n + e] +
                          J[3 * r + 2] * b.jac_inv0[(6 + c) * n + e];
      for (int r = 0; r < 3; ++r)  // F M
        for (int c = 0; c < 3; ++c)
          FM[3 * r + c] = Fm[3 * r] * b.mat_axes[c * n + e] + Fm[3 * r + 1] * b.mat_axes[(3 + c) * n + e] +
                          Fm[3 * r + 2] * b.mat_axes[(6 + c) * n + e];
      // C_mat = (FM)^T (FM)
      const double C11 = FM[0] * FM[0] + FM[3] * FM[3] + FM[6] * FM[6];
      const double C22 = FM[1] * FM[1] + FM[4] * FM[4] + FM[7] * FM[7];
      const double C33 = FM[2] * FM[2] + FM[5] * FM[5] + FM[8] * FM[8];
      const double C12 = FM[0] * FM[1] + FM[3] * FM[4] + FM[6] * FM[7];
      const double C23 = FM[1] * FM[2] + FM[4] * FM[5] + FM[7] * FM[8];
      const double C13 = FM[0] * FM[2] + FM[3] * FM[5] + FM[6] * FM[8];
      const double Enew[6] = {0.5 * (C11 - 1), 0.5 * (C22 - 1), 0.5 * (C33 - 1), C12, C23, C13};
      for (int c = 0; c < 6; ++c) deps[c][j] = Enew[c] - b.strain[c * n + e];
      for (int k = 0; k < 9; ++k) Qm[k][j] = FM[k];
      // Hourglass rates q_alpha = vhat_{3+alpha} - L a_{3+alpha}, then into the element frame.
      for (int al = 0; al < 4; ++al) {
        const Vec3 a = g.a[4 + al];
        const Vec3 q{vh[4 + al].x - (L[0] * a.x + L[1] * a.y + L[2] * a.z),
                     vh[4 + al].y - (L[3] * a.x + L[4] * a.y + L[5] * a.z),
                     vh[4 + al].z - (L[6] * a.x + L[7] * a.y + L[8] * a.z)};
        qdot[3 * al][j] = R[0] * q.x + R[3] * q.y + R[6] * q.z;
        qdot[3 * al + 1][j] = R[1] * q.x + R[4] * q.y + R[7] * q.z;
        qdot[3 * al + 2][j] = R[2] * q.x + R[5] * q.y + R[8] * q.z;
        Ak[al][0][j] = a.x, Ak[al][1][j] = a.y, Ak[al][2][j] = a.z;
      }
      for (int k = 0; k < 9; ++k) Rm[k][j] = R[k];
      for (int k = 1; k < 7; ++k) Dk[k][0][j] = g.d[k].x, Dk[k][1][j] = g.d[k].y, Dk[k][2][j] = g.d[k].z;
      for (int k = 0; k < 3; ++k) len[k][j] = l3[k];
      Vol[j] = g.V;
      const double lc = g.V / std::sqrt(max_face_area_sq(xe));
      dtc[j] = lc / std::sqrt(b.p_modulus / b.density[e]);
      for (int c = 0; c < 6; ++c) sig_old[c][j] = b.stress[c * n + e];
    }

    // Pass B: constitutive update for the whole batch (one call, no per-element dispatch).
    MaterialBatch batch;
    batch.n = static_cast<std::size_t>(m);
    batch.stride = n;
    batch.strain_stride = CH;
    batch.strain_increment = &deps[0][0];
    batch.stress = b.stress.data() + e0;
    batch.history = b.history.empty() ? nullptr : b.history.data() + e0;
    batch.dt = dt;
    b.material->update_stress(batch);

    // Pass C: nodal forces (stress + stabilisation), energies, stable step.
    for (int j = 0; j < m; ++j) {
      const std::size_t e = e0 + j;
      const double V = Vol[j];
      b.volume[e] = V;
      double sm[6], wint = 0;
      for (int c = 0; c < 6; ++c) {
        sm[c] = b.stress[c * n + e];
        wint += 0.5 * (sm[c] + sig_old[c][j]) * deps[c][j];
        b.strain[c * n + e] += deps[c][j];
      }
      e_int += b.volume0[e] * wint;
      // Cauchy stress sigma = (FM) S (FM)^T / det F, with S the 2nd Piola-Kirchhoff stress in the
      // material axes; det F = V / V0 with the exact volumes.
      const double Sm[9] = {sm[0], sm[3], sm[5], sm[3], sm[1], sm[4], sm[5], sm[4], sm[2]};
      double Q[9], SQt[9], sg[9];
      for (int k = 0; k < 9; ++k) Q[k] = Qm[k][j];
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          SQt[3 * r + c] = Sm[3 * r] * Q[3 * c] + Sm[3 * r + 1] * Q[3 * c + 1] + Sm[3 * r + 2] * Q[3 * c + 2];
      const double iJ = b.volume0[e] / V;
      for (int r = 0; r < 3; ++r)
        for (int c = 0; c < 3; ++c)
          sg[3 * r + c] = iJ * (Q[3 * r] * SQt[c] + Q[3 * r + 1] * SQt[3 + c] + Q[3 * r + 2] * SQt[6 + c]);

      // Physical stabilisation: incremental generalised forces in the element frame.
      const double l1 = len[0][j], l2 = len[1][j], l3 = len[2][j];
      const double E1 = b.hg_moduli[e], E2 = b.hg_moduli[n + e], E3 = b.hg_moduli[2 * n + e];
      const double G12 = b.hg_moduli[3 * n + e], G23 = b.hg_moduli[4 * n + e],
                   G13 = b.hg_moduli[5 * n + e];
      double dc[12];
      for (int k = 0; k < 12; ++k) dc[k] = dt * qdot[k][j];
      const double kV = kappa * V;
      double dQ[12];
      // index [3*mode + axis]; modes 0: eta*zeta, 1: zeta*xi, 2: xi*eta, 3: xi*eta*zeta
      const double k1 = kV * E1 / (l1 * l1), k2 = kV * E2 / (l2 * l2), k3 = kV * E3 / (l3 * l3);
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
        const double c11 = dc[0], c22 = dc[4], c33 = dc[8];
        const double s12 = c11 / l2 + c22 / l1, s13 = c11 / l3 + c33 / l1, s23 = c22 / l3 + c33 / l2;
        dQ[0] = third * kV * (G12 * s12 / l2 + G13 * s13 / l3);
        dQ[4] = third * kV * (G12 * s12 / l1 + G23 * s23 / l3);
        dQ[8] = third * kV * (G13 * s13 / l1 + G23 * s23 / l2);
      }
      // Viscous part: fraction zeta of the critical damping of the stiffest hourglass mode.
      const double Emax = std::max({E1, E2, E3}), lmin = std::min({l1, l2, l3});
      const double cv = zeta * 2.0 * V * std::sqrt(b.density[e] * Emax * third) / lmin;
      double Qt[12], wst = 0, whg = 0;
      for (int k = 0; k < 12; ++k) {
        const double qo = b.hg_force[k * n + e];
        const double qn = qo + dQ[k];
        b.hg_force[k * n + e] = qn;
        wst += 0.5 * (qo + qn) * dc[k];
        const double qv = cv * qdot[k][j];
        whg += qv * dc[k];
        Qt[k] = qn + qv;
      }
      e_stab += wst;
      e_int += wst;
      e_hg += whg;
      // Generalised hourglass forces to global axes, H = sum_alpha Q_alpha (x) a_{3+alpha}
      double R[9];
      for (int k = 0; k < 9; ++k) R[k] = Rm[k][j];
      Vec3 Qg[4];
      for (int al = 0; al < 4; ++al) {
        const double* q = Qt + 3 * al;
        Qg[al] = {R[0] * q[0] + R[1] * q[1] + R[2] * q[2], R[3] * q[0] + R[4] * q[1] + R[5] * q[2],
                  R[6] * q[0] + R[7] * q[1] + R[8] * q[2]};
      }
      double H[9] = {0, 0, 0, 0, 0, 0, 0, 0, 0};
      for (int al = 0; al < 4; ++al) {
        const double ax = Ak[al][0][j], ay = Ak[al][1][j], az = Ak[al][2][j];
        H[0] += Qg[al].x * ax, H[1] += Qg[al].x * ay, H[2] += Qg[al].x * az;
        H[3] += Qg[al].y * ax, H[4] += Qg[al].y * ay, H[5] += Qg[al].y * az;
        H[6] += Qg[al].z * ax, H[7] += Qg[al].z * ay, H[8] += Qg[al].z * az;
      }
      // W_k = (sigma - H/V) d_k (k=1..6) + Q_{k-3}/8 (k=4..7); f_int,I = sum_k S[k][I] W_k
      const double iV = 1.0 / V;
      double Mx[9];
      for (int k = 0; k < 9; ++k) Mx[k] = sg[k] - iV * H[k];
      Vec3 W[8];
      for (int k = 1; k < 7; ++k) {
        const double dx = Dk[k][0][j], dy = Dk[k][1][j], dz = Dk[k][2][j];
        W[k] = {Mx[0] * dx + Mx[1] * dy + Mx[2] * dz, Mx[3] * dx + Mx[4] * dy + Mx[5] * dz,
                Mx[6] * dx + Mx[7] * dy + Mx[8] * dz};
      }
      W[7] = {0, 0, 0};
      for (int al = 0; al < 4; ++al) W[4 + al] = W[4 + al] + 0.125 * Qg[al];
      for (int I = 0; I < 8; ++I) {
        Vec3 fi{0, 0, 0};
        for (int k = 1; k < 8; ++k) fi = fi + S[k][I] * W[k];
        const std::size_t node = static_cast<std::size_t>(b.conn[I * n + e]);
        f[3 * node] -= fi.x;
        f[3 * node + 1] -= fi.y;
        f[3 * node + 2] -= fi.z;
      }
      if (dtc[j] < step.dt) step = {dtc[j], b.user_id[e], false};
    }
  }
  energy.internal += e_int;
  energy.stabilisation += e_stab;
  energy.hourglass += e_hg;
}

}  // namespace ncfsim::fem
