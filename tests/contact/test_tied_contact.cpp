// Tied contact between two free blocks with non-matching meshes (analytic solution: a rigid
// pair under a force F accelerates at F / (m1 + m2); the tie carries F m_lower / (m1 + m2)).
// The upper block is pulled away from the lower one by a force ramped in over 2 ms (quasi-static:
// a wave crosses a block in 0.03 ms).
//  * Below the normal strength (tie stress 0.25 of it): no tie fails, the blocks move as one,
//    their mean velocities agree within 1 % (and with F t / m_total within 2 %), and the
//    interface opens by less than 1e-3 of the block size (the penalty compliance gives ~1 um).
//  * Above it (tie stress twice the strength at the end of the ramp): every tie fails on the
//    way up, after which nothing acts on the lower block (its velocity from 3 ms to 4 ms changes
//    by less than 1 %) and the upper one accelerates at F / m_upper within 2 %.
//  * The energy balance closes within 1 % in both runs; failed ties report their released
//    elastic energy as dissipated.
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kL = 0.01, kRho = 1000, kStrength = 1e4;  // m, kg/m^3, Pa

struct TieRun {
  double v_lower = 0, v_upper = 0, opening = 0, energy_error = 0, released = 0;
  double v_lower_3ms = 0, v_upper_3ms = 0, t_3ms = 0, t_end = 0;
  std::size_t n_ties = 0, n_failed = 0, n_untied = 0;
};

/// `nodes_to_faces`: the upper block's bottom and top nodes tied to the lower block's surface
/// (TIED_NODES_TO_SURFACE, as the cured stitch's nodes to the tows), no strength.
TieRun pull_apart(double force, bool nodes_to_faces = false) {
  fem::Model model;
  test::add_elastic_block(model, "lower", {0, 0, 0}, {kL, kL, kL}, {3, 3, 2}, kRho, 1e8, 0.3);
  test::add_elastic_block(model, "upper", {0, 0, kL}, {kL, kL, kL}, {2, 2, 2}, kRho, 1e8, 0.3);
  fem::NodalLoad pull;
  pull.name = "pull";
  pull.nodes = test::part_nodes_at(model.mesh, 1, 2, 2 * kL);
  pull.force_per_node = {0, 0, force / static_cast<double>(pull.nodes.size())};
  pull.ramp_time = 2e-3;
  model.loads.push_back(pull);
  fem::TiedContactConfig cfg;
  cfg.name = "glue";
  if (nodes_to_faces) {
    cfg.slave_nodes = test::part_nodes_at(model.mesh, 1, 2, kL);
    for (auto n : test::part_nodes_at(model.mesh, 1, 2, 2 * kL)) cfg.slave_nodes.push_back(n);
    cfg.master = {"lower", {0}};
  } else {
    cfg.slave = {"upper", {1}};
    cfg.master = {"lower", {0}};
    cfg.normal_strength = kStrength;
    cfg.shear_strength = kStrength;
  }
  auto* tie = test::add_contact<fem::TiedContact>(model, cfg);
  model.time.end_time = 4e-3;
  fem::ExplicitSolver solver(model);
  const auto lower = test::part_nodes(model.mesh, 0), upper = test::part_nodes(model.mesh, 1);
  const auto lower_top = test::part_nodes_at(model.mesh, 0, 2, kL);
  const auto upper_bottom = test::part_nodes_at(model.mesh, 1, 2, kL);
  TieRun r;
  while (solver.time() < model.time.end_time) {
    solver.step();
    if (r.v_lower_3ms == 0 && solver.time() >= 3e-3) {
      r.v_lower_3ms = test::mean_of(solver, lower, 2, 1);
      r.v_upper_3ms = test::mean_of(solver, upper, 2, 1);
      r.t_3ms = solver.time() + 0.5 * solver.time_step();
    }
    r.opening = std::max(r.opening, test::mean_of(solver, upper_bottom, 2, 0) -
                                        test::mean_of(solver, lower_top, 2, 0));
  }
  r.v_lower = test::mean_of(solver, lower, 2, 1);
  r.v_upper = test::mean_of(solver, upper, 2, 1);
  r.t_end = solver.time() + 0.5 * solver.time_step();
  r.energy_error = solver.energy().error();
  r.released = tie->friction_dissipation();
  r.n_ties = tie->n_ties();
  r.n_failed = tie->n_failed();
  r.n_untied = tie->untied_nodes();
  return r;
}

