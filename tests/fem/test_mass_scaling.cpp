// Dynamic mass scaling (time.mass_scaling_dynamic; issue #41): the column of test_erosion.cpp
// (two cubes of side h, the lower one crushed at speed v between its fixed base and its top face,
// which stays a box in uniaxial strain) with the target step at the initial one, dt0 = sf h / c.
// The lower cube's step is sf h_A / c' with h_A = h - v t and c' = sqrt(3K / rho'), so whenever it
// falls below dt0 its density must become rho (1.05 h / h_A)^2 at that moment. Checked:
//  * the step never falls more than one cycle's shrinking below the target (0.5 %), and no
//    element is eroded for its step although the cube is crushed to 30 % of its height, past the
//    erosion ratio of 0.5 that erodes it without scaling (test_erosion.cpp);
//  * the lower cube's density lies between rho (h / h_A)^2 and rho (1.05 h / h_A)^2 at the end;
//  * the mass reported for the part is the density's increase times the reference volume (1e-12),
//    and the nodal masses hold it (their sum: physical plus added, 1e-12);
//  * the energy balance stays closed (a free node gaining mass keeps its kinetic energy; the
//    middle plane, held at v, gets its added mass's kinetic energy from the fixture, booked as
//    external work): the imbalance below 2e-5 of the internal energy (measured 7.7e-6 with the
//    lower cube's mass raised elevenfold: what remains is the product-form
//    kinetic energy 1/2 m v^{n-1/2} v^{n+1/2} across a cycle whose v^{n-1/2} was scaled; 4e-5
//    if the held nodes' kinetic energy is not booked, 6e-4 if no velocity is scaled).
#include "fem/elements/hex8_block.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {
constexpr double kH = 0.01, kRho = 1000, kE = 1e6, kNu = 0.3, kV = 0.05;

// The column with dynamic mass scaling to its initial step dt0 (returned), crushed to 30 % of
// the lower cube's height, each hexahedron's added mass capped at max_added_ratio.
double scaled_column(fem::Model& model, double max_added_ratio) {
  test::add_crushed_column(model, kH, kRho, kE, kNu, kV);
  const double c = std::sqrt(kE / (1 - 2 * kNu) / kRho);  // the step's modulus 3K
  const double sf = 0.9, dt0 = sf * kH / c;
  model.time.safety_factor = sf;
  model.time.end_time = 0.7 * kH / kV;
  model.time.mass_scaling_dt = dt0 * (1 + 1e-12);  // nothing to scale at the start
  model.time.mass_scaling_dynamic = true;
  model.time.mass_scaling_max_ratio = max_added_ratio;
  return dt0;
}

// The densities of the lower (crushed) and upper cube at the end.
struct ColumnDensities {
  double lower = 0, upper = 0;
};
ColumnDensities column_densities(const fem::Model& model, const fem::Hex8Block& b) {
  ColumnDensities d;
  for (std::size_t e = 0; e < b.n; ++e) {
    double z = 0;
    for (int I = 0; I < 8; ++I)
      z += model.mesh.coords[3 * static_cast<std::size_t>(b.conn[I * b.n + e]) + 2] / 8;
    (z < kH ? d.lower : d.upper) = b.density[e];
  }
  return d;
}

// The balance closed: the imbalance below 2e-5 of the internal energy.
void expect_balance_closed(const fem::ExplicitSolver& solver) {
  const auto& en = solver.energy();
  EXPECT_LT(std::abs(en.total() - en.initial_total - en.external_work), 2e-5 * en.internal)
      << "internal " << en.internal;
}
}  // namespace

TEST(DynamicMassScaling, CrushedElementKeepsTheTargetStepWithTheMassItNeeds) {
  fem::Model model;
  const double dt0 = scaled_column(model, 1e3);  // the cap out of reach (the next tests)
  model.time.erosion_step_ratio = 0.5;

  fem::ExplicitSolver solver(model);
  ASSERT_TRUE(test::near_rel(solver.time_step(), dt0, 1e-9));
  EXPECT_LT(solver.part_masses()[0].added_mass, 1e-10 * kRho * kH * kH * kH);
  double smallest = 1e300;
  while (solver.time() < model.time.end_time) {
    solver.step();
    smallest = std::min(smallest, solver.time_step());
  }
  EXPECT_TRUE(solver.erosions().empty()) << solver.erosions().size() << " eroded";
  EXPECT_GT(solver.mass_scaling_events(), 10);
  EXPECT_GT(smallest, 0.995 * dt0);

  const auto& b = solver.blocks<fem::Hex8Block>().at(0);
  const double h_a = kH - kV * solver.time();
  const double ratio = column_densities(model, b).lower / kRho;
  EXPECT_GE(ratio, std::pow(kH / h_a, 2) * (1 - 1e-9));
  EXPECT_LE(ratio, std::pow(1.05 * kH / h_a, 2) * (1 + 1e-9));
  double added = 0;
  for (std::size_t e = 0; e < b.n; ++e) added += (b.density[e] - kRho) * b.volume0[e];
  EXPECT_TRUE(test::near_rel(solver.part_masses()[0].added_mass, added, 1e-12));
  double nodal = 0;
  {
    auto M = solver.mass.view();
    for (std::size_t i = 0; i < model.mesh.n_nodes(); ++i) nodal += M[3 * i];
  }
  EXPECT_TRUE(test::near_rel(nodal, 2 * kRho * kH * kH * kH + added, 1e-12));
  expect_balance_closed(solver);
}

