// Two-node bars with a tabulated force-strain law.
#include "tests/test_support.hpp"

using namespace ncfsim;

TEST(BarForceLaw, InterpolatesAndExtrapolatesTheTable) {
  fem::BarForceLaw law("stitch", {0.0, 0.01, 0.03}, {0.0, 1.0, 5.0}, true, 1e-5);
  EXPECT_DOUBLE_EQ(law.force(0.005), 0.5);
  EXPECT_DOUBLE_EQ(law.force(0.02), 3.0);
  EXPECT_DOUBLE_EQ(law.force(0.04), 7.0);  // last slope continues
  EXPECT_DOUBLE_EQ(law.force(-0.01), 0.0);  // tension only
  EXPECT_DOUBLE_EQ(law.max_slope(), 200.0);
}

TEST(BarForceLaw, RejectsBadTables) {
  EXPECT_THROW(fem::BarForceLaw("a", {0.0, 0.0}, {0.0, 1.0}, false, 1e-5), std::invalid_argument);
  EXPECT_THROW(fem::BarForceLaw("b", {0.0, 0.1}, {0.0, -1.0}, false, 1e-5), std::invalid_argument);
  EXPECT_THROW(fem::BarForceLaw("c", {0.0, 0.1}, {0.0, 1.0}, false, 0.0), std::invalid_argument);
  EXPECT_THROW(fem::BarForceLaw("d", {0.1, 0.2}, {1.0, 2.0}, false, 1e-5), std::invalid_argument);
}

namespace {

// One bar along x, node 0 fixed, node 1 driven at velocity vx; returns the bar force and the
// reaction at the fixed node after the end node moved `travel`.
struct BarRun {
  double force, reaction_x, internal;
};

BarRun drive_bar(double vx, bool tension_only, double travel) {
  fem::Model model;
  const int p = model.mesh.add_part("stitch");
  model.mesh.coords = {0, 0, 0, 0.01, 0, 0};
  model.mesh.elements(fem::ElementKind::Bar2).add({0, 1}, p);
  model.bar_laws.push_back(fem::BarForceLaw::linear("yarn", 100.0, tension_only, 1e-4));
  model.parts.resize(1);
  model.parts[0].bar_law = 0;
  model.fixed.push_back({"anchor", {0}, {true, true, true}});
  fem::PrescribedVelocity pv{"pull", {1}, {true, true, true}, {vx, 0, 0}, 0.0, 0.0};
  model.velocities.push_back(pv);
  model.time.end_time = 1;
  fem::ExplicitSolver solver(model);
  while (std::abs(test::node_coord(solver, 1, 0) - 0.01) < travel) solver.step();
  solver.step();
  const auto& b = solver.blocks<fem::BarBlock>().at(0);
  return {b.force[0], solver.reaction_force({0}).x, solver.energy().internal};
}

}  // namespace

TEST(Bar, TensionOnlyBarCarriesNoForceInCompression) {
  const auto r = drive_bar(-0.01, true, 1e-4);
  EXPECT_EQ(r.force, 0.0);
  EXPECT_EQ(r.internal, 0.0);
  EXPECT_NEAR(r.reaction_x, 0.0, 1e-12);
}

TEST(Bar, AxialForceFollowsTheLawInTension) {
  // Slow pull: strain ~1e-2, F = EA * strain; the anchor reaction balances it (quasi-static).
  const auto r = drive_bar(0.001, true, 1e-4);
  EXPECT_TRUE(test::near_rel(r.force, 100.0 * 1e-2, 0.02));
  EXPECT_TRUE(test::near_rel(-r.reaction_x, r.force, 0.02));
}

TEST(Bar, CompressionCarriedWhenNotTensionOnly) {
  const auto r = drive_bar(-0.001, false, 1e-4);
  EXPECT_TRUE(test::near_rel(r.force, -1.0, 0.02));
}

// A blow-up is reported with the bar's id and position (never a NaN run): one node of a bar
// block at a non-finite position makes the force pass throw NumericalError naming the bar.
TEST(Bar, NonFiniteForceNamesTheBarAndWhere) {
  fem::Model model;
  const int p = model.mesh.add_part("stitch");
  model.mesh.coords = {0, 0, 0, 0.01, 0, 0, 0.02, 0.002, 0};
  model.mesh.elements(fem::ElementKind::Bar2).add({0, 1}, p);
  model.mesh.elements(fem::ElementKind::Bar2).add({1, 2}, p);
  model.bar_laws.push_back(fem::BarForceLaw::linear("yarn", 100.0, true, 1e-4));
  model.parts.resize(1);
  model.parts[0].bar_law = 0;
  model.time.end_time = 1;
  fem::ExplicitSolver solver(model);
  fem::BarBlock b = solver.blocks<fem::BarBlock>().at(0);
  ASSERT_EQ(b.n, 2u);
  std::vector<double> x = model.mesh.coords, f(x.size(), 0.0);
  x[6] = std::nan("");  // node 2 is lost: the second bar's force is not finite
  fem::ElementEnergyIncrement energy;
  fem::StableStep step;
  try {
    fem::bar_internal_forces(b, x.data(), f.data(), energy, step);
    FAIL() << "no NumericalError";
  } catch (const NumericalError& e) {
    const std::string msg = e.what();
    const std::size_t lost = b.conn[0] == 2 || b.conn[b.n] == 2 ? 0 : 1;  // the bar on node 2
    const std::int64_t id = b.user_id[lost];
    EXPECT_NE(msg.find("bar " + std::to_string(id) + " (part 0) has a non-finite force at ("),
              std::string::npos)
        << msg;
  }
}
