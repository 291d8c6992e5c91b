// Impact of two free elastic blocks (analytic solution: conservation laws). A block thrown at an
// identical resting block, offset sideways so the meshes do not match:
//  * total momentum is conserved to 1e-6 of the initial momentum at every cycle (contact forces
//    on nodes and segment corners sum to zero exactly; only round-off remains);
//  * the largest penetration stays below 5 % of the element thickness;
//  * no energy is created: balance error below 1 %, the interface energy (minus the work of the
//    contact forces) is never negative beyond 1e-6 of the initial kinetic energy, kinetic plus
//    internal energy at the end does not exceed the initial kinetic energy, and the blocks part
//    again with the thrown block's momentum mostly handed over. (The contact's default normal
//    damping, 10 % of critical, takes a few per cent of the energy.)
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

TEST(ContactImpact, TwoBlocksConserveMomentumWithoutPenetrationOrEnergyGain) {
  fem::Model model;
  const double L = 0.02, h = L / 5, v0 = 2.0;
  test::add_elastic_block(model, "resting", {0, 0, 0}, {L, L, L}, {5, 5, 5}, 1000, 1e8, 0.3);
  test::add_elastic_block(model, "thrown", {L + 0.5e-3, 0.3 * h, 0.4 * h}, {L, L, L}, {5, 5, 5},
                          1000, 1e8, 0.3);
  model.initial_velocities.push_back({test::part_nodes(model.mesh, 1), {-v0, 0, 0}});
  fem::PenaltyContactConfig cfg;
  cfg.name = "impact";
  cfg.groups = {{"resting", {0}}, {"thrown", {1}}};
  cfg.pairs = {{0, 1, 0.0}};
  auto* contact = test::add_contact<fem::PenaltyContact>(model, cfg);
  // Closing 0.5 mm at 2 m/s takes 0.25 ms; the contact lasts about 2 L / c = 0.1 ms.
  model.time.end_time = 0.6e-3;
  fem::ExplicitSolver solver(model);
  const fem::V3 P0 = test::momentum(solver);
  const double P0n = norm(P0);
  const double ke0 = solver.energy().kinetic;
  double worst_dp = 0, worst_pen = 0, lowest_contact_energy = 0;
  std::int64_t cycles_in_contact = 0;
  while (solver.time() < model.time.end_time) {
    solver.step();
    worst_dp = std::max(worst_dp, norm(test::momentum(solver) - P0) / P0n);
    worst_pen = std::max(worst_pen, contact->stats().max_penetration);
    lowest_contact_energy = std::min(lowest_contact_energy, solver.energy().contact);
    if (contact->active_contacts() > 0) ++cycles_in_contact;
  }
  std::printf(
      "impact: %lld cycles, %lld in contact, dp %.3g, pen/h %.4f, energy error %.3g, sorts %lld\n",
      (long long)solver.cycle(), (long long)cycles_in_contact, worst_dp, worst_pen / h,
      solver.energy().error(), (long long)contact->stats().n_sorts);
  EXPECT_GT(cycles_in_contact, 10) << "the blocks never met";
  EXPECT_LT(worst_dp, 1e-6) << "relative momentum error";
  EXPECT_LT(worst_pen, 0.05 * h) << "largest penetration (m), element thickness " << h;
  EXPECT_LT(solver.energy().error(), 0.01) << "energy balance";
  EXPECT_EQ(contact->active_contacts(), 0) << "the blocks should have parted";
  const double v_rest = test::mean_of(solver, test::part_nodes(model.mesh, 0), 0, 1);
  EXPECT_LT(v_rest, -0.5 * v0) << "the resting block should carry most of the momentum away";
  EXPECT_GT(lowest_contact_energy, -1e-6 * ke0) << "contact forces did net work on the blocks (J)";
  const auto& en = solver.energy();
  EXPECT_LE(en.kinetic + en.internal + en.hourglass, ke0 * (1 + 1e-6));
  // The contact's own tally of damping work uses half-step velocities: 5 %.
  EXPECT_TRUE(test::near_rel(en.contact, contact->friction_dissipation(), 0.05))
      << "after parting, the interface energy is what the contact damping dissipated (J)";
}
