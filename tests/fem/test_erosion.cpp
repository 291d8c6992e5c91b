// Erosion of distorted hexahedra (time.erosion_step_ratio: LS-DYNA's ERODE with DTMIN, and folded
// corners as its PSFAIL). A column of two cubes (side h): the lower one is crushed between its
// fixed base and its top face, driven down at speed v; the upper one rides on it. The lower cube
// stays a box (uniaxial strain), so its stable step is sf h_A / c with h_A = h - v t, and it must
// be eroded when h_A / h falls below the ratio r, at t_e = (1 - r) h / v (within a step). Then:
//  * the base carries nothing: its reaction is exactly zero (the eroded cube was all that held it);
//  * the step comes back to the upper cube's, sf h / c;
//  * the elastic energy it held when eroded is 1/2 (lambda + 2 mu) E_zz^2 V0 with E_zz the
//    Green-Lagrange strain (h_A^2/h^2 - 1)/2 (the law is linear in E), to 1e-9, and the same
//    energy (within 1 %) is in the internal energy, which keeps it; the balance stays closed
//    (the erosion moves it by less than 1e-6 of that energy).
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {
constexpr double kH = 0.01, kRho = 1000, kE = 1e6, kNu = 0.3, kV = 0.05, kRatio = 0.5;
}  // namespace

TEST(HexErosion, CrushedElementIsErodedAtTheStepRatio) {
  fem::Model model;
  const auto base = test::add_crushed_column(model, kH, kRho, kE, kNu, kV);
  model.time.end_time = 1.0;
  model.time.erosion_step_ratio = kRatio;

  fem::ExplicitSolver solver(model);
  const double sf = model.time.safety_factor, dt0 = solver.time_step();
  const double M = kE * (1 - kNu) / ((1 + kNu) * (1 - 2 * kNu));  // lambda + 2 mu
  const double c = std::sqrt(kE / (1 - 2 * kNu) / kRho);          // the step's modulus 3K
  ASSERT_TRUE(test::near_rel(dt0, sf * kH / c, 1e-12));
  const double t_e = (1 - kRatio) * kH / kV;
  auto imbalance = [&] {  // E - E0 - W, J
    const auto& en = solver.energy();
    return en.total() - en.initial_total - en.external_work;
  };
  double internal_before = 0, reaction_before = 0, t_before = 0, imbalance_before = 0;
  while (solver.erosions().empty() && solver.time() < 2 * t_e) {
    solver.step([&] {
      if (!solver.erosions().empty()) return;
      internal_before = solver.energy().internal;
      reaction_before = solver.reaction_force(base).z;
      t_before = solver.time();
      imbalance_before = imbalance();
    });
  }
  ASSERT_EQ(solver.erosions().size(), 1u)
      << "the crushed cube was not eroded by t = " << solver.time();
  const auto& ev = solver.erosions()[0];
  EXPECT_EQ(ev.element, model.mesh.elements(fem::ElementKind::Hex8).user_id[0]);
  EXPECT_NEAR(ev.time, t_e, 2 * dt0) << "eroded when h_A / h = " << 1 - kV * ev.time / kH;
  EXPECT_LT(ev.step, kRatio * dt0);
  EXPECT_GT(std::abs(reaction_before), 0.1 * M * kH * kH) << "the base carried the crushing force";

  // Its elastic energy at erosion, from the position of the crushed face then.
  const double hA = kH - kV * ev.time, Ezz = 0.5 * (hA * hA / (kH * kH) - 1);
  const double w = 0.5 * M * Ezz * Ezz * kH * kH * kH;
  EXPECT_TRUE(test::near_rel(solver.energy().eroded_internal, w, 1e-9));
  EXPECT_TRUE(test::near_rel(internal_before, w, 0.01)) << "t " << t_before;

  for (int k = 0; k < 200; ++k) solver.step();
  const fem::V3 r = solver.reaction_force(base);
  EXPECT_EQ(r.x, 0.0);
  EXPECT_EQ(r.y, 0.0);
  EXPECT_EQ(r.z, 0.0);
  EXPECT_TRUE(test::near_rel(solver.time_step(), sf * kH / c, 1e-3))
      << "the step is the upper cube's again";
  EXPECT_EQ(solver.erosions().size(), 1u);
  EXPECT_LT(solver.energy().error(), 1e-3);
  // The force the cube still exerted when eroded does work over the first half of the next
  // increment in the trapezoidal external work; the solver books that half as the cube's: the
  // erosion itself leaves the balance as it was (without, it would move by ~6e-4 of w here).
  EXPECT_LT(std::abs(imbalance() - imbalance_before), 1e-6 * w);
}

