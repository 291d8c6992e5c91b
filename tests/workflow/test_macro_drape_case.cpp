// The macro (shell) hemisphere drape end to end (issue #19): with the symmetric fabric law the four
// quadrant maxima of the ring agree within 1 deg (a +-45 membrane on a sphere has the ring's
// four-fold symmetry); the punch reaches full depth; the energy balance holds; the ring CSV has the
// macro and kinematic columns; and the run's own last frame (.vtu), read back by `ncfsim compare`
// as an imported macro result, gives the same ring within 0.1 deg. Also the case-file `include`
// mechanism the meso and macro cases share their tools through.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

TEST(CliRegressionMacroDrape, SymmetricLawGivesEqualQuadrantsAndItsVtuImportsBack) {
  const fs::path out = fresh_dir("macro_drape");
  const auto r =
      run_cli({"run", (kSource / "cases/hemisphere/drape_macro.toml").string(), "-o", out.string(),
               "--set", "mesh.resolution=coarse", "--set", "output.frames=both"});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "completed");
  EXPECT_GT(s["punch_displacement_m"].get<double>(), 0.0815);  // equator at the blankholder plane
  EXPECT_LT(s["energy_balance_error"].get<double>(), 0.02);
  double q[4];
  for (int k = 0; k < 4; ++k) q[k] = s["macro_max_shear_deg_q" + std::to_string(k + 1)];
  for (int k = 1; k < 4; ++k) EXPECT_NEAR(q[k], q[0], 1.0) << "q" << k + 1;
  // Near the pin-jointed net's 26.3 deg (the membrane shears freely until it locks near 40 deg).
  EXPECT_NEAR(q[0], s["kinematic_max_shear_deg_q1"].get<double>(), 3.0);
  const auto ring = read_history(out / "ring_shear.csv");
  ASSERT_EQ(ring.rows.size(), 360u);
  const auto mc = ring.column("macro_shear_deg");
  ASSERT_LT(mc, ring.columns.size());
  ASSERT_LT(ring.column("kinematic_shear_deg"), ring.columns.size());

  // The last frame as an imported result.
  fs::path last;
  for (const auto& e : fs::directory_iterator(out / "frames"))
    if (e.path().extension() == ".vtu" && (last.empty() || e.path() > last)) last = e.path();
  ASSERT_FALSE(last.empty());
  const fs::path cmp = fresh_dir("macro_drape_compare");
  const auto c = run_cli(
      {"compare", "macro=" + out.string(), "imported=" + last.string(), "-o", cmp.string()});
  ASSERT_EQ(c.code, 0) << c.output;
  const auto rings = read_history(cmp / "rings.csv");
  std::size_t a = rings.columns.size(), b = a;
  for (std::size_t k = 0; k < rings.columns.size();
       ++k) {  // labels: macro, macro kinematic, imported
    if (rings.columns[k] == "imported") b = k;
    if (rings.columns[k] == "macro") a = k;
  }
  ASSERT_LT(a, rings.columns.size()) << slurp(cmp / "rings.csv").substr(0, 300);
  ASSERT_LT(b, rings.columns.size());
  int compared = 0;
  for (const auto& row : rings.rows)
    if (std::isfinite(row[a]) && std::isfinite(row[b])) {
      EXPECT_NEAR(row[b], row[a], 0.1);
      ++compared;
    }
  EXPECT_GT(compared, 300);
  fs::remove_all(out);
  fs::remove_all(cmp);
}

// The stitched macro model (the stitch as bars sewn onto the shells) on the coarse shells shows
// the meso drape's shear bias: q1 and q3 (positive shear, the stitch stretched) well under q2 and
// q4, each pair equal (the blank's two-fold symmetry); it completes with its energy balance.
TEST(CliRegressionMacroDrape, StitchedModelShowsTheShearBias) {
  const fs::path out = fresh_dir("macro_drape_stitched");
  const auto r =
      run_cli({"-q", "run", (kSource / "cases/hemisphere/drape_macro_stitched.toml").string(), "-o",
               out.string(), "--set", "mesh.resolution=coarse", "--set",
               "mesh.shell_stitch[0].line_spacing=5e-3", "--set",
               "mesh.shell_stitch[0].point_spacing=5e-3", "--set", "output.frames=none", "--set",
               "output.figures=false", "--set", "output.report=false"});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "completed");
  EXPECT_GT(s["punch_displacement_m"].get<double>(), 0.0815);
  EXPECT_LT(s["energy_balance_error"].get<double>(), 0.02);
  double q[4];
  for (int k = 0; k < 4; ++k) q[k] = s["macro_max_shear_deg_q" + std::to_string(k + 1)];
  EXPECT_NEAR(q[2], q[0], 1.0);
  EXPECT_NEAR(q[3], q[1], 1.0);
  EXPECT_GT(q[1] - q[0], 10.0) << "no shear bias";
  // Measured (5 December 2026): 10.98 / 29.42 / 10.98 / 29.42 deg in 5 s (default shells: 11.09 /
  // 29.42 / 11.09 / 29.42).
  std::printf("stitched macro drape, coarse: q1..q4 %.2f %.2f %.2f %.2f deg\n", q[0], q[1], q[2],
              q[3]);
  fs::remove_all(out);
}

// include = [...]: a missing file and a key given both in the case and in the included file are
// bad input naming `include` / the key.
TEST(CliCaseInclude, MissingFileAndConflictingKeyNameTheKey) {
  const fs::path dir = fresh_dir("include_cases");
  fs::create_directories(dir);
  std::ofstream(dir / "shared.toml") << "[time]\nend_time = 1e-3\n";
  const std::string body = std::string("[case]\nname = \"inc\"\n[mesh]\n[[mesh.plate]]\n") +
                           "part = \"p\"\nsize = [0.01, 0.01]\ndivisions = [1, 1]\n" +
                           "[[material]]\nname = \"m\"\ntype = \"elastic_isotropic\"\n" +
                           "density = 1000.0\nyoungs_modulus = 1e9\npoisson_ratio = 0.3\n" +
                           "[[part]]\nname = \"p\"\nmaterial = \"m\"\nthickness = 0.001\n";
  std::ofstream(dir / "missing.toml") << "include = [\"nope.toml\"]\n" << body;
  std::ofstream(dir / "conflict.toml") << "include = [\"shared.toml\"]\n"
                                       << body << "[time]\nend_time = 2e-3\n";
  std::ofstream(dir / "good.toml") << "include = [\"shared.toml\"]\n" << body;
  auto r = run_cli({"check", (dir / "missing.toml").string()});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("include"), std::string::npos) << r.output;
  r = run_cli({"check", (dir / "conflict.toml").string()});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("time.end_time"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("shared.toml"), std::string::npos) << r.output;
  r = run_cli({"check", (dir / "good.toml").string()});
  EXPECT_EQ(r.code, 0) << r.output;
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ncfsim::test
