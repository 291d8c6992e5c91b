// Cantilever with one hexahedron through the thickness, slenderness L/h = 20, tip load P:
// quasi-static tip deflection within 5 % of Euler-Bernoulli, delta = P L^3 / (3 E I).
// The stabilisation carries the bending (physical, part of the internal energy); the viscous
// hourglass work must stay under 10 % of the internal energy.
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

struct CantileverResult {
  double tip_deflection, analytic, internal, hourglass, stabilisation, balance_error;
};

CantileverResult run_cantilever(int n_along) {
  fem::Model model;
  const double L = 0.2, h = 0.01, w = 0.01, E = 200e9, nu = 0.3, rho = 7850, P = 50.0;
  test::add_elastic_block(model, "beam", {0, 0, 0}, {L, h, w}, {n_along, 1, 1}, rho, E, nu);
  fem::FixedDofs root;
  root.nodes = test::nodes_at(model.mesh, 0, 0.0);
  model.fixed.push_back(root);
  fem::NodalLoad tip;
  tip.nodes = test::nodes_at(model.mesh, 0, L);
  tip.force_per_node = {0, -P / static_cast<double>(tip.nodes.size()), 0};
  tip.ramp_time = 0.01;
  model.loads.push_back(tip);
  // Critical mass damping of the first bending mode settles the beam quickly.
  const double I = w * h * h * h / 12.0;
  const double omega1 = 1.875 * 1.875 * std::sqrt(E * I / (rho * w * h * std::pow(L, 4)));
  model.mass_damping = 2.0 * omega1;
  model.time.end_time = 0.04;
  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  double dy = 0;
  for (auto i : tip.nodes) dy += (test::node_coord(solver, i, 1) - model.mesh.coords[3 * i + 1]) / 4.0;
  const auto& en = solver.energy();
  return {-dy, P * L * L * L / (3 * E * I), en.internal, en.hourglass, en.stabilisation, en.error()};
}

}  // namespace

TEST(Hex8Cantilever, OneElementThroughThicknessMatchesEulerBernoulli) {
  const auto r = run_cantilever(20);  // cubic elements
  EXPECT_TRUE(test::near_rel(r.tip_deflection, r.analytic, 0.05))
      << "tip " << r.tip_deflection << " m, Euler-Bernoulli " << r.analytic << " m";
  EXPECT_LT(r.hourglass, 0.10 * r.internal);
  EXPECT_GT(r.stabilisation, 0.5 * r.internal) << "bending should be carried by the stabilisation";
  EXPECT_LT(r.balance_error, 0.01);
}

TEST(Hex8Cantilever, ElongatedElementsStillBendCorrectly) {
  const auto r = run_cantilever(10);  // element aspect 2:1
  EXPECT_TRUE(test::near_rel(r.tip_deflection, r.analytic, 0.05))
      << "tip " << r.tip_deflection << " m, Euler-Bernoulli " << r.analytic << " m";
  EXPECT_LT(r.hourglass, 0.10 * r.internal);
}
