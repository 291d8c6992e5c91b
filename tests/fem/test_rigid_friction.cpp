// Coulomb friction against a rigid plane: a block pressed with normal force N and pulled
// sideways slides with a tangential force mu N (within 2 %); pushed sideways with less than
// mu N it sticks: after the push is applied its bottom moves no further (the regularised law
// allows an elastic stick displacement mu N_node / k while the push builds up, none after).
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kMu = 0.3, kN = 200.0, kSize = 0.02;

fem::Model pressed_block() {
  fem::Model model;
  test::add_elastic_block(model, "block", {0, 0, 0}, {kSize, kSize, kSize}, {2, 2, 2}, 2000, 1e8, 0.3);
  fem::RigidTool plane;
  plane.name = "table";
  plane.surface.shape = fem::ToolShape::Plane;
  plane.surface.point = {0, 0, 0};
  plane.surface.axis = {0, 0, 1};
  plane.contact_nodes = test::nodes_at(model.mesh, 2, 0.0);
  plane.friction = kMu;
  model.tools.push_back(plane);
  fem::NodalLoad press;
  press.nodes = test::nodes_at(model.mesh, 2, kSize);
  press.force_per_node = {0, 0, -kN / static_cast<double>(press.nodes.size())};
  press.ramp_time = 2e-3;
  model.loads.push_back(press);
  model.mass_damping = 200.0;  // settles the pressing transient
  return model;
}

}  // namespace

TEST(RigidFriction, SlidingForceEqualsMuTimesNormalForce) {
  fem::Model model = pressed_block();
  // Drive every node above the sliding face, as a sled is towed at its base: a pull at the top
  // alone would tip the soft block (moment mu N h) and lift its trailing edge.
  fem::PrescribedVelocity pull;
  pull.nodes = test::nodes_where(model.mesh, [](double, double, double z) { return z > 1e-9; });
  pull.dofs = {true, false, false};
  pull.velocity = {0.2, 0, 0};  // slides well past the elastic stick distance by t = 8 ms
  pull.start_time = 4e-3;
  pull.ramp_time = 1e-3;
  model.velocities.push_back(pull);
  model.mass_damping = 0;
  model.time.end_time = 12e-3;
  fem::ExplicitSolver solver(model);
  double sum_ft = 0, sum_fn = 0;
  int samples = 0;
  while (solver.time() < model.time.end_time) {
    solver.step([&] {
      if (solver.time() > 8e-3) {
        const auto& tool = solver.model().tools[0];
        sum_ft += tool.force.x;  // force of the block on the table
        sum_fn += -tool.force.z;
        ++samples;
      }
    });
  }
  ASSERT_GT(samples, 10);
  const double ft = sum_ft / samples, fn = sum_fn / samples;
  EXPECT_TRUE(test::near_rel(fn, kN, 0.02)) << "normal force";
  EXPECT_TRUE(test::near_rel(ft, kMu * fn, 0.02)) << "sliding friction force";
  EXPECT_GT(solver.model().tools[0].friction_dissipation, 0.0);
  EXPECT_LT(solver.energy().error(), 0.02);
}

TEST(RigidFriction, BelowMuNormalForceTheBlockSticks) {
  fem::Model model = pressed_block();
  fem::NodalLoad push;
  push.nodes = test::nodes_at(model.mesh, 2, kSize);
  push.force_per_node = {0.6 * kMu * kN / static_cast<double>(push.nodes.size()), 0, 0};
  push.ramp_time = 4e-3;
  model.loads.push_back(push);
  model.time.end_time = 15e-3;
  fem::ExplicitSolver solver(model);
  const auto bottom = test::nodes_at(model.mesh, 2, 0.0);
  auto bottom_slip = [&] {
    double ux = 0;
    for (auto i : bottom) ux = std::max(ux, std::abs(test::node_coord(solver, i, 0) - model.mesh.coords[3 * i]));
    return ux;
  };
  while (solver.time() < 8e-3) solver.step();
  const double slip_8ms = bottom_slip();
  while (solver.time() < model.time.end_time) solver.step();
  // Elastic ringing of the stuck block moves the bottom by ~0.2 um; without friction the push
  // would move it by millimetres over these 7 ms.
  EXPECT_LT(std::abs(bottom_slip() - slip_8ms), 1e-6) << "bottom nodes kept sliding (m)";
  EXPECT_LT(slip_8ms, 1e-3) << "elastic stick displacement (m)";
  const auto& tool = solver.model().tools[0];
  EXPECT_TRUE(test::near_rel(tool.force.x, 0.6 * kMu * kN, 0.02)) << "static friction carries the push";
}

// Normal damping of the tool's penalty spring: a block dropped on the plane keeps nearly all of
// its kinetic energy through the bounce without it (the penalty spring is conservative; a little
// stays in the block as strain energy of its vibration) and clearly less with it; in both cases
// the energy balance closes because the damping work is counted with the contact dissipation.
namespace {
struct Bounce {
  double kinetic_ratio, dissipated_ratio, balance_error;
};
Bounce drop_on_plane(double damping) {
  fem::Model model;
  test::add_elastic_block(model, "block", {0, 0, 1e-4}, {kSize, kSize, kSize}, {2, 2, 2}, 2000, 1e8,
                          0.3);
  fem::RigidTool plane;
  plane.name = "table";
  plane.surface.shape = fem::ToolShape::Plane;
  plane.surface.point = {0, 0, 0};
  plane.surface.axis = {0, 0, 1};
  plane.contact_nodes = test::nodes_at(model.mesh, 2, 1e-4);
  plane.damping = damping;
  model.tools.push_back(plane);
  fem::InitialVelocity drop;
  for (std::size_t i = 0; i < model.mesh.n_nodes(); ++i)
    drop.nodes.push_back(static_cast<std::int32_t>(i));
  drop.velocity = {0, 0, -1.0};
  model.initial_velocities.push_back(drop);
  model.time.end_time = 2e-3;  // the bounce lasts a few element transit times (~0.1 ms)
  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  const auto& e = solver.energy();
  const double ke0 = 0.5 * 2000 * kSize * kSize * kSize * 1.0 * 1.0;
  return {e.kinetic / ke0, solver.model().tools[0].friction_dissipation / ke0, e.error()};
}
}  // namespace

TEST(RigidContactDamping, DampingTakesEnergyFromTheBounceAndItsWorkIsCounted) {
  const Bounce elastic = drop_on_plane(0.0);
  const Bounce damped = drop_on_plane(0.5);
  EXPECT_GT(elastic.kinetic_ratio, 0.8) << "conservative penalty: a nearly elastic bounce";
  EXPECT_NEAR(elastic.dissipated_ratio, 0.0, 1e-12);
  EXPECT_LT(damped.kinetic_ratio, 0.8 * elastic.kinetic_ratio) << "damping takes energy";
  EXPECT_GT(damped.dissipated_ratio, 0.1);
  EXPECT_LT(elastic.balance_error, 0.01);
  EXPECT_LT(damped.balance_error, 0.01);
}
