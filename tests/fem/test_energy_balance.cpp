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
  fem::RigidTool& plane = test::add_rigid_plane(model, "plane", {0, 0, 0}, {0, 0, 1},
                                                test::nodes_at(model.mesh, 2, 0.001));
  plane.motion.kind = fem::ToolMotion::Kind::Velocity;
  plane.motion.velocity = {0, 0, 0.1};
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

// Viscous hourglass work (issue #23 item 6): a coarse block (2 x 2 x 2, so its hourglass modes are
// excited by the impact) is thrown at 2 m/s onto a rigid wall and bounces off. In free flight
// after the bounce no force but the element's own acts, so kinetic + internal + hourglass energy
// must stay constant (the viscous hourglass force only turns kinetic energy into hourglass
// work): it may not rise by more than 1e-4 of the impact energy, and the balance closes to 1e-3.
// The work was booked as F^n . du^{n-1/2} (the force over the increment before t^n); the
// trapezoid of F^n over both increments around t^n, as every other force is booked, closes it.
TEST(EnergyBalance, ViscousHourglassWorkEqualsTheEnergyItTakesOut) {
  fem::Model model;
  test::add_elastic_block(model, "block", {0, 0, 0.0005}, {0.02, 0.02, 0.02}, {2, 2, 2}, 1000, 1e6,
                          0.3);
  model.parts[0].hourglass_viscosity = 0.2;
  test::add_rigid_plane(model, "wall", {0, 0, 0}, {0, 0, 1}, test::nodes_at(model.mesh, 2, 0.0005));
  const auto all = test::all_nodes(model.mesh);
  // Tilted velocity: one corner lands first, which excites the hourglass modes.
  model.initial_velocities.push_back({all, {0.3, 0.2, -2.0}});
  model.time.end_time = 0.03;
  fem::ExplicitSolver solver(model);
  const double e0 = solver.energy().kinetic;
  auto mechanical = [&] {
    const auto& en = solver.energy();
    return en.kinetic + en.internal + en.hourglass;
  };
  bool touched = false, apart = false;
  double e_apart = 0, rise = 0;
  while (solver.time() < model.time.end_time) {
    solver.step();
    const auto& tool = solver.model().tools[0];
    if (tool.n_active > 0) touched = true;
    if (touched && tool.n_active == 0 && !apart) apart = true, e_apart = mechanical();
    if (apart) rise = std::max(rise, mechanical() - e_apart);
  }
  ASSERT_TRUE(apart) << "the block did not bounce off";
  EXPECT_GT(solver.energy().hourglass, 1e-6 * e0) << "the hourglass modes were not excited";
  EXPECT_LT(rise, 1e-4 * e0) << "energy rose in free flight: hourglass "
                             << solver.energy().hourglass;
  EXPECT_LT(solver.energy().error(), 1e-3);
}
