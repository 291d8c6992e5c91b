// Picture-frame cases end to end (issue #4), through the ncfsim executable:
// - unstitched 6.64 mm unit cell: no force before the gaps close (14.1 deg), then tow compaction,
//   and the force rises steeply into the locking branch of the tow law (the tows reach 0.75 of
//   their width at 43.4 deg); it never drops (before the frame walls, the compaction measure of
//   the tow law and the in-plane plates the tows bowed apart and rolled over each other from
//   ~38 deg and the force fell);
// - stitched 2 x 2 cells, positive and negative shear: both complete to 45 deg with a balanced
//   energy; the stitches carry force before the gaps close, and positive shear resists more than
//   negative (shear bias, largest at low angles where the stitches dominate; the paper's text
//   gives no order, its Fig. 6c is not available: this is the model's order, see
//   docs/fabric-data.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "tests/workflow/cli_test_support.hpp"

namespace fs = std::filesystem;
using namespace ncfsim::test;

namespace {

struct FrameRun {
  nlohmann::json summary;
  std::vector<std::pair<double, double>> curve;  // (frame shear angle deg, normalised shear force N/m)
};

FrameRun run_frame(const std::string& which, const std::vector<std::string>& extra = {}) {
  const fs::path out = fresh_dir("pf_" + which);
  std::vector<std::string> args{"-q", "run", (kSource / ("cases/drape/picture_frame_" + which + ".toml")).string(),
                                "-o", out.string(), "--set", "output.figures=false", "--set", "output.report=false",
                                "--set", "output.frames=none"};
  args.insert(args.end(), extra.begin(), extra.end());
  const Result r = run_cli(args);
  EXPECT_EQ(r.code, 0) << r.output;
  FrameRun run;
  if (fs::exists(out / "summary.json")) run.summary = nlohmann::json::parse(slurp(out / "summary.json"));
  const History h = read_history(out / "history.csv");
  const std::size_t ca = h.column("frame_shear_angle_deg"), cf = h.column("frame_normalised_shear_force_N_per_m");
  EXPECT_LT(cf, h.columns.size());
  if (cf < h.columns.size())
    for (const auto& v : h.rows) run.curve.emplace_back(v[ca], v[cf]);
  fs::remove_all(out);
  return run;
}

double mean_force(const FrameRun& r, double a, double b) {
  double s = 0;
  int n = 0;
  for (const auto& [g, f] : r.curve)
    if (g >= a && g <= b) s += f, ++n;
  EXPECT_GT(n, 2) << "no history rows between " << a << " and " << b << " deg";
  return n > 0 ? s / n : 0.0;
}

// Least-squares line f = c0 + c1 g over [a, b].
std::pair<double, double> fit(const FrameRun& r, double a, double b) {
  double sg = 0, sf = 0, sgg = 0, sgf = 0;
  int n = 0;
  for (const auto& [g, f] : r.curve)
    if (g >= a && g <= b) sg += g, sf += f, sgg += g * g, sgf += g * f, ++n;
  EXPECT_GT(n, 2);
  const double c1 = (n * sgf - sg * sf) / (n * sgg - sg * sg);
  return {(sf - c1 * sg) / n, c1};
}

void expect_completed(const FrameRun& r, double final_angle) {
  ASSERT_FALSE(r.summary.is_null());
  EXPECT_EQ(r.summary["status"], "completed");
  EXPECT_LT(r.summary["energy_balance_error_max"].get<double>(), 0.01);
  ASSERT_FALSE(r.curve.empty());
  EXPECT_GT(r.curve.back().first, final_angle - 0.1);
}

}  // namespace

TEST(CliRegressionPictureFrame, UnstitchedForceRisesSteeplyIntoLocking) {
  const FrameRun u = run_frame("unstitched");
  expect_completed(u, 45.0);
  const double f45 = u.curve.back().second;
  double before = 0, running_max = 0, worst_drop = 1;
  for (const auto& [g, f] : u.curve) {
    if (g > 4.0 && g < 12.5) before = std::max(before, std::abs(f));
    if (g > 16.0) {
      if (running_max > 0) worst_drop = std::min(worst_drop, f / running_max);
      running_max = std::max(running_max, f);
    }
  }
  EXPECT_LT(before, 0.001 * f45) << "the tows rotate freely until their gaps close (14.1 deg)";
  EXPECT_GT(worst_drop, 0.95) << "the force must not drop once the tows compact (no overriding)";
  const auto early = fit(u, 20.0, 25.0), late = fit(u, 42.0, 45.0);
  EXPECT_GT(early.second, 0.0);
  EXPECT_GT(late.second, 10.0 * early.second) << "slope in the locking branch against the early compaction";
  // Tangent-intersection locking angle (measured 39.7 deg): between the gap-closing angle and the
  // angle at which the tows reach the locking branch of the law (0.75 w: 43.4 deg).
  const double lock = (early.first - late.first) / (late.second - early.second);
  EXPECT_GT(lock, 36.0);
  EXPECT_LT(lock, 43.4);
}

TEST(CliRegressionPictureFrame, StitchedPositiveAndNegativeCompleteWithShearBias) {
  // Half the case's end time (twice the shear rate; the kinetic energy stays < 1e-3 of the work).
  const std::vector<std::string> faster{"--set", "time.end_time=0.025"};
  const FrameRun p = run_frame("positive", faster);
  const FrameRun n = run_frame("negative", faster);
  expect_completed(p, 45.0);
  expect_completed(n, 45.0);
  // Before the gaps close only the stitches resist (unstitched: no force there).
  EXPECT_GT(mean_force(p, 8.0, 12.0), 1.0);
  EXPECT_GT(mean_force(n, 8.0, 12.0), 1.0);
  // Shear bias (measured 1.16 at 8-12 deg, 1.09 at 18-22 deg), fading as compaction takes over.
  EXPECT_GT(mean_force(p, 8.0, 12.0), 1.08 * mean_force(n, 8.0, 12.0));
  EXPECT_GT(mean_force(p, 18.0, 22.0), 1.04 * mean_force(n, 18.0, 22.0));
  EXPECT_GT(mean_force(p, 25.0, 30.0), mean_force(n, 25.0, 30.0));
  // Both lock like the unstitched fabric.
  EXPECT_GT(fit(p, 40.0, 43.0).second, 10.0 * fit(p, 20.0, 25.0).second);
  EXPECT_GT(fit(n, 40.0, 43.0).second, 10.0 * fit(n, 20.0, 25.0).second);
}
