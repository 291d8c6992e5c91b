// The kinematic drape stage end to end: `ncfsim run cases/hemisphere/fishnet.toml` writes the ring
// measure (360 azimuths, every one on the net), the four quadrant maxima (equal within 1 deg for a
// +-45 net on the sphere: the acceptance of issue #18), the net, and refuses bad input naming the
// key.
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

TEST(CliRegressionKinematicDrape, HemisphereFishnetGivesEqualQuadrantsAndTheRing) {
  const fs::path out = fresh_dir("fishnet");
  const auto r =
      run_cli({"run", (kSource / "cases/hemisphere/fishnet.toml").string(), "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["stage"], "kinematic_drape");
  EXPECT_EQ(s["status"], "completed");
  EXPECT_EQ(s["ring_samples"], 360);
  EXPECT_EQ(s["ring_samples_missed"], 0);
  const double q1 = s["kinematic_max_shear_deg_q1"];
  for (int k = 2; k <= 4; ++k)
    EXPECT_NEAR(s["kinematic_max_shear_deg_q" + std::to_string(k)].get<double>(), q1, 1.0);
  // Reference (tests/drape KinematicDrape tests: 26.28 deg on the 156 mm sphere at 40 mm, 0.5-2 mm
  // nets).
  EXPECT_NEAR(q1, 26.28, 0.1);
  const auto ring = read_history(out / "ring_shear.csv");
  ASSERT_EQ(ring.rows.size(), 360u);
  const auto az = ring.column("azimuth_deg"), sh = ring.column("kinematic_shear_deg");
  ASSERT_LT(sh, ring.columns.size());
  // No shear on the generators (45, 135, 225, 315 deg), most midway between them.
  for (const auto& row : ring.rows)
    if (std::fmod(row[az] - 45.0, 90.0) == 0.0) {
      EXPECT_NEAR(row[sh], 0.0, 0.05) << row[az];
    }
  EXPECT_TRUE(fs::exists(out / "net.csv"));
  EXPECT_TRUE(fs::exists(out / "log.txt"));
  fs::remove_all(out);
}

TEST(CliKinematicDrape, BadInputNamesTheKey) {
  const fs::path out = fresh_dir("fishnet_bad");
  const auto case_file = kSource / "cases/hemisphere/fishnet.toml";
  auto r = run_cli({"run", case_file.string(), "-o", out.string(), "--set", "net.spacing=0"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("net.spacing"), std::string::npos) << r.output;
  r = run_cli({"run", case_file.string(), "-o", out.string(), "--set", "net.pole=[0.0,0.0,0.01]"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("net.pole"), std::string::npos) << r.output;
  // A ring above the part meets nothing: bad input, and no maxima written (issue #45).
  r = run_cli({"run", case_file.string(), "-o", out.string(), "--set", "ring.height=0.5"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("ring.height"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out / "summary.json"));
  r = run_cli({"check", case_file.string()});
  EXPECT_EQ(r.code, 0) << r.output;
  fs::remove_all(out);
}

}  // namespace
}  // namespace ncfsim::test
