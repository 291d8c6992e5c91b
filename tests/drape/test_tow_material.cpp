// The dry-tow law (paper Eq. 1 plus nonlinear compaction): stress of a fibre strain is
// (E11f + C_m11) E11; the compaction stress has zero initial slope, a tangent E_c/(1-r)^2 equal to
// the numerical derivative, and locks (tangent capped) near the locking width; the law is path
// independent; a single hexahedron compacted across the tow in uniaxial strain reproduces the law
// through the whole engine (Cauchy stress from S, exact volume) within 0.5 %. With E11f_axial a
// tow strip stretches with it and bends with E11f (beam theory, 5 %); the element step estimate
// stays below the critical step of a compacted, sheared tow element (finite-difference tangent).
#include <gtest/gtest.h>

#include <cmath>
#include <utility>
#include <vector>

#include "drape/tow_material.hpp"
#include "fem/solver.hpp"
#include "tests/hex8_critical_step.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {
drape::TowConstants paper_tow() {
  drape::TowConstants c;
  c.density = 1080;
  c.E11f = 0.07e9;  // the paper's bending-calibrated fibre modulus
  c.E11m = 1e6, c.E22m = 1e6, c.E33m = 1e6;
  c.nu12m = 0.0, c.nu13m = 0.0, c.nu23m = 0.0;
  c.G12m = 0.2e6, c.G13m = 0.2e6, c.G23m = 0.2e6;
  c.compaction_modulus = 2e6;
  c.locking_width_ratio = 0.7;
  c.lock_stiffness_ratio = 50;
  return c;
}

std::array<double, 6> stress_after(const drape::TowMaterial& m, const std::vector<std::array<double, 6>>& increments) {
  std::array<double, 6> sig{}, hist{};
  for (const auto& d : increments) {
    fem::MaterialBatch b;
    b.n = 1, b.stride = 1, b.strain_stride = 1;
    b.strain_increment = d.data();
    b.stress = sig.data();
    b.history = hist.data();
    m.update_stress(b);
  }
  return sig;
}
}  // namespace

TEST(TowMaterial, FibreAndMatrixPhasesAdd) {
  const drape::TowMaterial m("tow", paper_tow());
  const auto s = stress_after(m, {{1e-3, 0, 0, 0, 0, 0}});
  EXPECT_NEAR(s[0], (0.07e9 + 1e6) * 1e-3, 1e-9 * s[0]);
  EXPECT_NEAR(s[1], 0.0, 1e-9);
  const auto g = stress_after(m, {{0, 0, 0, 2e-3, 0, 0}});
  EXPECT_NEAR(g[3], 0.2e6 * 2e-3, 1e-9);
  // Measured by the spacing of the fibre sheets, a shear also brings them closer (by cos): a
  // second-order compaction, ~1e-10 of the stress here.
  auto c = paper_tow();
  c.compaction_of_fibre_sheets = true;
  const auto gs = stress_after(drape::TowMaterial("tow", c), {{0, 0, 0, 2e-3, 0, 0}});
  EXPECT_NEAR(gs[3], 0.2e6 * 2e-3, 1e-6 * 0.2e6 * 2e-3);
}

