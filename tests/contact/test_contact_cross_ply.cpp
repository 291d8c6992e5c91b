// Two crossed plies of tows (thin hex strips like the NCF generator's: 0.23 mm thick, 3 mm wide,
// 0.1 mm gaps between the tows of a ply), touching at zero gap, with Coulomb friction (mu = 0.3
// ply-ply). Ply 1 is fixed at its base; ply 2, its cut tow ends lying on ply-1 tows, is pressed
// down (2 N) and dragged diagonally at 0.5 m/s over 2.7 mm, so its tow ends cross gaps between
// ply-1 tows and its tows slide over ply-1 tow edges.
//  * 0/90, ply-ply contact only: ply-2 tow ends 1.2 mm inside the far side of the tow beneath.
//  * +-45 with the tow ends cut along y (as in a bias-extension coupon), tow-tow contact too.
// Conservation (no analytic value): the energy balance closes within 1 %, the contact never does
// net positive work on the nodes (contact energy >= -1e-3 of the external work), friction and
// damping dissipate (>= 0), ply 2 stays on top of ply 1.
// Regression: a tow-end node lying on the other ply's tow top face also projects onto that tow's
// side face (at its top edge) with a 'penetration' up to half the tow width, and its end facet
// faces that side; it was pushed sideways (-0.8 J created at t = 0 in the +-45 bias-extension
// coupon, tests/cases/contact/fabric_cross_ply_energy.toml).
#include "tests/contact/contact_test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kT = 0.23e-3;   // tow thickness, m
constexpr double kW = 3.0e-3;    // tow width, m
constexpr double kGap = 0.1e-3;  // gap between the tows of a ply, m

struct CrossPly {
  fem::Model model;
  std::vector<int> ply1, ply2;
  fem::PenaltyContact* contact = nullptr;
};

enum class Layup {
  kCrossed,  // 0/90: tows along x over tows along y, ends cut square (end facets = tow axis)
  kBias,     // +-45 with the tow ends cut along y, as a bias-extension coupon's
};

// One tow: a row of hexahedra over x in [x0, x0 + length], 1 element across and through; with a
// shear slope (+-1 for +-45 deg) its points are moved by y += slope * x, which keeps the ends
// normal to x. Returns the part index.
int add_tow(fem::Model& m, const std::string& name, double x0, double y0, double z0, double length,
            double width_y, int n_elem, double slope) {
  test::add_elastic_block(m, name, {x0, y0, z0}, {length, width_y, kT}, {n_elem, 1, 1}, 1080, 5e7,
                          0.3);
  const int p = static_cast<int>(m.mesh.part_names.size()) - 1;
  for (auto i : test::part_nodes(m.mesh, p))
    m.mesh.coords[3 * static_cast<std::size_t>(i) + 1] +=
        slope * m.mesh.coords[3 * static_cast<std::size_t>(i)];
  return p;
}

void build_cross_ply(CrossPly& s, Layup layup, bool self_contact) {
  fem::Model& m = s.model;
  if (layup == Layup::kCrossed) {
    // Ply 1: 4 tows along x, 20 mm long (4 mm elements), y in [k pitch, k pitch + kW].
    // Ply 2: 4 tows along y over y in [1.8, 10.5] mm: the ends lie on ply-1 tows 0 and 3, 1.2 mm
    // inside their far sides (y = 3.0 and 9.3 mm), within max_penetration * tow width.
    const double pitch = kW + kGap;
    for (int k = 0; k < 4; ++k)
      s.ply1.push_back(
          add_tow(m, "ply1_tow" + std::to_string(k), 0, k * pitch, 0, 20e-3, kW, 5, 0));
    for (int k = 0; k < 4; ++k) {
      test::add_elastic_block(m, "ply2_tow" + std::to_string(k), {2e-3 + k * pitch, 1.8e-3, kT},
                              {kW, 8.7e-3, kT}, {1, 3, 1}, 1080, 5e7, 0.3);
      s.ply2.push_back(static_cast<int>(m.mesh.part_names.size()) - 1);
    }
  } else {
    // Tow widths measured along y (kW across the tow). Ply 1: 10 tows at +45 deg over x in
    // [0, 16] mm (5.7 mm elements along the tow); ply 2: 3 tows at -45 deg over x in [4.5, 12.5]
    // mm, lying on ply 1 with their cut ends (normal +-x, 45 deg from ply-1 tow sides) anywhere
    // across ply-1 tows. (Ply-2 ends exactly on ply-1 element seams, x = 4 and 12 mm, make those
    // nodes flip between the two segments of the seam and flutter under friction: ~1e-6 J.)
    const double wy = kW * std::sqrt(2.0), pitch = (kW + kGap) * std::sqrt(2.0);
    for (int k = 0; k < 10; ++k)
      s.ply1.push_back(
          add_tow(m, "ply1_tow" + std::to_string(k), 0, -30e-3 + k * pitch, 0, 16e-3, wy, 4, 1.0));
    for (int k = 0; k < 3; ++k)
      s.ply2.push_back(add_tow(m, "ply2_tow" + std::to_string(k), 4.5e-3, 1.5e-3 + k * pitch, kT,
                               8e-3, wy, 2, -1.0));
  }
  fem::renumber_for_locality(m.mesh);
  m.fixed.push_back({"ply1_base", test::nodes_at(m.mesh, 2, 0.0), {true, true, true}});
  const auto top = test::nodes_at(m.mesh, 2, 2 * kT);
  fem::NodalLoad press;
  press.name = "press";
  press.nodes = top;
  press.force_per_node = {0, 0, -2.0 / static_cast<double>(top.size())};  // 2 N in all
  press.ramp_time = 1e-3;
  m.loads.push_back(press);
  fem::PrescribedVelocity drag;
  drag.name = "drag";
  drag.nodes = top;
  drag.dofs = {true, true, false};
  drag.velocity = {0.4, 0.3, 0};
  drag.start_time = 1e-3;
  drag.ramp_time = 0.5e-3;
  m.velocities.push_back(drag);

  fem::PenaltyContactConfig cfg;
  cfg.name = "plies";
  cfg.groups = {{"ply1", s.ply1}, {"ply2", s.ply2}};
  cfg.pairs = {{0, 1, 0.3}};  // ply-ply only, as the bias-extension reproducer
  if (self_contact) cfg.pairs.insert(cfg.pairs.end(), {{0, 0, 0.25}, {1, 1, 0.25}});  // tow-tow
  s.contact = test::add_contact<fem::PenaltyContact>(m, cfg);
}

