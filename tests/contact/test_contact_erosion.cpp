// Contacts after erosion (ContactAlgorithm::erode): the faces of an eroded hexahedron stop being
// contact segments. A block rests on a fixed cube under a load ramped in over 1 ms; once the
// cube's element is reported eroded to the contact, nothing holds the block any more:
//  * penalty contact: no active contact from the next cycle on, and the block falls with the
//    acceleration of its load, F / m, within 1 % (before: at rest, |v| below 1 % of what that
//    fall gives over the same time);
//  * tied contact (the block pulled up at a quarter of the tie strength, so the ties hold): every
//    tie on the eroded cube fails in the next cycle and the block accelerates at F / m within 1 %;
//  * the face that an eroded hexahedron uncovers joins the penalty surface and catches the block.
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {
constexpr double kL = 0.01, kRho = 1000, kE = 1e8;

struct Rig {
  fem::Model model;
  std::vector<std::int32_t> upper;
  double force = 0, upper_mass = 0;
};

// Lower cube (part 0, fixed base) and an upper block (part 1) on it, loaded along z by `force`.
std::unique_ptr<Rig> rig(double force) {
  auto r = std::make_unique<Rig>();
  test::add_elastic_block(r->model, "lower", {0, 0, 0}, {kL, kL, kL}, {1, 1, 1}, kRho, kE, 0.3);
  test::add_elastic_block(r->model, "upper", {0.25 * kL, 0.25 * kL, kL},
                          {0.5 * kL, 0.5 * kL, 0.25 * kL}, {2, 2, 1}, kRho, kE, 0.3);
  r->model.fixed.push_back({"base", test::nodes_at(r->model.mesh, 2, 0.0), {true, true, true}});
  r->upper = test::part_nodes(r->model.mesh, 1);
  fem::NodalLoad ld;
  ld.name = "load";
  ld.nodes = test::part_nodes_at(r->model.mesh, 1, 2, 1.25 * kL);
  ld.force_per_node = {0, 0, force / static_cast<double>(ld.nodes.size())};
  ld.ramp_time = 1e-3;
  r->model.loads.push_back(ld);
  r->force = force;
  r->upper_mass = kRho * 0.5 * kL * 0.5 * kL * 0.25 * kL;
  r->model.time.end_time = 1.0;
  return r;
}

void run_to(fem::ExplicitSolver& s, double t) {
  while (s.time() < t) s.step();
}
}  // namespace

TEST(ContactErosion, PenaltySurfaceOfAnErodedElementHoldsNothing) {
  auto r = rig(-2.0);
  fem::PenaltyContactConfig cfg;
  cfg.name = "rest";
  cfg.groups = {{"lower", {0}}, {"upper", {1}}};
  cfg.pairs = {{0, 1, 0.0}};
  auto* contact = test::add_contact<fem::PenaltyContact>(r->model, cfg);
  fem::ExplicitSolver solver(r->model);
  run_to(solver, 3e-3);
  ASSERT_GT(contact->active_contacts(), 0);
  const double a = r->force / r->upper_mass, t0 = solver.time();
  EXPECT_LT(std::abs(test::mean_of(solver, r->upper, 2, 1)), 0.01 * std::abs(a) * 1e-3)
      << "at rest before";

  contact->erode({0});  // the lower cube
  const double v0 = test::mean_of(solver, r->upper, 2, 1);
  run_to(solver, t0 + 1e-3);
  EXPECT_EQ(contact->active_contacts(), 0);
  const double dv = test::mean_of(solver, r->upper, 2, 1) - v0, dt = solver.time() - t0;
  EXPECT_TRUE(test::near_rel(dv / dt, a, 0.01));
}