TEST(TowMaterial, CompactionIsTheSpacingOfTheFibreSheets) {
  // The fibres rotating against the transverse material line (u2 = k X1) pack the fibre sheets to
  // 1/sqrt(1 + k^2) of their spacing with E22 = 0: the law sees it as that compaction. The
  // fibres sliding along each other (u1 = k X2) stretch the transverse line (E22 = k^2/2) but
  // leave the spacing: no compaction stress.
  drape::TowConstants c = paper_tow();
  c.compaction_of_fibre_sheets = true;
  const drape::TowMaterial m("tow", c);
  const double k = 0.6;
  const auto rot = stress_after(m, {{0.5 * k * k, 0, 0, k, 0, 0}});
  const double E_sheet = 0.5 * (1.0 / (1 + k * k) - 1);
  ASSERT_LT(E_sheet, -0.4 * m.locking_strain());
  const double C21 = m.elastic_stiffness()[6];
  EXPECT_NEAR(rot[1], C21 * 0.5 * k * k + m.compaction_stress(E_sheet), 1e-9 * std::abs(m.compaction_stress(E_sheet)));
  const auto slide = stress_after(m, {{0, 0.5 * k * k, 0, k, 0, 0}});
  EXPECT_NEAR(slide[1], m.elastic_stiffness()[7] * 0.5 * k * k, 1e-9 * m.elastic_stiffness()[7]);
  // The default measure (E22) misses the trellising compaction.
  const auto rot_e22 = stress_after(drape::TowMaterial("tow", paper_tow()), {{0.5 * k * k, 0, 0, k, 0, 0}});
  EXPECT_NEAR(rot_e22[1], C21 * 0.5 * k * k, 1e-9);
  // Hyperelastic: the stress is the gradient of the compaction energy (numerical check of S12).
  const auto measure = drape::TowMaterial::compaction_measure;
  std::array<double, 6> E{0.5 * k * k, 0, 0, k, 0, 0};
  auto energy = [&](const std::array<double, 6>& e) {  // W = int s_c dE2 along E2, numerically
    const double target = measure(e.data()).E2;
    double W = 0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) W += m.compaction_stress(target * (i + 0.5) / n) * target / n;
    return W;
  };
  const double h = 1e-6;
  auto Ep = E, Em = E;
  Ep[3] += h, Em[3] -= h;
  const double dW = (energy(Ep) - energy(Em)) / (2 * h);  // dW/d(gamma12) = S12
  const double S12_comp = rot[3] - m.elastic_stiffness()[21] * k;
  EXPECT_NEAR(S12_comp, dW, 1e-4 * std::abs(dW));
}

TEST(TowMaterial, CompactionStiffensAndLocks) {
  const drape::TowMaterial m("tow", paper_tow());
  const double el = m.locking_strain();
  EXPECT_NEAR(el, 0.5 * (1 - 0.49), 1e-12);
  EXPECT_EQ(m.compaction_stress(1e-3), 0.0) << "no compaction stress in tension";
  EXPECT_LT(m.compaction_tangent(-1e-9) / 2e6, 1e-7) << "zero initial slope";
  double prev_tangent = -1;
  for (double r = 0.05; r < 1.2; r += 0.05) {
    const double E = -r * el, h = 1e-7 * el;
    const double numeric = -(m.compaction_stress(E - h) - m.compaction_stress(E + h)) / (2 * h);
    EXPECT_NEAR(m.compaction_tangent(E), numeric, 1e-5 * (1 + numeric)) << "r = " << r;
    EXPECT_GE(m.compaction_tangent(E), prev_tangent) << "tangent must not fall as the tow compacts";
    prev_tangent = m.compaction_tangent(E);
  }
  EXPECT_NEAR(m.compaction_tangent(-1.1 * el), 2e6 * (50 - 1), 1e-6 * 2e6 * 50) << "capped past the lock";
  // The stable step sees the capped stiffness.
  EXPECT_NEAR(m.stable_step_stiffness()[7], m.elastic_stiffness()[7] + 2e6 * 49, 1.0);
}

TEST(TowMaterial, PathIndependent) {
  const drape::TowMaterial m("tow", paper_tow());
  std::vector<std::array<double, 6>> path;
  for (int i = 0; i < 50; ++i) path.push_back({1e-5, -4e-3, -1e-3, 1e-4, 0, 0});
  for (int i = 0; i < 30; ++i) path.push_back({0, 3e-3, 0, -1e-4, 0, 0});
  const auto a = stress_after(m, path);
  std::array<double, 6> total{};
  for (const auto& d : path)
    for (int k = 0; k < 6; ++k) total[static_cast<std::size_t>(k)] += d[static_cast<std::size_t>(k)];
  const auto b = stress_after(m, {total});
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(a[static_cast<std::size_t>(k)], b[static_cast<std::size_t>(k)], 1e-9 * (1 + std::abs(b[static_cast<std::size_t>(k)])));
}