void drag_cross_ply(Layup layup, bool self_contact) {
  CrossPly s;
  build_cross_ply(s, layup, self_contact);
  s.model.time.end_time = 6.5e-3;  // 2.2 mm in x, 1.65 mm in y: ply-2 tow ends cross a gap
  fem::ExplicitSolver solver(s.model);
  std::vector<std::int32_t> nodes2;
  for (int p : s.ply2) {
    const auto n = test::part_nodes(s.model.mesh, p);
    nodes2.insert(nodes2.end(), n.begin(), n.end());
  }
  const double x0 = test::mean_of(solver, nodes2, 0, 0);
  double worst_contact = 0, worst_stored = 0, worst_error = 0, worst_pen = 0;
  while (solver.time() < s.model.time.end_time) {
    solver.step();
    const fem::EnergyBalance& e = solver.energy();
    const double allowance = 1e-3 * std::abs(e.external_work);
    worst_contact = std::min(worst_contact, e.contact + allowance);
    worst_stored = std::min(worst_stored, e.contact - e.friction + allowance);
    if (solver.time() > 0.5e-3) worst_error = std::max(worst_error, e.error());
    worst_pen = std::max(worst_pen, s.contact->stats().max_penetration);
  }
  const fem::EnergyBalance& e = solver.energy();
  auto X = solver.x.view();
  for (std::size_t d = 0; d < 3 * s.model.mesh.n_nodes(); ++d) ASSERT_TRUE(std::isfinite(X[d]));
  const double slide = test::mean_of(solver, nodes2, 0, 0) - x0;
  const double z2 = test::mean_of(solver, nodes2, 2, 0);
  std::printf(
      "%s%s: slide %.3g m, external work %.4g J, contact %.4g J (friction and damping "
      "%.4g J), energy error %.3g (worst %.3g), penetration %.3g of the thickness, ply-2 mean "
      "height %.4g mm\n",
      layup == Layup::kCrossed ? "0/90" : "+-45", self_contact ? " with tow-tow contact" : "",
      slide, e.external_work, e.contact, e.friction, e.error(), worst_error, worst_pen / kT,
      z2 * 1e3);
  EXPECT_GT(slide, 1.5e-3) << "ply 2 should have been dragged along (m)";
  EXPECT_LT(worst_error, 0.01) << "energy balance error after the first 0.5 ms";
  EXPECT_GE(worst_contact, 0.0) << "contact energy fell below -1e-3 of the external work (J)";
  EXPECT_GE(worst_stored, 0.0)
      << "contact energy less friction (the penalty springs' energy) fell below -1e-3 of the "
         "external work (J)";
  EXPECT_GT(s.contact->friction_dissipation(), 0.0) << "friction should have dissipated (J)";
  EXPECT_LT(worst_pen, 0.05 * kT) << "largest penetration (m)";
  EXPECT_GT(z2, 1.45 * kT) << "ply 2 (mean height 1.5 kT) should stay on top of ply 1 (m)";
}

}  // namespace

TEST(ContactCrossPly, DraggedCrossedTowPliesConserveEnergyAndContactCreatesNone) {
  drag_cross_ply(Layup::kCrossed, false);
}

TEST(ContactCrossPly, DraggedBiasPliesWithTowEndsCutAlongYToo) {
  drag_cross_ply(Layup::kBias, true);
}