// A corner folded over: one top corner of a cube (the others held) is driven down through the
// plane of the base. The one-point volume stays positive (7/8 of the cube's when the corner reaches
// the base) and the step hardly changes, but the corner Jacobian at that corner and at the base
// corner below it is h_corner a^2 and vanishes when the corner reaches the base, at t_f = h / v;
// the element must be eroded for its folded corner within the 50 cycles between searches.
TEST(HexErosion, FoldedCornerIsEroded) {
  fem::Model model;
  test::add_elastic_block(model, "cube", {0, 0, 0}, {kH, kH, kH}, {1, 1, 1}, kRho, kE, kNu);
  model.parts[0].hourglass_viscosity = 0.0;
  const auto corner = test::nodes_where(model.mesh, [](double x, double y, double z) {
    return x < 1e-9 && y < 1e-9 && z > 0.5 * kH;
  });
  ASSERT_EQ(corner.size(), 1u);
  std::vector<std::int32_t> others;
  for (std::int32_t i = 0; i < static_cast<std::int32_t>(model.mesh.n_nodes()); ++i)
    if (i != corner[0]) others.push_back(i);
  model.fixed.push_back({"held", others, {true, true, true}});
  fem::PrescribedVelocity pv;
  pv.name = "fold";
  pv.nodes = corner;
  pv.dofs = {true, true, true};
  pv.velocity = {0, 0, -10 * kV};
  model.velocities.push_back(pv);
  model.time.end_time = 1.0;
  model.time.erosion_step_ratio = 0.1;
  fem::ExplicitSolver solver(model);
  const double t_f = kH / (10 * kV);
  while (solver.erosions().empty() && solver.time() < 2 * t_f) solver.step();
  ASSERT_EQ(solver.erosions().size(), 1u);
  const auto& ev = solver.erosions()[0];
  EXPECT_EQ(ev.cause, fem::ErosionEvent::Cause::InvertedCorner);
  EXPECT_GE(ev.time, t_f * (1 - 1e-9));
  EXPECT_LE(ev.time, t_f + 51 * solver.time_step());
  EXPECT_GT(ev.step, 0.1 * solver.time_step()) << "the step criterion must not be what fired";
}

// Nodes left with no element. A cube (side h) on a fixed base is pressed on its top face by a
// force ramped past the largest the (Saint Venant-Kirchhoff) cube can carry, about 0.19 (lambda +
// 2 mu) h^2 at a stretch of 1/sqrt(3): it collapses, and once its step falls to half the initial
// one it is eroded and its four top nodes belong to no element. They must be taken out as
// LS-DYNA deletes them: held where they are although the load still pushes them (an orphan node
// flies on and hits the tools with forces from nothing: here a rigid floor at 0.3 h, which they
// would reach), out of the floor's contact (its force stays exactly zero), their kinetic energy
// at that moment, sum 1/2 m_i v_i^2 of the last half-step velocities, booked as eroded kinetic
// energy (within 15 %: the exact figure is the work of the holding reaction, in the product form
// of central differences, 1/2 m v^{n-1/2} v^{n+1/2} with the velocity the node, accelerating
// under the load, would have had half a step later), and the balance still closed (< 1e-3). The
// fixed base nodes stay.
TEST(HexErosion, NodesLeftWithNoElementAreTakenOut) {
  fem::Model model;
  test::add_elastic_block(model, "cube", {0, 0, 0}, {kH, kH, kH}, {1, 1, 1}, kRho, kE, kNu);
  model.parts[0].hourglass_viscosity = 0.0;
  const auto base = test::nodes_at(model.mesh, 2, 0.0), top = test::nodes_at(model.mesh, 2, kH);
  model.fixed.push_back({"base", base, {true, true, true}});
  const double M = kE * (1 - kNu) / ((1 + kNu) * (1 - 2 * kNu));  // lambda + 2 mu
  fem::NodalLoad press;
  press.nodes = top;
  press.force_per_node = {0, 0, -0.4 * M * kH * kH / 4};  // twice the collapse force
  press.ramp_time = 0.02;
  model.loads.push_back(press);
  test::add_rigid_plane(model, "floor", {0, 0, 0.3 * kH}, {0, 0, 1}, top);
  model.time.end_time = 1.0;
  model.time.erosion_step_ratio = kRatio;
  fem::ExplicitSolver solver(model);
  double ke_top = 0;  // sum 1/2 m v^2 over the top nodes at the last cycle before erosion
  while (solver.erosions().empty() && solver.time() < press.ramp_time)
    solver.step([&] {
      if (!solver.erosions().empty()) return;
      auto V = solver.v.view();
      auto M = solver.mass.view();
      ke_top = 0;
      for (auto i : top)
        for (std::size_t c = 0; c < 3; ++c) {
          const std::size_t d = 3 * static_cast<std::size_t>(i) + c;
          ke_top += 0.5 * M[d] * V[d] * V[d];
        }
    });
  ASSERT_EQ(solver.erosions().size(), 1u) << "the cube did not collapse to the step ratio";
  EXPECT_GT(solver.cycle(), 20) << "collapsed too fast to resolve";
  EXPECT_EQ(solver.n_freed_nodes(), 4u);
  EXPECT_GT(ke_top, 0.0) << "the top still moves";
  EXPECT_TRUE(test::near_rel(solver.energy().eroded_kinetic, ke_top, 0.15));
  EXPECT_TRUE(solver.model().tools[0].contact_nodes.empty());
  std::vector<double> x_then;
  {
    auto X = solver.x.view();
    x_then.assign(X.data(), X.data() + 24);
  }
  for (int k = 0; k < 1000; ++k) solver.step();
  auto X = solver.x.view();
  for (std::size_t d = 0; d < 24; ++d) EXPECT_EQ(X[d], x_then[d]) << "dof " << d;
  EXPECT_EQ(solver.model().tools[0].force.z, 0.0);
  EXPECT_EQ(solver.energy().kinetic, 0.0);
  EXPECT_LT(solver.energy().error(), 1e-3);
}
