// Virtual friction sled (paper Eq. 7, mu = F / P) through the ncfsim command line (regression): the
// three cases of cases/drape -- tows on aluminium (rigid plane, mu = 0.20), tows on tows 0/0 and
// 0/90 (penalty contact between two tow plies, mu = 0.25 and 0.30, docs/fabric-data.md) -- recover
// their input Coulomb coefficient within 2 %, from the mean pulling force and from the friction work
// per sliding distance, with a clean energy balance. The references and tolerances are read from
// cases/drape/reference/<case>.csv. Coarse meshes (about 15 s for the three on the
// 2-core development VM; the case files' default meshes meet the same 2 %).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/workflow/cli_test_support.hpp"

namespace fs = std::filesystem;
using namespace ncfsim::test;

namespace {

// Runs cases/drape/<name>.toml on the coarse mesh and checks mu against its reference
// (cases/drape/reference/<name>.csv: the input coefficient, 2 %).
void check_sled(const std::string& name) {
  const Reference ref = case_reference("drape", name);
  const fs::path out = fresh_dir(name);
  const Result r = run_cli({"-q", "run", (kSource / "cases/drape" / (name + ".toml")).string(), "-o", out.string(),
                            "--set", "mesh.resolution=coarse", "--set", "output.frames=none", "--set",
                            "output.figures=false", "--set", "output.report=false"});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "completed");
  for (const char* q : {"friction_coefficient",             // mean pulling force / P (Eq. 7)
                        "friction_work_over_P_distance"}) {  // friction work / (P x sliding distance)
    ASSERT_TRUE(s[q].is_number()) << s.dump(2);
    const double mu = ref.at(q, "reference");
    EXPECT_NEAR(s[q].get<double>(), mu, ref.at(q, "rel_tol") * mu) << name << ": " << q;
  }
  EXPECT_LT(s["energy_balance_error"].get<double>(), 0.01);
  // Steady sliding: no friction-excited vibration of the sled (pulled at the top of its soft block,
  // the aluminium case put 1.2 % of the friction work into hourglass modes and mu came out 2.5 %
  // low; now below 0.03 %).
  EXPECT_LT(s["hourglass_energy_J"].get<double>(), 1e-3 * s["friction_energy_J"].get<double>());
  fs::remove_all(out);
}

}  // namespace

TEST(CliRegressionFrictionSled, TowsOnAluminiumRecoverMu) { check_sled("friction_sled_aluminium"); }

TEST(CliRegressionFrictionSled, TowsOnTowsParallelRecoverMu) { check_sled("friction_sled_tow_tow_0_0"); }

TEST(CliRegressionFrictionSled, TowsOnTowsCrossedRecoverMu) { check_sled("friction_sled_tow_tow_0_90"); }
