// Block on an inclined deformable plate (analytic solution: Coulomb's sliding block). The plate
// lies flat and gravity is tilted by the incline angle theta, which is the same problem. Gravity
// is ramped in over 5 ms (quasi-static: the block's first mode is ~3 kHz), the plate's base is
// fixed, mu = 0.3 between block and plate.
//  * tan(theta) < mu: the block stays. After the ramp, the block's mean position along the slope
//    moves by less than 1 um over 20 ms (it would slide 0.5 m without friction).
//  * tan(theta) > mu: it slides with a = g (sin(theta) - mu cos(theta)) within 3 %, from a
//    least-squares fit of its mean velocity after the ramp.
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kMu = 0.3, kG = 9.81;

struct InclineRun {
  double slip = 0;          // block movement along the slope after the ramp, m
  double acceleration = 0;  // fitted, m/s^2
  double energy_error = 0;
  double dissipated = 0;
};

InclineRun run_incline(double theta_deg) {
  const double th = theta_deg * M_PI / 180;
  fem::Model model;
  test::add_elastic_block(model, "plate", {0, 0, 0}, {0.06, 0.03, 0.004}, {12, 6, 2}, 1000, 1e7,
                          0.3);
  test::add_elastic_block(model, "block", {0.01, 0.01, 0.004}, {0.01, 0.01, 0.01}, {2, 2, 2}, 1000,
                          1e7, 0.3);
  model.fixed.push_back({"base", test::nodes_at(model.mesh, 2, 0.0), {true, true, true}});
  fem::PenaltyContactConfig cfg;
  cfg.name = "incline";
  cfg.groups = {{"plate", {0}}, {"block", {1}}};
  cfg.pairs = {{1, 0, kMu}};
  auto* contact = test::add_contact<fem::PenaltyContact>(model, cfg);
  const double t_ramp = 5e-3, t_fit = 8e-3;
  model.time.end_time = 28e-3;
  fem::ExplicitSolver solver(model);
  test::add_ramped_gravity(solver, {kG * std::sin(th), 0, -kG * std::cos(th)}, t_ramp);
  const auto block = test::part_nodes(model.mesh, 1);
  double x_fit0 = 0;
  double st = 0, sv = 0, stt = 0, stv = 0;
  int n = 0;
  while (solver.time() < model.time.end_time) {
    solver.step([&] {
      const double t = solver.time();
      if (t < t_fit) return;
      if (n == 0) x_fit0 = test::mean_of(solver, block, 0, 0);
      // v is at t + dt/2 inside the callback.
      const double tv = t + 0.5 * solver.time_step(), vx = test::mean_of(solver, block, 0, 1);
      st += tv, sv += vx, stt += tv * tv, stv += tv * vx;
      ++n;
    });
  }
  InclineRun r;
  r.slip = test::mean_of(solver, block, 0, 0) - x_fit0;
  r.acceleration = (n * stv - st * sv) / (n * stt - st * st);
  r.energy_error = solver.energy().error();
  r.dissipated = contact->friction_dissipation();
  return r;
}

}  // namespace

TEST(ContactIncline, BelowFrictionAngleTheBlockStays) {
  const double theta = 10;  // tan = 0.176 < mu
  const InclineRun r = run_incline(theta);
  std::printf("incline %g deg: slip %.3g m, a %.4g m/s2, energy error %.3g\n", theta, r.slip,
              r.acceleration, r.energy_error);
  EXPECT_LT(std::abs(r.slip), 1e-6) << "movement along the slope after the ramp (m)";
  EXPECT_LT(r.energy_error, 0.01);
}

TEST(ContactIncline, AboveFrictionAngleTheBlockSlidesWithCoulombAcceleration) {
  const double theta = 30, th = theta * M_PI / 180;  // tan = 0.577 > mu
  const InclineRun r = run_incline(theta);
  const double a = kG * (std::sin(th) - kMu * std::cos(th));
  std::printf("incline %g deg: slip %.3g m, a %.4g m/s2 (analytic %.4g), energy error %.3g\n",
              theta, r.slip, r.acceleration, a, r.energy_error);
  EXPECT_TRUE(test::near_rel(r.acceleration, a, 0.03)) << "sliding acceleration (m/s^2)";
  EXPECT_GT(r.dissipated, 0.0);
  EXPECT_LT(r.energy_error, 0.01);
}

// Contact thickness (offset): a block placed 1 mm above the plate with thickness = 1 mm rests
// there under gravity (ramped in): its bottom stays 1 mm above the plate's top to within 1 % of
// the offset (the penalty compliance under the block's weight is ~1e-8 m).
TEST(ContactIncline, ContactThicknessKeepsTheBlockAtTheOffset) {
  fem::Model model;
  const double offset = 1e-3;
  test::add_elastic_block(model, "plate", {0, 0, 0}, {0.03, 0.03, 0.004}, {6, 6, 2}, 1000, 1e7,
                          0.3);
  test::add_elastic_block(model, "block", {0.01, 0.01, 0.004 + offset}, {0.01, 0.01, 0.01},
                          {2, 2, 2}, 1000, 1e7, 0.3);
  model.fixed.push_back({"base", test::nodes_at(model.mesh, 2, 0.0), {true, true, true}});
  fem::PenaltyContactConfig cfg;
  cfg.name = "offset";
  cfg.groups = {{"plate", {0}}, {"block", {1}}};
  cfg.pairs = {{1, 0, 0.3}};
  cfg.thickness = offset;
  auto* contact = test::add_contact<fem::PenaltyContact>(model, cfg);
  model.time.end_time = 15e-3;
  fem::ExplicitSolver solver(model);
  test::add_ramped_gravity(solver, {0, 0, -kG}, 5e-3);
  while (solver.time() < model.time.end_time) solver.step();
  const double gap =
      test::mean_of(solver, test::part_nodes_at(model.mesh, 1, 2, 0.004 + offset), 2, 0) -
      test::mean_of(solver, test::part_nodes_at(model.mesh, 0, 2, 0.004), 2, 0);
  std::printf("offset: gap %.6g m for thickness %.6g m, %lld contacts\n", gap, offset,
              static_cast<long long>(contact->active_contacts()));
  EXPECT_GT(contact->active_contacts(), 0);
  EXPECT_TRUE(test::near_rel(gap, offset, 0.01)) << "resting gap (m)";
  EXPECT_LT(solver.energy().error(), 0.01);
}
