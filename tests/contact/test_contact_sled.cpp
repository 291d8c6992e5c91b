// Friction sled of the NCF paper (Eq. 7, mu = F / P): a sled of tows (thin hex strips, one part
// per tow, self-contact between them) is pressed with a normal force P onto a plate of tows (fixed
// at its base, self-contact between its tows) and pulled along the plate's tows at 0.5 m/s. The
// coefficient recovered from the contact resultant on the sled, mu = F / P averaged while it
// slides, matches the input within 2 %, for sled tows parallel (0/0) and crossed (0/90) to the
// plate's. Tow seams of sled and plate do not line up.
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kMu = 0.25, kP = 20.0, kT = 1e-3;  // friction, normal force (N), tow thickness (m)

double recovered_mu(bool crossed, double& energy_error, double& slide) {
  fem::Model model;
  std::vector<int> plate, sled;
  const double rho = 1500, E = 1e8, nu = 0.3;
  // Plate: 4 tows along x, 40 x 5 x 1 mm, side by side.
  for (int k = 0; k < 4; ++k) {
    test::add_elastic_block(model, "plate_tow" + std::to_string(k), {0, 5e-3 * k, 0},
                            {40e-3, 5e-3, kT}, {16, 2, 1}, rho, E, nu);
    plate.push_back(k);
  }
  // Sled over x in [4, 20] mm, y in [2.5, 17.5] mm: 3 tows along x (0/0) or 4 tows along y (0/90).
  const int n_sled = crossed ? 4 : 3;
  for (int k = 0; k < n_sled; ++k) {
    const std::string name = "sled_tow" + std::to_string(k);
    if (crossed)
      test::add_elastic_block(model, name, {4e-3 + 4e-3 * k, 2.5e-3, kT}, {4e-3, 15e-3, kT},
                              {2, 6, 1}, rho, E, nu);
    else
      test::add_elastic_block(model, name, {4e-3, 2.5e-3 + 5e-3 * k, kT}, {16e-3, 5e-3, kT},
                              {8, 2, 1}, rho, E, nu);
    sled.push_back(4 + k);
  }
  model.fixed.push_back({"plate_base", test::nodes_at(model.mesh, 2, 0.0), {true, true, true}});
  const auto top = test::nodes_at(model.mesh, 2, 2 * kT);
  fem::NodalLoad press;
  press.name = "press";
  press.nodes = top;
  press.force_per_node = {0, 0, -kP / static_cast<double>(top.size())};
  press.ramp_time = 2e-3;
  model.loads.push_back(press);
  // Pull every node above the sliding face (the sled's top), as a sled is towed at its base.
  fem::PrescribedVelocity pull;
  pull.name = "pull";
  pull.nodes = top;
  pull.dofs = {true, false, false};
  pull.velocity = {0.5, 0, 0};
  pull.start_time = 3e-3;
  pull.ramp_time = 1e-3;
  model.velocities.push_back(pull);

  fem::PenaltyContactConfig cfg;
  cfg.name = "sled";
  cfg.groups = {{"sled", sled}, {"plate", plate}};
  cfg.pairs = {{0, 1, kMu}, {0, 0, 0.3}, {1, 1, 0.3}};
  auto* contact = test::add_contact<fem::PenaltyContact>(model, cfg);
  model.time.end_time = 13e-3;
  fem::ExplicitSolver solver(model);
  double sum_f = 0, sum_p = 0;
  int n = 0;
  const double x0 = test::mean_of(solver, test::part_nodes(model.mesh, sled[0]), 0, 0);
  while (solver.time() < model.time.end_time) {
    solver.step();
    if (solver.time() > 6e-3) {
      const fem::V3 F = contact->resultants()[0].force;  // on the sled, from the plate
      sum_f += -F.x;
      sum_p += F.z;
      ++n;
    }
  }
  EXPECT_GT(n, 100);
  EXPECT_TRUE(test::near_rel(sum_p / n, kP, 0.05)) << "mean normal force (N)";
  energy_error = solver.energy().error();
  slide = test::mean_of(solver, test::part_nodes(model.mesh, sled[0]), 0, 0) - x0;
  return sum_f / sum_p;
}

}  // namespace

TEST(ContactSled, ParallelTowsRecoverMuFromForceOverPressure) {
  double err = 0, slide = 0;
  const double mu = recovered_mu(false, err, slide);
  std::printf("sled 0/0: mu %.5f (input %.3f), slide %.3g m, energy error %.3g\n", mu, kMu, slide,
              err);
  EXPECT_TRUE(test::near_rel(mu, kMu, 0.02)) << "mu = F / P, 0/0";
  EXPECT_GT(slide, 3e-3) << "the sled should have slid (m)";
  EXPECT_LT(err, 0.01);
}

TEST(ContactSled, CrossedTowsRecoverMuFromForceOverPressure) {
  double err = 0, slide = 0;
  const double mu = recovered_mu(true, err, slide);
  std::printf("sled 0/90: mu %.5f (input %.3f), slide %.3g m, energy error %.3g\n", mu, kMu, slide,
              err);
  EXPECT_TRUE(test::near_rel(mu, kMu, 0.02)) << "mu = F / P, 0/90";
  EXPECT_GT(slide, 3e-3) << "the sled should have slid (m)";
  EXPECT_LT(err, 0.01);
}
