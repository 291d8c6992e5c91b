// A tool's speed profile (velocity_curve_time / velocity_curve_scale, fem/rigid_tool.hpp): the
// velocity is `velocity` x the C1 ramp x the curve, linear between its points and held past them.
// Its travel is the integral, in closed form here: a ramp of T at scale s0 covers s0 v T / 2, a
// linear piece (a + b) / 2 v dt. The solver's tool, stepped on it, ends within a hundredth of one
// step's travel of that: it advances on the velocity at each half step, the midpoint rule, exact
// for a linear speed and off by O(dt^2) at the profile's kinks only (1.1e-7 m against 7.2e-7).
#include <cmath>

#include "fem/rigid_tool.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kV = 0.8, kRamp = 2e-3, kSlowEnd = 10e-3, kFast = 12e-3;

fem::ToolMotion slow_then_fast() {
  fem::ToolMotion m;
  m.kind = fem::ToolMotion::Kind::Velocity;
  m.velocity = {0, 0, kV};
  m.ramp_time = kRamp;
  m.curve_time = {0.0, kSlowEnd, kFast};
  m.curve_scale = {0.3, 0.3, 1.0};
  return m;
}

// The closed form: ramp at 0.3, 0.3 to 10 ms, 0.3 -> 1 linearly to 12 ms, 1 after.
double travel_closed_form(double t) {
  if (t <= kRamp) {
    const double s = t / kRamp;  // integral of s^2 (3 - 2 s): T (s^3 - s^4 / 2)
    return 0.3 * kV * kRamp * (s * s * s - 0.5 * s * s * s * s);
  }
  double d = 0.3 * kV * kRamp / 2;
  d += 0.3 * kV * (std::min(t, kSlowEnd) - kRamp);
  if (t > kSlowEnd) {
    const double u = std::min(t, kFast) - kSlowEnd;
    const double scale_u = 0.3 + 0.7 * u / (kFast - kSlowEnd);
    d += kV * 0.5 * (0.3 + scale_u) * u;
  }
  if (t > kFast) d += kV * (t - kFast);
  return d;
}

}  // namespace

TEST(ToolVelocityCurve, ScaleIsLinearBetweenItsPointsAndHeldPastThem) {
  const fem::ToolMotion m = slow_then_fast();
  EXPECT_DOUBLE_EQ(fem::tool_velocity_scale(m, -1.0), 0.3);
  EXPECT_DOUBLE_EQ(fem::tool_velocity_scale(m, 5e-3), 0.3);
  EXPECT_NEAR(fem::tool_velocity_scale(m, 11e-3), 0.65, 1e-14);
  EXPECT_DOUBLE_EQ(fem::tool_velocity_scale(m, 1.0), 1.0);
  fem::ToolMotion none;
  EXPECT_DOUBLE_EQ(fem::tool_velocity_scale(none, 3e-3), 1.0);
}

TEST(ToolVelocityCurve, TravelIsTheSpeedProfilesIntegral) {
  fem::RigidTool tool;
  tool.motion = slow_then_fast();
  for (const double t : {0.5e-3, 2e-3, 7e-3, 10e-3, 11e-3, 12e-3, 20e-3})
    EXPECT_NEAR(fem::tool_prescribed_travel(tool, t), travel_closed_form(t), 1e-12 * kV) << t;
  EXPECT_DOUBLE_EQ(fem::tool_prescribed_travel(tool, 0.0), 0.0);
  const fem::V3 v = fem::tool_prescribed_velocity(tool, 11e-3);
  EXPECT_NEAR(v.z, 0.65 * kV, 1e-14);
}

TEST(ToolVelocityCurve, TheSolversToolFollowsTheProfile) {
  fem::Model model;
  test::add_elastic_block(model, "block", {0, 0, 0.05}, {0.01, 0.01, 0.01}, {2, 2, 2}, 1000, 1e6,
                          0.3);
  fem::RigidTool& plane = test::add_rigid_plane(model, "plane", {0, 0, 0}, {0, 0, 1},
                                                test::nodes_at(model.mesh, 2, 0.05));
  plane.motion = slow_then_fast();
  model.time.end_time = 20e-3;
  fem::ExplicitSolver solver(model);
  double dt_max = 0;
  while (solver.time() < model.time.end_time) {
    solver.step();
    dt_max = std::max(dt_max, solver.time_step());
  }
  const double expected = travel_closed_form(solver.time());
  EXPECT_NEAR(solver.model().tools[0].displacement.z, expected, 0.01 * kV * dt_max)
      << "the tool's travel against the profile's integral (" << expected << " m)";
  EXPECT_NEAR(solver.model().tools[0].velocity.z, kV, 1e-12);
}