TEST(TowMaterial, SingleHexCompactionMatchesTheLaw) {
  // One tow element 1 x 1 x 0.25 mm, fibres along x, compacted along y to 60 % of the locking
  // strain in uniaxial strain (x and z held), slowly (quasi-static).
  fem::Model model;
  const int p = model.mesh.add_part("tow");
  fem::add_hex_block(model.mesh, p, {0, 0, 0}, {1e-3, 1e-3, 0.25e-3}, {1, 1, 1});
  auto c = paper_tow();
  model.materials.push_back(std::make_unique<drape::TowMaterial>("tow", c));
  model.parts.resize(1);
  model.parts[0].material = 0;
  const auto* mat = static_cast<const drape::TowMaterial*>(model.materials[0].get());
  fem::FixedDofs hold;
  hold.name = "hold";
  hold.nodes = test::nodes_where(model.mesh, [](double, double, double) { return true; });
  hold.dofs = {true, false, true};
  model.fixed.push_back(hold);
  fem::FixedDofs base;
  base.name = "base";
  base.nodes = test::nodes_at(model.mesh, 1, 0.0);
  model.fixed.push_back(base);
  const double target_E = -0.6 * mat->locking_strain();  // Green-Lagrange
  const double stretch = std::sqrt(1 + 2 * target_E);     // lambda_y
  const double T = 0.02;
  fem::PrescribedVelocity push;
  push.name = "push";
  push.nodes = test::nodes_at(model.mesh, 1, 1e-3);
  push.dofs = {false, true, false};
  push.velocity = {0, (stretch - 1) * 1e-3 / T, 0};
  model.velocities.push_back(push);
  model.mass_damping = 2000;
  model.time.end_time = T;
  fem::ExplicitSolver solver(model);
  while (solver.time() < T) solver.step();
  const double ly = test::node_coord(solver, push.nodes[0], 1);
  const double lam = ly / 1e-3, E = 0.5 * (lam * lam - 1);
  const double S22 = mat->elastic_stiffness()[7] * E + mat->compaction_stress(E);
  // Cauchy sigma_22 = lam^2 S22 / lam; force = sigma_22 * area (x-z face, unchanged).
  const double expected = lam * S22 * 1e-3 * 0.25e-3;
  const double reaction = solver.reaction_force(push.nodes).y;
  EXPECT_NEAR(-reaction, -expected, 0.005 * std::abs(expected)) << "E22 = " << E;
  EXPECT_LT(E, -0.5 * mat->locking_strain());
}

namespace {
// A tow strip 20 x 2 x 0.5 mm (one hexahedron through the thickness, 20 along), fibres along x,
// clamped at x = 0, a tip force (x: pull, z: bend), settled by mass damping; tip displacement.
double tow_strip_tip(const drape::TowConstants& c, int axis, double force) {
  fem::Model model;
  const double L = 20e-3, w = 2e-3, h = 0.5e-3;
  const int p = model.mesh.add_part("tow");
  fem::add_hex_block(model.mesh, p, {0, 0, 0}, {L, w, h}, {20, 2, 1});
  model.materials.push_back(std::make_unique<drape::TowMaterial>("tow", c));
  model.parts.resize(1);
  model.parts[0].material = 0;
  fem::FixedDofs root;
  root.name = "root";
  root.nodes = test::nodes_at(model.mesh, 0, 0.0);
  model.fixed.push_back(root);
  // Consistent nodal forces: the tip nodes on the mid-width line carry twice those on the edges.
  const auto tip_nodes = test::nodes_at(model.mesh, 0, L);
  for (int line = 0; line < 2; ++line) {
    fem::NodalLoad tip;
    for (auto i : tip_nodes) {
      const bool mid =
          std::abs(model.mesh.coords[3 * static_cast<std::size_t>(i) + 1] - 0.5 * w) < 1e-9;
      if (mid == (line == 1)) tip.nodes.push_back(i);
    }
    fem::V3 F{};
    (axis == 0 ? F.x : F.z) = force * (line == 1 ? 0.25 : 0.125);  // 2 mid + 4 edge nodes
    tip.force_per_node = F;
    tip.ramp_time = 0.02;
    model.loads.push_back(tip);
  }
  const double E_bend = c.E11f + c.E11m, I = w * h * h * h / 12, rhoA = c.density * w * h;
  const double omega1 = 1.875 * 1.875 * std::sqrt(E_bend * I / (rhoA * L * L * L * L));
  model.mass_damping = 2.0 * omega1;
  model.time.end_time = 0.25;
  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  double d = 0;
  for (auto i : tip_nodes)
    d += (test::node_coord(solver, i, axis == 0 ? 0 : 2) -
          model.mesh.coords[3 * i + (axis == 0 ? 0 : 2)]) /
         static_cast<double>(tip_nodes.size());
  return d;
}
}  // namespace

