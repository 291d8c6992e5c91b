// Single-element verification of the impregnated-tow damage law through the whole engine (issue
// #21; cases/verification/damage/*.toml): one 0.5 mm hexahedron loaded slowly to full damage in
// each failure mode. The crack band predicts, for a uniaxial or pure-shear path:
//   * the material-frame stress of the mode peaks at its strength X (compressive: 0.6 of the
//     tensile one, the default compressive_ratio): within 0.5 %;
//   * the energy dissipated per volume (the internal energy left at full damage, less the elastic
//     energy still held by the other components) equals G / L, with L = 0.5 mm the element's
//     length across the crack: within 1 % (the runs: 0.15 % and 0.005 %).
#include <gtest/gtest.h>

#include <algorithm>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

struct ModeCase {
  const char* file;
  const char* component;   // the mode's stress component
  double strength;         // Pa, signed
  double fracture_energy;  // J/m^2
};

constexpr double kLength = 5e-4, kVolume = kLength * kLength * kLength;

void check_mode(const ModeCase& c) {
  const fs::path out = fresh_dir(std::string("damage_") + c.file);
  const auto r =
      run_cli({"-q", "run",
               (kSource / "cases/verification/damage" / (std::string(c.file) + ".toml")).string(),
               "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const History h = read_history(out / "history.csv");
  const std::size_t s = h.column(std::string("element_stress_") + c.component + "_Pa");
  ASSERT_LT(s, h.columns.size());
  double peak = 0;
  for (const auto& row : h.rows)
    peak = c.strength > 0 ? std::max(peak, row[s]) : std::min(peak, row[s]);
  EXPECT_NEAR(peak / c.strength, 1.0, 0.005) << c.file;
  const auto& last = h.rows.back();
  double elastic = 0;
  for (const char* ij : {"11", "22", "33", "12", "23", "13"})
    elastic += 0.5 * last[h.column(std::string("element_stress_") + ij + "_Pa")] *
               last[h.column(std::string("element_strain_") + ij)];
  const double dissipated = (last[h.column("internal_energy_J")] - elastic * kVolume) / kVolume;
  EXPECT_NEAR(dissipated / (c.fracture_energy / kLength), 1.0, 0.01) << c.file;
  EXPECT_EQ(last[s], 0.0) << c.file << ": the mode is not fully damaged at the end";
  EXPECT_LT(last[h.column("energy_balance_error")], 1e-4) << c.file;
  fs::remove_all(out);
}

TEST(CliVerificationDamage, FibreTensionPeaksAtXtAndDissipatesGOverL) {
  check_mode({"fibre_tension", "11", 2.3e9, 90e3});
}
TEST(CliVerificationDamage, FibreCompressionPeaksAtSixtyPercentOfXt) {
  check_mode({"fibre_compression", "11", -0.6 * 2.3e9, 80e3});
}
TEST(CliVerificationDamage, MatrixTensionPeaksAtYtAndDissipatesGOverL) {
  check_mode({"matrix_tension", "22", 60e6, 280});
}
TEST(CliVerificationDamage, MatrixCompressionPeaksAtSixtyPercentOfYt) {
  check_mode({"matrix_compression", "22", -0.6 * 60e6, 800});
}
TEST(CliVerificationDamage, InPlaneShearPeaksAtS12AndDissipatesGOverL) {
  check_mode({"in_plane_shear", "12", 80e6, 800});
}
TEST(CliVerificationDamage, TransverseShearPeaksAtS23AndDissipatesGOverL) {
  check_mode({"transverse_shear", "23", 60e6, 500});
}

// A crushed tow keeps a residual compressive strength when the material gives one: pushed far
// past full matrix-compression damage, S22 stays at residual_compression x Yc (0.5 x 36 MPa).
TEST(CliVerificationDamage, CrushedTowHoldsItsResidualCompressiveStrength) {
  const fs::path out = fresh_dir("damage_residual");
  const auto r = run_cli({"-q", "run",
                          (kSource / "cases/verification/damage/matrix_compression.toml").string(),
                          "-o", out.string(), "--set", "material[0].residual_compression=0.5"});
  ASSERT_EQ(r.code, 0) << r.output;
  const History h = read_history(out / "history.csv");
  const double s22 = h.rows.back()[h.column("element_stress_22_Pa")];
  EXPECT_NEAR(s22 / (-0.5 * 0.6 * 60e6), 1.0, 0.005);
  fs::remove_all(out);
}

// A fracture energy too small for the element (snap-back: the crack band needs L < 2 G E / X^2)
// is bad input naming the key and the limit; so are a zero strength and a negative energy.
TEST(CliVerificationDamage, RefusesSnapBackAndNonPositiveData) {
  const std::string c = (kSource / "cases/verification/damage/fibre_tension.toml").string();
  // 2 G E / X^2 with G = 1 kJ/m^2: 0.053 mm < 0.5 mm.
  auto r = run_cli({"check", c, "--set", "material[0].fracture_energy.fibre_tension=1000.0"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("material[0].fracture_energy.fibre_tension"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("snap-back"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("give at least"), std::string::npos) << r.output;
  r = run_cli({"check", c, "--set", "material[0].Xt=0.0"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("material[0].Xt"), std::string::npos) << r.output;
  r = run_cli({"check", c, "--set", "material[0].fracture_energy.matrix_tension=-5.0"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("material[0].fracture_energy.matrix_tension"), std::string::npos)
      << r.output;
}

}  // namespace
}  // namespace ncfsim::test
