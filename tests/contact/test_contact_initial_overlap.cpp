// Penetration offset of the penalty contact: a node found already behind a surface (an initial
// overlap of the meshes, or a node that reached the surface round an edge or over a seam) starts
// from zero force, so the contact never creates energy. Two blocks whose meshes overlap by 2 % of
// the element thickness at t = 0, with no load:
//  * at rest they stay at rest: no kinetic energy appears (below 1e-12 J; without the offset
//    the overlap springs them apart with the penalty energy 1/2 k p^2 per node, ~1e-6 J here);
//  * the upper block then slid along the interface at 1 m/s, over the lower block's seams
//    (non-matching meshes), gains no vertical velocity (below 1e-6 m/s) and the interface energy
//    is never negative: no energy is created.
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {
constexpr double kL = 0.01, kH = kL / 4, kOverlap = 0.02 * kH;

struct Overlap {
  fem::Model model;
  fem::PenaltyContact* contact = nullptr;
};

std::unique_ptr<Overlap> overlapping_blocks(double slide_speed) {
  auto o = std::make_unique<Overlap>();
  test::add_elastic_block(o->model, "lower", {0, 0, 0}, {kL, kL, kH}, {4, 4, 1}, 1000, 1e8, 0.3);
  test::add_elastic_block(o->model, "upper", {0.2 * kL, 0.1 * kL, kH - kOverlap},
                          {0.5 * kL, 0.5 * kL, kH}, {3, 3, 1}, 1000, 1e8, 0.3);
  if (slide_speed != 0)
    o->model.initial_velocities.push_back({test::part_nodes(o->model.mesh, 1), {slide_speed, 0, 0}});
  fem::PenaltyContactConfig cfg;
  cfg.name = "overlap";
  cfg.groups = {{"lower", {0}}, {"upper", {1}}};
  cfg.pairs = {{0, 1, 0.0}};
  o->contact = test::add_contact<fem::PenaltyContact>(o->model, cfg);
  return o;
}
}  // namespace

TEST(ContactInitialOverlap, OverlappingBlocksAtRestStayAtRest) {
  auto o = overlapping_blocks(0.0);
  o->model.time.end_time = 0.2e-3;
  fem::ExplicitSolver solver(o->model);
  double max_ke = 0;
  while (solver.time() < o->model.time.end_time) {
    solver.step();
    max_ke = std::max(max_ke, solver.energy().kinetic);
  }
  EXPECT_GT(o->contact->active_contacts(), 0) << "the overlap must be seen as contact";
  EXPECT_LT(max_ke, 1e-12) << "the overlap pushed the blocks apart (J)";
}

TEST(ContactInitialOverlap, SlidingOverSeamsCreatesNoEnergy) {
  auto o = overlapping_blocks(1.0);
  o->model.time.end_time = 2e-3;  // 2 mm of sliding: over two seams of the lower block
  fem::ExplicitSolver solver(o->model);
  const auto upper = test::part_nodes(o->model.mesh, 1);
  double max_vz = 0, lowest_contact_energy = 0;
  while (solver.time() < o->model.time.end_time) {
    solver.step();
    max_vz = std::max(max_vz, std::abs(test::mean_of(solver, upper, 2, 1)));
    lowest_contact_energy = std::min(lowest_contact_energy, solver.energy().contact);
  }
  const double ke0 = 0.5 * 1000 * 0.25 * kL * kL * kH * 1.0;
  EXPECT_GT(o->contact->active_contacts(), 0);
  EXPECT_LT(max_vz, 1e-6) << "the upper block was kicked off the interface (m/s)";
  EXPECT_GT(lowest_contact_energy, -1e-9 * ke0) << "contact forces did net work (J)";
  EXPECT_LT(solver.energy().error(), 0.01);
}
