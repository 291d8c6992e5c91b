// Patch test of the one-point hexahedron (Flanagan-Belytschko uniform gradient, total-Lagrangian
// stress): on a distorted 2x2x2 mesh whose boundary follows a homogeneous motion x = (I + tG) X,
// the free interior node must stay on that motion and every element must carry the same
// Green-Lagrange strain E = (F^T F - I)/2 and stress S = C : E, to 1e-10 relative.
#include <random>

#include "fem/elements/hex8_block.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

struct PatchSetup {
  fem::Model model;
  std::int32_t interior = -1;
  double G[9] = {0.020, 0.006, 0.004, 0.002, -0.010, 0.005, 0.003, 0.001, 0.016};
};

void build_patch(PatchSetup& ps) {
  test::add_elastic_block(ps.model, "cube", {0, 0, 0}, {1, 1, 1}, {2, 2, 2}, 1000.0, 1e9, 0.3);
  auto& m = ps.model.mesh;
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> jitter(-0.12, 0.12);
  for (std::size_t i = 0; i < m.n_nodes(); ++i) {
    for (int c = 0; c < 3; ++c) {
      const double v = m.coords[3 * i + c];
      if (std::abs(v - 0.5) < 1e-12) m.coords[3 * i + c] += jitter(rng);  // distort mid nodes
    }
    bool interior = true;
    for (int c = 0; c < 3; ++c) interior &= std::abs(m.coords[3 * i + c] - 0.5) < 0.2;
    if (interior) ps.interior = static_cast<std::int32_t>(i);
  }
  ASSERT_GE(ps.interior, 0);
  for (std::size_t i = 0; i < m.n_nodes(); ++i) {
    const fem::V3 X{m.coords[3 * i], m.coords[3 * i + 1], m.coords[3 * i + 2]};
    const fem::V3 v{ps.G[0] * X.x + ps.G[1] * X.y + ps.G[2] * X.z,
                    ps.G[3] * X.x + ps.G[4] * X.y + ps.G[5] * X.z,
                    ps.G[6] * X.x + ps.G[7] * X.y + ps.G[8] * X.z};
    if (static_cast<std::int32_t>(i) == ps.interior) {
      ps.model.initial_velocities.push_back({{ps.interior}, v});
    } else {
      fem::PrescribedVelocity pv;
      pv.nodes = {static_cast<std::int32_t>(i)};
      pv.dofs = {true, true, true};
      pv.velocity = v;
      ps.model.velocities.push_back(pv);
      ps.model.initial_velocities.push_back({{static_cast<std::int32_t>(i)}, v});
    }
  }
  ps.model.time.end_time = 1.0;
  ps.model.parts[0].hourglass_viscosity = 0.0;
}

}  // namespace

TEST(Hex8PatchTest, DistortedMeshReproducesHomogeneousDeformation) {
  PatchSetup ps;
  build_patch(ps);
  fem::ExplicitSolver solver(ps.model);
  const auto X0 = ps.model.mesh.node(static_cast<std::size_t>(ps.interior));
  double t_stress = 0;  // stresses are evaluated at t^n, before positions move on to t^{n+1}
  for (int c = 0; c < 300; ++c) solver.step([&] { t_stress = solver.time(); });
  const double t = solver.time();
  ASSERT_GT(t * 0.02, 1e-4) << "the motion must strain the patch measurably";

  // Interior node on the homogeneous motion.
  for (int c = 0; c < 3; ++c) {
    const double expected = X0[c] + t * (ps.G[3 * c] * X0[0] + ps.G[3 * c + 1] * X0[1] + ps.G[3 * c + 2] * X0[2]);
    const double disp = expected - X0[c];
    EXPECT_TRUE(test::near_rel(test::node_coord(solver, ps.interior, c) - X0[c], disp, 1e-10));
  }

  // Analytic Green-Lagrange strain and 2nd Piola-Kirchhoff stress of F = I + tG.
  double F[9];
  for (int k = 0; k < 9; ++k) F[k] = (k % 4 == 0 ? 1.0 : 0.0) + t_stress * ps.G[k];
  double E[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double s = 0;
      for (int k = 0; k < 3; ++k) s += F[3 * k + i] * F[3 * k + j];
      E[i][j] = 0.5 * (s - (i == j ? 1.0 : 0.0));
    }
  const double Ev[6] = {E[0][0], E[1][1], E[2][2], 2 * E[0][1], 2 * E[1][2], 2 * E[0][2]};
  const auto C = ps.model.materials[0]->elastic_stiffness();
  double Sv[6] = {0, 0, 0, 0, 0, 0};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) Sv[i] += C[6 * i + j] * Ev[j];
  double smax = 0;
  for (double s : Sv) smax = std::max(smax, std::abs(s));

  const auto& b = solver.blocks<fem::Hex8Block>().at(0);
  ASSERT_EQ(b.n, 8u);
  for (std::size_t e = 0; e < b.n; ++e)
    for (int c = 0; c < 6; ++c) {
      EXPECT_TRUE(test::near_rel(b.strain[c * b.n + e], Ev[c], 0, 1e-10 * std::abs(Ev[0])))
          << "element " << e << " strain component " << c;
      EXPECT_TRUE(test::near_rel(b.stress[c * b.n + e], Sv[c], 0, 1e-10 * smax))
          << "element " << e << " stress component " << c;
    }
  // A homogeneous motion has no hourglass content.
  EXPECT_LT(std::abs(solver.energy().stabilisation), 1e-10 * solver.energy().internal);
  EXPECT_LT(std::abs(solver.energy().hourglass), 1e-10 * solver.energy().internal);
}
