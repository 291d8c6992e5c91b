// Stitch-to-tow connection: a stitch block joined to a clamped tow block by one connection and
// pulled at constant speed: the force rises with the connection stiffness, then stays at the sliding
// force (within 1 %); the energy dissipated equals F_s times the slip (within 1 %); the energy
// balance closes (< 1 %).
#include <gtest/gtest.h>

#include "drape/stitch_connection.hpp"
#include "fem/solver.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

TEST(StitchConnection, ElasticThenSlidingAtTheSlidingForce) {
  fem::Model model;
  test::add_elastic_block(model, "tow", {0, 0, 0}, {1e-3, 1e-3, 1e-3}, {1, 1, 1}, 1000, 1e8, 0.3);
  test::add_elastic_block(model, "stitch", {2e-3, 0, 0}, {1e-3, 1e-3, 1e-3}, {1, 1, 1}, 1000, 1e8, 0.3);
  const auto tow_nodes = test::nodes_where(model.mesh, [](double x, double, double) { return x < 1.5e-3; });
  const auto stitch_nodes = test::nodes_where(model.mesh, [](double x, double, double) { return x > 1.5e-3; });
  fem::FixedDofs clamp;
  clamp.name = "clamp";
  clamp.nodes = tow_nodes;
  model.fixed.push_back(clamp);
  fem::PrescribedVelocity pull;
  pull.name = "pull";
  pull.nodes = stitch_nodes;
  pull.dofs = {true, true, true};
  pull.velocity = {0.1, 0, 0};
  pull.ramp_time = 1e-4;
  model.velocities.push_back(pull);
  // Join the stitch block's node at (2, 0, 0) mm to the tow's node at (1, 0, 0) mm.
  std::int32_t a = -1, b = -1;
  for (auto i : stitch_nodes)
    if (std::abs(model.mesh.coords[3 * i] - 2e-3) < 1e-9 && model.mesh.coords[3 * i + 1] == 0 && model.mesh.coords[3 * i + 2] == 0) a = i;
  for (auto i : tow_nodes)
    if (std::abs(model.mesh.coords[3 * i] - 1e-3) < 1e-9 && model.mesh.coords[3 * i + 1] == 0 && model.mesh.coords[3 * i + 2] == 0) b = i;
  ASSERT_GE(a, 0);
  ASSERT_GE(b, 0);
  drape::StitchConnectionSettings s;
  s.sliding_force = 0.5;
  s.stiffness = 2000;  // N/m, below the stability cap (~3900 N/m here): slides after 0.25 mm
  model.contacts.push_back(std::make_unique<drape::StitchToTowConnection>("stitch_tow", std::vector<drape::StitchConnection>{{a, b}}, s));
  model.time.end_time = 8e-3;  // 0.8 mm of pull
  fem::ExplicitSolver solver(model);
  const auto* conn = static_cast<const drape::StitchToTowConnection*>(solver.model().contacts[0].get());
  double f_at_01mm = 0;
  while (solver.time() < model.time.end_time) {
    solver.step([&] {
      const double u = test::node_coord(solver, a, 0) - 2e-3;
      if (f_at_01mm == 0 && u > 0.1e-3) f_at_01mm = solver.reaction_force(pull.nodes).x;
    });
  }
  ASSERT_EQ(conn->stiffness(0), 2000.0);
  EXPECT_NEAR(f_at_01mm, 2000 * 0.1e-3, 0.02 * 0.2) << "elastic branch k u";
  const double F = solver.reaction_force(pull.nodes).x;  // the puller holds the connection force
  EXPECT_NEAR(F, 0.5, 0.01 * 0.5) << "sliding force";
  const double u = test::node_coord(solver, a, 0) - 2e-3;
  const double slip = u - 0.5 / 2000;
  EXPECT_NEAR(conn->slip_length(0), slip, 0.01 * slip);
  EXPECT_NEAR(conn->friction_dissipation(), 0.5 * slip, 0.01 * 0.5 * slip);
  EXPECT_LT(solver.energy().error(), 0.01);
}