TEST(TowMaterial, AxialAndBendingFibreModuliSeparate) {
  // E11f_axial sets the uniform axial strain (tow stretch), E11f the bending (the physical
  // hourglass stabilisation of the one hexahedron through the thickness): a strip stretches by
  // P L / (E_axial A) and bends by P L^3 / (3 E_bend I) (plus its shear deflection), each within 5
  // %.
  auto c = paper_tow();
  c.compaction_modulus = 0;
  c.E11f_axial = 0.7e9;  // ten times the bending value
  const drape::TowMaterial m("tow", c);
  EXPECT_DOUBLE_EQ(m.elastic_stiffness()[0], c.E11f_axial + c.E11m);
  EXPECT_DOUBLE_EQ(m.bending_stiffness()[0], c.E11f + c.E11m);
  EXPECT_GE(m.stable_step_stiffness()[0], c.E11f_axial);
  const double L = 20e-3, w = 2e-3, h = 0.5e-3;
  const double P_pull = 1.0, P_bend = 1e-4;
  const double stretch = tow_strip_tip(c, 0, P_pull);
  EXPECT_TRUE(test::near_rel(stretch, P_pull * L / ((c.E11f_axial + c.E11m) * w * h), 0.05))
      << stretch;
  const double deflection = tow_strip_tip(c, 2, P_bend);
  const double I = w * h * h * h / 12;
  // Timoshenko: the soft transverse shear of the tow (G13m) adds P L / (5/6 G A), 7 % here.
  const double bending = P_bend * L * L * L / (3 * (c.E11f + c.E11m) * I);
  const double shear = P_bend * L / (5.0 / 6.0 * c.G13m * w * h);
  EXPECT_TRUE(test::near_rel(deflection, bending + shear, 0.05)) << deflection;
  // Without E11f_axial the strip stretches ten times more (the paper's Eq. 1: one fibre modulus).
  c.E11f_axial = 0;
  EXPECT_TRUE(
      test::near_rel(tow_strip_tip(c, 0, P_pull), P_pull * L / ((c.E11f + c.E11m) * w * h), 0.05));
}

namespace {
// Critical step 2 / omega_max of one tow hexahedron (L1 along the fibres, L2 across, L3 thick)
// after it has been brought quasi-statically to the shape x = (X + shear Y, sy Y, sz Z), from
// its finite-difference tangent stiffness there (compaction tangent, locking cap and geometric
// stiffness included; hourglass viscosity off), and the engine's estimate in that shape.
std::pair<double, double> compacted_tow_steps(const drape::TowMaterial& mat, double sy, double sz,
                                              double shear) {
  auto h = test::one_hex(mat, {3.32e-3, 0, 0}, {0, 1.61e-3, 0}, {0, 0, 0.23e-3});
  const std::vector<double> x0 = h.x;
  std::vector<double> v(24), f(24);
  fem::ElementEnergyIncrement inc;
  fem::StableStep st;
  const int steps = 200;
  for (int k = 1; k <= steps; ++k) {
    for (std::size_t I = 0; I < 8; ++I) {
      const double X = x0[3 * I], Y = x0[3 * I + 1], Z = x0[3 * I + 2],
                   s = static_cast<double>(k) / steps;
      const double xn[3] = {X + s * shear * Y, Y + s * (sy - 1) * Y, Z + s * (sz - 1) * Z};
      for (std::size_t c = 0; c < 3; ++c)
        v[3 * I + c] = xn[c] - h.x[3 * I + c], h.x[3 * I + c] = xn[c];
    }
    fem::hex8_internal_forces(h.block, h.x.data(), v.data(), 1.0, f.data(), inc, st);  // unit step
  }
  return {test::critical_step(h), test::estimated_step(h)};
}
}  // namespace

TEST(TowMaterial, CompactedElementStepEstimateIsSafe) {
  // Along compaction through the thickness and across the width to 0.6 (past the locking width
  // 0.7: the capped branch), also sheared by 0.3, the estimate never exceeds the critical step
  // of the compacted, distorted tow element, for the paper's tow and one with 5 GPa axial fibres.
  for (double axial : {0.0, 5e9}) {
    auto c = paper_tow();
    c.E11f_axial = axial;
    const drape::TowMaterial mat("tow", c);
    for (double r : {1.0, 0.9, 0.8, 0.7, 0.6})
      for (double shear : {0.0, 0.3})
        for (int across : {0, 1}) {
          const auto [exact, est] =
              compacted_tow_steps(mat, across ? r : 1.0, across ? 1.0 : r, shear);
          EXPECT_LE(est, exact) << "E11f_axial " << axial << ", ratio " << r
                                << (across ? " across" : " through") << ", shear " << shear;
        }
  }
}
