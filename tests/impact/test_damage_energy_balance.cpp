// The energy balance of a damaging body (the dome crush drifts past 5 %, issue #21): a block of
// impregnated tow (3 x 3 x 2 hexahedra of 1 mm, fibres along x, strengths a tenth of T700/epoxy's
// so that every mode initiates) is thrown tilted at 20 m/s onto a rigid wall, crushed against it
// and bounces off. Every force acting is the material's, the wall's (penalty, damped) and nothing
// else, so E - E0 - W must stay within 1 % of the energy in play over the whole run, and in free
// flight after the bounce kinetic + internal energy may not rise.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "fem/contact/penalty_contact.hpp"
#include "fem/contact/tied_contact.hpp"
#include "fem/elements/hex8_block.hpp"
#include "impact/tow_damage_material.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

// Impregnated tow (T700/epoxy constants) with strengths a tenth of the real ones, so that every
// mode initiates in a 20 m/s impact; no element eroded.
impact::TowDamageConstants weak_tow() {
  impact::TowDamageConstants c;
  c.density = 1550;
  c.elastic = {140e9, 9e9, 9e9, 0.3, 0.3, 0.45, 5e9, 5e9, 3.1e9};
  c.strength = {230e6, 140e6, 6e6, 3.6e6, 8e6, 6e6};
  c.fracture_energy = {90e3, 80e3, 280, 800, 800, 500};
  c.erode_on = {false, false, false, false, false, false};
  return c;
}

}  // namespace

TEST(DamageEnergyBalance, CrushedBlockBouncingOffAWallKeepsTheBalance) {
  fem::Model model;
  const int p = model.mesh.add_part("block");
  fem::add_hex_block(model.mesh, p, {0, 0, 0.0002}, {0.003, 0.003, 0.002}, {3, 3, 2});
  model.materials.push_back(std::make_unique<impact::TowDamageMaterial>("tow", weak_tow()));
  model.parts.resize(1);
  model.parts[0].material = 0;
  model.parts[0].hourglass_viscosity = 0;
  test::add_rigid_plane(model, "wall", {0, 0, 0}, {0, 0, 1}, test::all_nodes(model.mesh), 0.3);
  model.initial_velocities.push_back({test::all_nodes(model.mesh), {3.0, 2.0, -20.0}});
  model.time.end_time = 4e-4;
  fem::ExplicitSolver solver(model);
  double worst = 0, largest_damage = 0;
  bool touched = false, apart = false;
  double e_apart = 0, rise = 0;
  while (solver.time() < model.time.end_time) {
    solver.step();
    worst = std::max(worst, solver.energy().error());
    const auto& tool = solver.model().tools[0];
    touched = touched || tool.n_active > 0;
    const double mech = solver.energy().kinetic + solver.energy().internal;
    if (touched && tool.n_active == 0 && !apart) apart = true, e_apart = mech;
    if (apart) rise = std::max(rise, mech - e_apart);
  }
  for (const auto& b : solver.blocks<fem::Hex8Block>())
    for (std::size_t k = impact::TowDamageMaterial::kDamageRow * b.n;
         k < (impact::TowDamageMaterial::kDamageRow + 6) * b.n; ++k)
      largest_damage = std::max(largest_damage, b.history[k]);
  const auto& en = solver.energy();
  std::printf(
      "damage block: largest damage %.3g, balance worst %.3g, final %.3g, rise %.3g J of %.3g J\n",
      largest_damage, worst, en.error(), rise, en.scale_max);
  EXPECT_TRUE(touched);
  EXPECT_GT(largest_damage, 0.5) << "the block was not damaged";
  EXPECT_LT(worst, 0.01);
  if (apart) {
    EXPECT_LT(rise, 1e-3 * en.scale_max);
  }
}

// The same with what the dome adds: two plies (3 x 3 x 1 hexahedra each) bonded face to face by
// a cohesive tie (mode I 300, mode II 1000 J/m^2, 40 / 60 MPa) with a frictional penalty contact
// between them for when the bond has failed, as the crush case sets them up.
TEST(DamageEnergyBalance, BondedPliesCrushedOnAWallKeepTheBalance) {
  fem::Model model;
  const int lower = model.mesh.add_part("lower"), upper = model.mesh.add_part("upper");
  fem::add_hex_block(model.mesh, lower, {0, 0, 0.0002}, {0.003, 0.003, 0.001}, {3, 3, 1});
  fem::add_hex_block(model.mesh, upper, {0, 0, 0.0012}, {0.003, 0.003, 0.001}, {3, 3, 1});
  model.materials.push_back(std::make_unique<impact::TowDamageMaterial>("tow", weak_tow()));
  model.parts.resize(2);
  for (auto& pp : model.parts) pp.material = 0, pp.hourglass_viscosity = 0;
  // Faces: the lower block's top (face 1, +z) under the upper block's bottom (face 0, -z).
  const fem::ElementSet& hexes = model.mesh.elements(fem::ElementKind::Hex8);
  std::vector<fem::TiedFacePair> pairs;
  for (std::size_t a = 0; a < hexes.size(); ++a)
    for (std::size_t b = 0; b < hexes.size(); ++b) {
      if (hexes.part[a] != upper || hexes.part[b] != lower) continue;
      double ca[3] = {0, 0, 0}, cb[3] = {0, 0, 0};
      for (auto n : hexes.nodes(a))
        for (int k = 0; k < 3; ++k)
          ca[k] += 0.125 * model.mesh.coords[3 * static_cast<std::size_t>(n) + k];
      for (auto n : hexes.nodes(b))
        for (int k = 0; k < 3; ++k)
          cb[k] += 0.125 * model.mesh.coords[3 * static_cast<std::size_t>(n) + k];
      if (std::abs(ca[0] - cb[0]) < 1e-9 && std::abs(ca[1] - cb[1]) < 1e-9)
        pairs.push_back({static_cast<std::int32_t>(a), static_cast<std::int32_t>(b), 0, 1});
    }
  ASSERT_EQ(pairs.size(), 9u);
  fem::TiedContactConfig tie;
  tie.name = "bond";
  tie.face_pairs = pairs;
  tie.normal_strength = 40e6;
  tie.shear_strength = 60e6;
  tie.mode_i_energy = 300;
  tie.mode_ii_energy = 1000;
  model.contacts.push_back(std::make_unique<fem::TiedContact>(tie));
  fem::PenaltyContactConfig touch;
  touch.name = "plies";
  touch.groups = {{"lower", {lower}}, {"upper", {upper}}};
  touch.pairs = {{0, 1, 0.3}};
  model.contacts.push_back(std::make_unique<fem::PenaltyContact>(touch));
  test::add_rigid_plane(model, "wall", {0, 0, 0}, {0, 0, 1}, test::all_nodes(model.mesh), 0.3);
  model.initial_velocities.push_back({test::all_nodes(model.mesh), {3.0, 2.0, -20.0}});
  model.time.end_time = 4e-4;
  fem::ExplicitSolver solver(model);
  double worst = 0;
  while (solver.time() < model.time.end_time) {
    solver.step();
    worst = std::max(worst, solver.energy().error());
  }
  const auto& en = solver.energy();
  std::printf(
      "bonded plies: balance worst %.3g, final %.3g, contact %.3g J, friction %.3g J of %.3g J\n",
      worst, en.error(), en.contact, en.friction, en.scale_max);
  EXPECT_LT(worst, 0.01);
}
