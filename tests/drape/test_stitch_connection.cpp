// Stitch-to-tow connection: a stitch block joined to a clamped tow block by one connection and
// pulled at constant speed: the force rises with the connection stiffness, then stays at the sliding
// force (within 1 %); the energy dissipated equals F_s times the slip (within 1 %); the energy
// balance closes (< 1 %).
#include <gtest/gtest.h>

#include <map>

#include "drape/fabric_generator.hpp"
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

// The stitch pins the two plies of a blanket to each other at its penetration points: a 20 x 20 mm
// +-45 blanket whose bottom ply is held while the top ply is pulled 20 um along x (tows stiff,
// no contact, so only the stitch couples the plies) is held back by the stitch nodes on the ply
// interface. Each is joined to n1 tows of the bottom ply and n2 of the top one; once they slide
// it holds min(n1, n2) F_s (the sum within 2 %). The legs, tension-only bars across a ply, add only
// a second-order term (a tilt d over the ply thickness t stretches a leg by d^2 / 2t): with the leg
// from the top face to the bottom face alone the plies would slide over each other almost freely.
TEST(StitchConnection, StitchPinsThePliesToEachOther) {
  fem::Model model;
  drape::FabricSpec f;
  drape::BlanketSpec bl;
  bl.size = {0.02, 0.02};
  const drape::FabricModel fm = drape::generate_blanket(model.mesh, f, bl);
  model.parts.resize(model.mesh.part_names.size());
  model.materials.push_back(std::make_unique<fem::ElasticIsotropic>("tow", 1080, 1e9, 0.3));
  for (int p : fm.ply_parts)
    model.parts[static_cast<std::size_t>(p)] = {fem::PartProperties::Kind::Solid, 0};
  // A heavy yarn (100 x 76 dtex) lets the joints be stiff (their stiffness is capped by the stitch
  // node mass): they slide after ~0.1 um, well before the 20 um of pull.
  model.bar_laws.push_back(fem::BarForceLaw::linear("stitch", 2.0, true, 7.6e-4));
  for (int p : {fm.stitch_I_part, fm.stitch_Lambda_part, fm.stitch_leg_part}) {
    model.parts[static_cast<std::size_t>(p)].kind = fem::PartProperties::Kind::Bar;
    model.parts[static_cast<std::size_t>(p)].bar_law = 0;
  }
  std::vector<int> ply_of_node(model.mesh.n_nodes(), -1);
  for (std::size_t e = 0; e < model.mesh.hexes.size(); ++e)
    for (auto nd : model.mesh.hexes[e])
      ply_of_node[static_cast<std::size_t>(nd)] =
          fm.ply_of_tow[static_cast<std::size_t>(fm.tow_of_hex[e])];
  fem::FixedDofs hold;
  hold.name = "bottom_ply";
  fem::PrescribedVelocity pull;
  pull.name = "top_ply";
  pull.dofs = {true, true, true};
  pull.velocity = {0.01, 0, 0};  // m/s: 20 um in 2 ms (+ half the ramp)
  pull.ramp_time = 5e-4;
  for (std::size_t i = 0; i < ply_of_node.size(); ++i) {
    if (ply_of_node[i] == 0) hold.nodes.push_back(static_cast<std::int32_t>(i));
    if (ply_of_node[i] == 1) pull.nodes.push_back(static_cast<std::int32_t>(i));
  }
  model.fixed.push_back(hold);
  model.velocities.push_back(pull);
  drape::StitchConnectionSettings s;
  s.sliding_force = 0.05;
  model.contacts.push_back(
      std::make_unique<drape::StitchToTowConnection>("stitch_tow", fm.connections, s));
  model.time.end_time = 2.25e-3;
  // What the interface nodes can hold once their joints slide.
  const double t = fm.tow_thickness;
  std::map<std::int32_t, std::array<int, 2>> per_ply;
  for (const auto& c : fm.connections)
    if (std::abs(model.mesh.coords[3 * static_cast<std::size_t>(c.stitch_node) + 2] - t) < 1e-9 * t)
      ++per_ply[c.stitch_node]
               [static_cast<std::size_t>(ply_of_node[static_cast<std::size_t>(c.tow_node)])];
  double holding = 0;
  for (const auto& [nd, n] : per_ply) holding += std::min(n[0], n[1]) * s.sliding_force;
  ASSERT_GT(holding, 10 * s.sliding_force);

  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  const fem::V3 F = solver.reaction_force(pull.nodes);
  EXPECT_NEAR(F.x, holding, 0.02 * holding) << "the top ply is held by the interface joints";
  EXPECT_LT(solver.energy().error(), 0.01);
}
