#pragma once
// One free hexahedron as a block, and the exact critical central-difference step of its current
// state: K from the internal forces of small nodal displacements (finite differences through the
// kernel; the tangent of the material, its stabilisation and the stress are all in it), omega_max^2
// = lambda_max(M^-1 K) with the lumped mass rho V0 / 8, dt_crit = 2 / omega_max.
#include <Eigen/Eigenvalues>
#include <array>
#include <cmath>
#include <vector>

#include "fem/elements/hex8_block.hpp"
#include "fem/material.hpp"

namespace ncfsim::test {

struct OneHex {
  std::vector<double> x;  // [8][3] current positions (the reference ones after one_hex)
  fem::Hex8Block block;
};

/// Parallelepiped from the origin spanned by the edges e1, e2, e3 (VTK node order), material
/// axes `axes` (row-major, axes as columns), hourglass viscosity off.
inline OneHex one_hex(const fem::SolidMaterial& mat, const std::array<double, 3>& e1,
                      const std::array<double, 3>& e2, const std::array<double, 3>& e3,
                      const std::array<double, 9>& axes = {1, 0, 0, 0, 1, 0, 0, 0, 1}) {
  OneHex h;
  const int corner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                            {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  for (const auto& c : corner)
    for (int r = 0; r < 3; ++r) h.x.push_back(c[0] * e1[r] + c[1] * e2[r] + c[2] * e3[r]);
  auto& b = h.block;
  b.material = &mat;
  b.n = 1;
  for (int I = 0; I < 8; ++I) b.conn.push_back(I);
  b.user_id = {1};
  b.mesh_hex = {0};
  b.hourglass_viscosity = 0.0;
  fem::hex8_initialise(b, h.x.data(), axes);
  return h;
}

/// Internal forces of a copy of the block moved from h.x to x with velocities v over a unit step.
inline std::vector<double> one_hex_forces(const OneHex& h, const std::vector<double>& x,
                                          const std::vector<double>& v) {
  fem::Hex8Block b = h.block;
  std::vector<double> f(24, 0.0);
  fem::ElementEnergyIncrement inc;
  fem::StableStep st;
  fem::hex8_internal_forces(b, x.data(), v.data(), 1.0, f.data(), inc, st);
  return f;
}

/// Critical step 2 / omega_max of the element in its current state (h.block at h.x).
inline double critical_step(const OneHex& h) {
  const double eps = 1e-6 * std::cbrt(h.block.volume0[0]);
  const std::vector<double> f0 = one_hex_forces(h, h.x, std::vector<double>(24, 0.0));
  Eigen::MatrixXd K(24, 24);
  for (std::size_t j = 0; j < 24; ++j) {
    std::vector<double> x = h.x, v(24, 0.0);
    x[j] += eps, v[j] = eps;
    const auto f = one_hex_forces(h, x, v);
    for (std::size_t i = 0; i < 24; ++i)
      K(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = -(f[i] - f0[i]) / eps;
  }
  const Eigen::MatrixXd Ks =
      0.5 * (K + K.transpose()) / (h.block.density[0] * h.block.volume0[0] / 8.0);
  const double w2 = Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd>(Ks, Eigen::EigenvaluesOnly)
                        .eigenvalues()
                        .maxCoeff();
  return 2.0 / std::sqrt(w2);
}

/// The engine's step estimate for the element at h.x.
inline double estimated_step(const OneHex& h) {
  std::vector<double> dt;
  fem::hex8_element_steps(h.block, h.x.data(), dt);
  return dt[0];
}

}  // namespace ncfsim::test
