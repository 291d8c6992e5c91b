// The element step estimate against the exact highest frequency of one free hexahedron:
// K is assembled column by column from the internal forces of small nodal displacements (the
// total-Lagrangian kernel, hourglass viscosity off), omega_max^2 = lambda_max(M^-1 K) with the
// lumped mass rho V / 8, and the critical central-difference step is 2 / omega_max.
// On a parallelepiped at rest the directional bound (anisotropic materials) is the exact
// uniform-strain frequency and the hourglass modes lie below it, so the estimate must equal the
// critical step within 1 % (and never exceed it) for orthotropic materials, also sheared and
// with turned fibre axes; for a tow-like element (stiff along its length, soft and thin across)
// the characteristic length V / A_max with the largest modulus alone would be 5 times too small.
// Isotropic elements keep the Flanagan-Belytschko bound: exact on a cube, safe on a plate.
#include <array>
#include <cmath>
#include <vector>

#include "tests/hex8_critical_step.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

using test::critical_step;
using test::estimated_step;

constexpr std::array<double, 9> kIdentity{1, 0, 0, 0, 1, 0, 0, 0, 1};

}  // namespace

TEST(Hex8StableStep, IsotropicCubeIsSafe) {
  fem::ElasticIsotropic steel("steel", 7800, 210e9, 0.3);
  const auto h = test::one_hex(steel, {1e-3, 0, 0}, {0, 1e-3, 0}, {0, 0, 1e-3}, kIdentity);
  const double exact = critical_step(h), est = estimated_step(h);
  EXPECT_LE(est, exact * (1 + 1e-6));
  EXPECT_GE(est, 0.99 * exact);
}

TEST(Hex8StableStep, ThinIsotropicPlateKeepsTheFlanaganBelytschkoMargin) {
  // Isotropic elements keep V/A_max over sqrt(3K/rho): 0.69 of the critical step of a thin plate
  // element (penalty contacts use that margin, fem/contact/README.md).
  fem::ElasticIsotropic steel("steel", 7800, 210e9, 0.3);
  const auto h = test::one_hex(steel, {10e-3, 0, 0}, {0, 8e-3, 0}, {0, 0, 1e-3}, kIdentity);
  const double exact = critical_step(h), est = estimated_step(h);
  EXPECT_LE(est, exact * (1 + 1e-6));
  EXPECT_GE(est, 0.6 * exact);
  EXPECT_TRUE(test::near_rel(est, 1e-3 / std::sqrt(210e9 / (1 - 0.6) / 7800), 1e-9));
}

TEST(Hex8StableStep, OrthotropicTowElementUsesItsLengthForTheFibreModulus) {
  // A tow-like element: 3.3 x 1.65 x 0.15 mm, fibre axis along the length, stiff fibres
  // (20 GPa) against a soft transverse phase (0.1 GPa).
  fem::ElasticOrthotropic tow("tow", 1080,
                              {20e9, 0.1e9, 0.1e9, 0.0, 0.0, 0.0, 0.05e9, 0.05e9, 0.05e9});
  const auto h = test::one_hex(tow, {3.3e-3, 0, 0}, {0, 1.65e-3, 0}, {0, 0, 0.15e-3}, kIdentity);
  const double exact = critical_step(h), est = estimated_step(h);
  EXPECT_LE(est, exact * (1 + 1e-6));
  EXPECT_GE(est, 0.99 * exact);
  // The characteristic length with the largest modulus: ~5 times smaller.
  const double lc = 0.15e-3 / std::sqrt(20e9 / 1080);
  EXPECT_GT(est, 4.0 * lc);
}

TEST(Hex8StableStep, ShearedRotatedOrthotropicElementIsSafe) {
  // A parallelogram prism (60 deg in-plane corner) whose fibre axes are turned 30 deg in plane.
  fem::ElasticOrthotropic tow("tow", 1080,
                              {20e9, 0.1e9, 0.1e9, 0.2, 0.2, 0.3, 0.05e9, 0.05e9, 0.05e9});
  const double c = std::cos(M_PI / 6), s = std::sin(M_PI / 6);
  const std::array<double, 9> axes{c, -s, 0, s, c, 0, 0, 0, 1};
  const auto h = test::one_hex(tow, {3e-3, 0, 0}, {1e-3, 1.7e-3, 0}, {0, 0, 0.2e-3}, axes);
  const double exact = critical_step(h), est = estimated_step(h);
  EXPECT_LE(est, exact * (1 + 1e-6));
  EXPECT_GE(est, 0.99 * exact);
}

TEST(Hex8StableStep, KernelReportsTheSameStep) {
  fem::ElasticOrthotropic tow("tow", 1080,
                              {20e9, 0.1e9, 0.1e9, 0.0, 0.0, 0.0, 0.05e9, 0.05e9, 0.05e9});
  auto h = test::one_hex(tow, {3.3e-3, 0, 0}, {0, 1.65e-3, 0}, {0, 0, 0.15e-3}, kIdentity);
  std::vector<double> v(24, 0.0), f(24, 0.0);
  fem::ElementEnergyIncrement inc;
  fem::StableStep st;
  fem::hex8_internal_forces(h.block, h.x.data(), v.data(), 1e-9, f.data(), inc, st);
  EXPECT_TRUE(test::near_rel(st.dt, estimated_step(h), 1e-12));
}
