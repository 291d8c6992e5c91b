// Free vibration of an undamped elastic block: with no dissipation the total energy
// (kinetic + internal) must stay within 0.5 % of its initial value over 10 periods.
#include "tests/test_support.hpp"

using namespace ncfsim;

TEST(EnergyConservation, FreeVibrationOfUndampedBlock) {
  fem::Model model;
  const double H = 0.1, E = 70e9, rho = 2700, v0 = 0.5;
  test::add_elastic_block(model, "block", {0, 0, 0}, {H, H, H}, {4, 4, 4}, rho, E, 0.3);
  model.parts[0].hourglass_viscosity = 0.0;
  // Breathing mode: radial initial velocity about the centre.
  for (std::size_t i = 0; i < model.mesh.n_nodes(); ++i) {
    const auto p = model.mesh.node(i);
    model.initial_velocities.push_back(
        {{static_cast<std::int32_t>(i)},
         {v0 * (p[0] - H / 2) / H, v0 * (p[1] - H / 2) / H, v0 * (p[2] - H / 2) / H}});
  }
  // Fundamental breathing period of a free cube ~ 2H/c_p; run 10 of them (and more).
  const double cp = std::sqrt(E * 0.7 / (1.3 * 0.4) / rho);
  model.time.end_time = 10 * 2 * H / cp * 1.5;
  fem::ExplicitSolver solver(model);
  const double e0 = solver.energy().kinetic;
  double worst = 0;
  int sign_changes = 0;
  double last_ke_slope = 0, last_ke = e0;
  while (solver.time() < model.time.end_time) {
    solver.step([&] {
      const auto& en = solver.energy();
      worst = std::max(worst, std::abs(en.kinetic + en.internal - e0) / e0);
      const double slope = en.kinetic - last_ke;
      if (slope * last_ke_slope < 0) ++sign_changes;
      if (slope != 0) last_ke_slope = slope;
      last_ke = en.kinetic;
    });
  }
  EXPECT_GE(sign_changes, 20) << "expected at least 10 vibration periods";
  EXPECT_LT(worst, 0.005) << "largest relative drift of kinetic + internal energy";
  EXPECT_LT(solver.energy().error(), 0.005);
}
