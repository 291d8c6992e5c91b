// The energy balance error's scale (fem/energy.hpp). A rigid plane starts 1 mm below a block
// resting on nothing and rises at 0.1 m/s: for the first 10 ms every energy is round-off
// (1e-20 J), which must read as a closed balance, not as a 100 % error; once the plane presses the
// block the error is measured against the largest energy in play so far, so it stays small when
// the energies fall again (the block flies off and the penalty energy goes back into motion).
#include "tests/test_support.hpp"

using namespace ncfsim;

TEST(EnergyBalance, RoundOffBeforeContactIsNotAnError) {
  fem::Model model;
  test::add_elastic_block(model, "block", {0, 0, 0.001}, {0.01, 0.01, 0.01}, {2, 2, 2}, 1000, 1e6,
                          0.3);
  fem::RigidTool plane;
  plane.name = "plane";
  plane.surface.shape = fem::ToolShape::Plane;
  plane.surface.point = {0, 0, 0};
  plane.surface.axis = {0, 0, 1};
  plane.motion.kind = fem::ToolMotion::Kind::Velocity;
  plane.motion.velocity = {0, 0, 0.1};
  plane.contact_nodes = test::nodes_at(model.mesh, 2, 0.001);
  model.tools.push_back(plane);
  model.time.end_time = 0.02;
  fem::ExplicitSolver solver(model);
  double worst_before = 0, worst_after = 0, largest = 0;
  while (solver.time() < model.time.end_time) {
    solver.step();
    const auto& en = solver.energy();
    largest = std::max(largest, en.scale());
    if (solver.time() < 0.009) worst_before = std::max(worst_before, en.error());
    if (solver.time() > 0.012) worst_after = std::max(worst_after, en.error());
  }
  EXPECT_LT(worst_before, 1e-6) << "round-off energies read as an error";
  EXPECT_GT(largest, 1e-6) << "the plane never pressed the block";
  EXPECT_LT(worst_after, 0.01);
  EXPECT_DOUBLE_EQ(solver.energy().scale_max, largest);
}
