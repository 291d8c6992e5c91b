// Crack-band regularisation through the engine: a 2 mm impregnated-tow strip (1 x 1 mm, fibres
// along it; short enough that its elastic energy at the peak, 0.04 J, is below G A = 0.09 J: the
// softening is stable, no snap-back of the strip) pulled to fibre-tension failure with 5, 10
// and 20 hexahedra along it (0.4, 0.2, 0.1 mm: twice and four times finer). One row in
// the middle is 1 % weaker (the flaw the crack starts from). Expected: the failure localises in
// that one row of elements (the others unload elastically, never reaching full damage), and the
// energy the damage dissipates is G_ft times the cross-section whatever the mesh: the three meshes
// agree within 10 % and match G A within 10 %. (Measured: 0.088, 0.088, 0.089 J against 0.090.
// Forty elements, 0.05 mm long and 1 mm wide, did not localise: damage spread over every row; the
// flaw's element would have to stretch to twice its length, GL strain 1.6, before it breaks.)
// Dissipated = internal energy less the elastic energy the elements still hold (1/2 S : E V0 of
// each, the hourglass stabilisation's stored part).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>

#include "fem/elements/hex8_block.hpp"
#include "impact/tow_damage_material.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kL = 0.002, kW = 0.001, kG = 90e3;  // m, m, J/m^2

impact::TowDamageConstants tow(double xt) {
  impact::TowDamageConstants c;
  c.density = 1550;
  c.elastic = {140e9, 9e9, 9e9, 0.3, 0.3, 0.45, 5e9, 5e9, 3.1e9};
  c.strength = {xt, 0.6 * xt, 60e6, 36e6, 80e6, 60e6};
  c.fracture_energy = {kG, 80e3, 280, 800, 800, 500};
  // erode_on: the fibre modes (default): the broken row is eroded, its energy stays counted
  return c;
}

struct StripRun {
  double dissipated = 0;
  int fully_damaged = 0, rows_damaged = 0;
};

StripRun pull_strip(int n) {
  fem::Model model;
  const int strip = model.mesh.add_part("strip");
  fem::add_hex_block(model.mesh, strip, {0, 0, 0}, {kL, kW, kW}, {n, 1, 1});
  // The flaw: the middle row in a part of its own, 1 % weaker.
  const int flaw = model.mesh.add_part("flaw");
  fem::ElementSet& hexes = model.mesh.elements(fem::ElementKind::Hex8);
  hexes.part[static_cast<std::size_t>(n / 2)] = flaw;
  model.materials.push_back(std::make_unique<impact::TowDamageMaterial>("tow", tow(2.3e9)));
  model.materials.push_back(std::make_unique<impact::TowDamageMaterial>("weak", tow(0.99 * 2.3e9)));
  model.parts.resize(2);
  model.parts[0].material = 0, model.parts[1].material = 1;
  for (auto& pp : model.parts) pp.hourglass_viscosity = 0;
  fem::FixedDofs x0{"x0", test::nodes_at(model.mesh, 0, 0.0), {true, false, false}};
  fem::FixedDofs y0{"y0", test::nodes_at(model.mesh, 1, 0.0), {false, true, false}};
  fem::FixedDofs z0{"z0", test::nodes_at(model.mesh, 2, 0.0), {false, false, true}};
  model.fixed = {x0, y0, z0};
  fem::PrescribedVelocity pull;
  pull.name = "pull";
  pull.nodes = test::nodes_at(model.mesh, 0, kL);
  pull.dofs = {true, false, false};
  pull.velocity = {1.0, 0, 0};  // m/s: the peak at ~0.035 ms, 160 wave transits of the strip
  pull.ramp_time = 2e-5;
  model.velocities.push_back(pull);
  model.time.end_time = 1.5e-4;  // 0.14 mm: past full damage of the flaw row (0.11 mm)
  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();

  StripRun r;
  double elastic = 0;
  std::vector<char> row_damaged(static_cast<std::size_t>(n), 0);
  const auto& set = solver.model().mesh.elements(fem::ElementKind::Hex8);
  for (const auto& b : solver.blocks<fem::Hex8Block>()) {
    const double* d_ft = b.history.data() + impact::TowDamageMaterial::kDamageRow * b.n;
    for (std::size_t e = 0; e < b.n; ++e) {
      for (int c = 0; c < 6; ++c)
        elastic += 0.5 * b.stress[static_cast<std::size_t>(c) * b.n + e] *
                   b.strain[static_cast<std::size_t>(c) * b.n + e] * b.volume0[e];
      r.fully_damaged += d_ft[e] >= 1.0 || (b.n_eroded && b.eroded[e]);
      if (d_ft[e] > 0.5) {
        // The element's row: its centroid's position along the strip.
        double x = 0;
        for (auto node : set.nodes(static_cast<std::size_t>(b.mesh_hex[e])))
          x += 0.125 * solver.model().mesh.coords[3 * static_cast<std::size_t>(node)];
        row_damaged[static_cast<std::size_t>(
            std::clamp(static_cast<int>(x / (kL / n)), 0, n - 1))] = 1;
      }
    }
  }
  for (char c : row_damaged) r.rows_damaged += c;
  const auto& en = solver.energy();
  r.dissipated = en.internal - elastic - en.stabilisation;
  return r;
}

}  // namespace

TEST(DamageRegularisation, StripDissipatesTheSameEnergyOnFinerMeshesInOneRow) {
  const double GA = kG * kW * kW;
  std::vector<StripRun> runs;
  for (int n : {5, 10, 20}) runs.push_back(pull_strip(n));
  for (std::size_t k = 0; k < runs.size(); ++k) {
    EXPECT_EQ(runs[k].rows_damaged, 1)
        << "mesh " << k << ": the failure did not localise in one row";
    EXPECT_EQ(runs[k].fully_damaged, 1) << "mesh " << k;
    EXPECT_TRUE(test::near_rel(runs[k].dissipated, GA, 0.10))
        << "mesh " << k << ": " << runs[k].dissipated << " J";
    EXPECT_TRUE(test::near_rel(runs[k].dissipated, runs[0].dissipated, 0.10)) << "mesh " << k;
    std::printf("mesh %zu: dissipated %.4g J (G A = %.4g J)\n", k, runs[k].dissipated, GA);
  }
}