TEST(ContactErosion, TiesOnAnErodedElementFail) {
  auto r = rig(+0.5);  // pulls up: 0.5 N over 25 mm^2, a quarter of the strength below
  fem::TiedContactConfig cfg;
  cfg.name = "glue";
  cfg.slave = {"upper", {1}};
  cfg.master = {"lower", {0}};
  cfg.normal_strength = 8e4;  // Pa: 2 N over the block's 25 mm^2
  cfg.shear_strength = 8e4;
  auto* tie = test::add_contact<fem::TiedContact>(r->model, cfg);
  fem::ExplicitSolver solver(r->model);
  run_to(solver, 3e-3);
  ASSERT_GT(tie->n_ties(), 0u);
  ASSERT_EQ(tie->n_failed(), 0u);
  const double a = r->force / r->upper_mass, t0 = solver.time();

  tie->erode({0});
  const double v0 = test::mean_of(solver, r->upper, 2, 1);
  solver.step();
  EXPECT_EQ(tie->n_failed(), tie->n_ties());
  EXPECT_GE(tie->friction_dissipation(), 0.0);
  run_to(solver, t0 + 1e-3);
  const double dv = test::mean_of(solver, r->upper, 2, 1) - v0, dt = solver.time() - t0;
  EXPECT_TRUE(test::near_rel(dv / dt, a, 0.01));
}

TEST(ContactErosion, FaceUncoveredByErosionCatchesTheBlock) {
  // The lower body is two hexahedra stacked (kL/2 high each). With erosion possible
  // (ContactSetup::erosion) the inner face between them is kept, covered; once the upper one is
  // eroded (reported to the contact; the solver keeps it as a ghost here), the loaded block falls
  // through its volume, held by nothing, and lands on the face it uncovered: it never sinks more
  // than 10 % of kL/2 below that face and comes to rest on it.
  fem::Model model;
  test::add_elastic_block(model, "lower", {0, 0, 0}, {kL, kL, kL}, {1, 1, 2}, kRho, kE, 0.3);
  test::add_elastic_block(model, "upper", {0.25 * kL, 0.25 * kL, kL},
                          {0.5 * kL, 0.5 * kL, 0.25 * kL}, {2, 2, 1}, kRho, kE, 0.3);
  model.fixed.push_back({"base", test::nodes_at(model.mesh, 2, 0.0), {true, true, true}});
  const auto upper = test::part_nodes(model.mesh, 1);
  const auto bottom = test::part_nodes_at(model.mesh, 1, 2, kL);
  fem::NodalLoad ld;
  ld.name = "load";
  ld.nodes = test::part_nodes_at(model.mesh, 1, 2, 1.25 * kL);
  ld.force_per_node = {0, 0, -2.0 / static_cast<double>(ld.nodes.size())};
  ld.ramp_time = 1e-3;
  model.loads.push_back(ld);
  model.mass_damping = 2000;  // settles the landing
  model.time.end_time = 1.0;
  model.time.erosion_step_ratio = 1e-6;  // erosion possible; nothing reaches it by itself
  std::int32_t top_hex = -1;
  const fem::ElementSet& hexes = model.mesh.elements(fem::ElementKind::Hex8);
  for (std::size_t e = 0; e < hexes.size(); ++e)
    if (hexes.part[e] == 0 &&
        model.mesh.coords[3 * static_cast<std::size_t>(hexes.nodes(e)[6]) + 2] > 0.9 * kL)
      top_hex = static_cast<std::int32_t>(e);
  ASSERT_GE(top_hex, 0);
  fem::PenaltyContactConfig cfg;
  cfg.name = "rest";
  cfg.groups = {{"lower", {0}}, {"upper", {1}}};
  cfg.pairs = {{0, 1, 0.0}};
  auto* contact = test::add_contact<fem::PenaltyContact>(model, cfg);
  fem::ExplicitSolver solver(model);
  run_to(solver, 3e-3);
  ASSERT_GT(contact->active_contacts(), 0);
  EXPECT_NEAR(test::mean_of(solver, bottom, 2, 0), kL, 0.05 * kL)
      << "resting on the upper hexahedron";

  contact->erode({top_hex});
  double lowest = 1e300;
  while (solver.time() < 12e-3) {
    solver.step();
    for (auto i : bottom) lowest = std::min(lowest, test::node_coord(solver, i, 2));
  }
  EXPECT_GT(lowest, 0.45 * kL) << "sank through the uncovered face";
  EXPECT_NEAR(test::mean_of(solver, bottom, 2, 0), 0.5 * kL, 0.05 * kL)
      << "at rest on the uncovered face";
  EXPECT_LT(std::abs(test::mean_of(solver, upper, 2, 1)), 0.01) << "m/s";
  EXPECT_GT(contact->active_contacts(), 0);
}
