// Wave in a bar of hexahedra: a velocity step at one end reaches the free far end after L/c,
// c = sqrt(E/rho) (nu = 0, so bar and dilatational speeds coincide). Tolerance 2 %.
#include "tests/test_support.hpp"

using namespace ncfsim;

TEST(Hex8Wave, StepWaveArrivesAfterLengthOverWaveSpeed) {
  fem::Model model;
  const double L = 1.0, E = 210e9, rho = 7800.0, v0 = 1.0;
  test::add_elastic_block(model, "bar", {0, 0, 0}, {L, 0.01, 0.01}, {200, 1, 1}, rho, E, 0.0);
  fem::PrescribedVelocity pv;
  pv.nodes = test::nodes_at(model.mesh, 0, 0.0);
  pv.dofs = {true, false, false};
  pv.velocity = {v0, 0, 0};
  model.velocities.push_back(pv);
  model.time.end_time = 1.0;
  fem::ExplicitSolver solver(model);
  const auto far = test::nodes_at(model.mesh, 0, L);
  const double c = std::sqrt(E / rho), t_expected = L / c;
  double t_arrival = -1;
  while (solver.time() < 1.5 * t_expected && t_arrival < 0) {
    solver.step([&] {
      auto V = solver.v.view();
      double vx = 0;
      for (auto i : far) vx += V[3 * static_cast<std::size_t>(i)] / static_cast<double>(far.size());
      if (vx >= v0) t_arrival = solver.time();  // free end: velocity doubles, half-height = v0
    });
  }
  ASSERT_GT(t_arrival, 0) << "the wave never reached the far end";
  EXPECT_TRUE(test::near_rel(t_arrival, t_expected, 0.02));
  EXPECT_LT(solver.energy().error(), 0.01);
}