// The cap on added mass (time.mass_scaling_max_ratio = 3): the lower cube is scaled as above
// until its density reaches 4 rho (when (1.05 h / h_A)^2 passes 4, h_A < 0.525 h); from there it
// keeps 4 rho and its own step, dt0 (h_A / h) sqrt(4), which falls with the crush: at 30 % of
// its height 0.6 dt0 (the erosion ratio 0.2 below it, nothing eroded). Reported as one capped
// hexahedron; the balance stays closed. (The upper cube, launched by the middle plane, dips
// below the target once and gets its 5 % headroom: 1.05^2 rho.)
TEST(DynamicMassScaling, ElementAtTheCapKeepsItsMassAndItsOwnStep) {
  fem::Model model;
  const double dt0 = scaled_column(model, 3.0);
  model.time.erosion_step_ratio = 0.2;

  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  EXPECT_TRUE(solver.erosions().empty()) << solver.erosions().size() << " eroded";
  EXPECT_EQ(solver.mass_scaling_capped(), 1);

  const auto& b = solver.blocks<fem::Hex8Block>().at(0);
  const double h_a = kH - kV * solver.time();
  const auto [lower_density, upper_density] = column_densities(model, b);
  EXPECT_TRUE(test::near_rel(lower_density, 4 * kRho, 1e-12)) << lower_density / kRho;
  EXPECT_LT(upper_density, 1.11 * kRho);
  // Its own step at the end: 2 dt0 h_A / h, within one cycle's shrinking (0.5 %).
  EXPECT_TRUE(test::near_rel(solver.time_step(), 2 * dt0 * h_a / kH, 5e-3))
      << solver.time_step() / dt0 << " dt0, expected " << 2 * h_a / kH;
  EXPECT_TRUE(test::near_rel(solver.part_masses()[0].added_mass,
                             (lower_density + upper_density - 2 * kRho) * kH * kH * kH, 1e-12));
  expect_balance_closed(solver);
}

// time.mass_scaling_erode_at_cap: the lower cube reaches the cap (4 rho) at h_A = 0.525 h with
// 5 % headroom, its own step 2 dt0 h_A / h then falls below the target at h_A = h / 2, and there
// it is eroded (cause MassCap), at t = h / (2 v) within a cycle; the step never falls more than a
// cycle's shrinking below the target.
TEST(DynamicMassScaling, ElementAtTheCapIsErodedWhenItsStepFallsBelowTheTargetIfAsked) {
  fem::Model model;
  const double dt0 = scaled_column(model, 3.0);
  model.time.mass_scaling_erode_at_cap = true;

  fem::ExplicitSolver solver(model);
  double smallest = 1e300;
  while (solver.time() < model.time.end_time) {
    solver.step();
    smallest = std::min(smallest, solver.time_step());
  }
  ASSERT_EQ(solver.erosions().size(), 1u);
  const auto& ev = solver.erosions().front();
  EXPECT_EQ(ev.cause, fem::ErosionEvent::Cause::MassCap);
  EXPECT_LT(ev.centroid.z, kH) << "the lower cube";
  EXPECT_NEAR(ev.time, 0.5 * kH / kV, 2 * dt0) << "h_A = h / 2";
  EXPECT_GT(smallest, 0.995 * dt0);
}

// A step a rounding below the target is at the target (kMassScalingBelowShare): the column at
// rest with the target 1e-12 above its step. Before, every cycle's scan gave both cubes 10 %
// more mass (the headroom) for nothing: on the paper model most of its tows, scaled statically to
// the target, sat one rounding under it in the kernel's arithmetic.
TEST(DynamicMassScaling, StepARoundingBelowTheTargetGetsNoMass) {
  fem::Model model;
  test::add_crushed_column(model, kH, kRho, kE, kNu, 0.0);
  const double c = std::sqrt(kE / (1 - 2 * kNu) / kRho);
  const double sf = 0.9, dt0 = sf * kH / c;
  model.time.safety_factor = sf;
  model.time.end_time = 200 * dt0;
  model.time.mass_scaling_dt = dt0 * (1 + 1e-12);
  model.time.mass_scaling_dynamic = true;
  model.time.mass_scaling_erode_at_cap = true;
  fem::ExplicitSolver solver(model);
  const double static_added = solver.part_masses()[0].added_mass;  // the 1e-12 of the start
  while (solver.time() < model.time.end_time) solver.step();
  EXPECT_EQ(solver.mass_scaling_events(), 0);
  EXPECT_EQ(solver.part_masses()[0].added_mass, static_added);
  EXPECT_TRUE(solver.erosions().empty());
}