// No tie failed; the blocks moved as one rigid pair under the pull F: v(t_end) = F / m_total *
// (ramp / 2 + 2 ms), the interface closed, the balance kept.
void expect_moved_as_one(const TieRun& r, double F) {
  EXPECT_EQ(r.n_failed, 0u);
  EXPECT_TRUE(test::near_rel(r.v_lower, r.v_upper, 0.01)) << "mean velocities of the blocks";
  const double m_total = 2 * kRho * kL * kL * kL;
  EXPECT_TRUE(test::near_rel(r.v_upper, F / m_total * (r.t_end - 1e-3), 0.02));
  EXPECT_LT(r.opening, 1e-3 * kL) << "interface opening (m)";
  EXPECT_LT(r.energy_error, 0.01);
}

}  // namespace

TEST(TiedContact, BelowStrengthTheBlocksMoveAsOne) {
  // Tie stress F m_lower / (m_total A) = 0.25 of the strength.
  const double F = 0.5 * kStrength * kL * kL;
  const TieRun r = pull_apart(F);
  std::printf("tied below: v %.5g / %.5g m/s, opening %.3g m, failed %zu / %zu, error %.3g\n",
              r.v_lower, r.v_upper, r.opening, r.n_failed, r.n_ties, r.energy_error);
  EXPECT_EQ(r.n_ties, 9u) << "the upper block's 3 x 3 bottom nodes";
  expect_moved_as_one(r, F);
}

TEST(TiedContact, AboveStrengthTheBlocksSeparate) {
  // Tie stress twice the strength when the pull is fully on.
  const double F = 4 * kStrength * kL * kL;
  const TieRun r = pull_apart(F);
  std::printf(
      "tied above: v %.5g / %.5g m/s, opening %.3g m, failed %zu / %zu, released %.3g J, error "
      "%.3g\n",
      r.v_lower, r.v_upper, r.opening, r.n_failed, r.n_ties, r.released, r.energy_error);
  EXPECT_EQ(r.n_failed, r.n_ties);
  EXPECT_GT(r.released, 0.0);
  EXPECT_TRUE(test::near_rel(r.v_lower, r.v_lower_3ms, 0.01)) << "nothing pulls the lower block";
  const double m_upper = kRho * kL * kL * kL;
  EXPECT_TRUE(test::near_rel((r.v_upper - r.v_upper_3ms) / (r.t_end - r.t_3ms), F / m_upper, 0.02))
      << "acceleration of the upper block (m/s^2)";
  EXPECT_GT(r.opening, 1e-4) << "the blocks separated (m)";
  EXPECT_LT(r.energy_error, 0.01);
}

// Nodes tied to faces: the upper block's bottom nodes find the lower block's top faces (its top
// nodes, a block's height away, beyond the search distance of the thinnest master hexahedron,
// stay untied); with no strength nothing fails and the blocks move as one under 8x the pull
// that broke the glue above.
TEST(TiedContact, NodesTiedToFacesMoveWithThem) {
  const double F = 4 * kStrength * kL * kL;
  const TieRun r = pull_apart(F, true);
  std::printf(
      "nodes to faces: v %.5g / %.5g m/s, opening %.3g m, tied %zu, untied %zu, error %.3g\n",
      r.v_lower, r.v_upper, r.opening, r.n_ties, r.n_untied, r.energy_error);
  EXPECT_EQ(r.n_ties, 9u) << "the upper block's 3 x 3 bottom nodes";
  EXPECT_EQ(r.n_untied, 9u) << "its top nodes";
  expect_moved_as_one(r, F);
}
