// Picture-frame cases end to end (issue #4), through the ncfsim executable:
// - unstitched 6.64 mm unit cell: no force before the gaps close (14.1 deg), then tow compaction,
//   and the force rises steeply into the locking branch of the tow law (the tows reach 0.75 of
//   their width at 43.4 deg, 0.7 at 47.2 deg); it never drops and keeps locking to 52 deg (before
//   the frame walls, the compaction measure of the tow law and the in-plane plates the tows
//   bowed apart and rolled over each other from ~38 deg and the force fell; between unilateral
//   plates the compacted stack buckled into the room it gained by thinning and the tows overrode
//   each other from 49 deg: the cell is now held in its plane, docs/fabric-data.md);
// - stitched 2 x 2 cells, positive and negative shear: both complete to 52 deg with a balanced
//   energy and lock without a drop; the stitches carry force before the gaps close, and positive
//   shear resists more than negative (shear bias, fading as compaction takes over; the paper's
//   text gives no order, its Fig. 6c is not available: this is the model's order, see
//   docs/fabric-data.md). The frame holds the stitch lines' ends (every penetration of the 2 x 2
//   cell lies on the outline of its stitch lattice), so the stitch follows the frame exactly and
//   positive minus negative is the 'I' pillars' force from the frame kinematics alone (analytic,
//   below; the 'Lambda' underlaps run along a fibre direction and do not stretch in either sign).
// The bounds and the measured references are read from cases/drape/reference/picture_frame_*.csv.
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <utility>
#include <vector>

#include "fem/case/toml_reader.hpp"
#include "tests/workflow/cli_test_support.hpp"
#include "workflow/calibrate/calibrate_macro.hpp"

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

// Smallest f / (running maximum of f) over the rows with g > from: 1 when the force never drops.
double worst_drop_after(const FrameRun& r, double from) {
  double running_max = 0, worst = 1;
  for (const auto& [g, f] : r.curve)
    if (g > from) {
      if (running_max > 0) worst = std::min(worst, f / running_max);
      running_max = std::max(running_max, f);
    }
  return worst;
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

// The positive case's tabulated 'I' pillar law ([[bar_law]] "stitch_I", from its fabric file):
// strain, force (N).
std::pair<std::vector<double>, std::vector<double>> pillar_law() {
  const ncfsim::fem::CaseDocument doc =
      ncfsim::fem::CaseDocument::load(kSource / "cases/drape/picture_frame_positive.toml", {});
  const toml::table& root = doc.root();
  std::vector<double> strain, force;
  const toml::array* laws = root["bar_law"].as_array();
  EXPECT_NE(laws, nullptr) << "no [[bar_law]] in picture_frame_positive.toml or its includes";
  if (!laws) return {strain, force};
  for (const auto& node : *laws) {
    const toml::table& law = *node.as_table();
    if (law["name"].value_or(std::string()) != "stitch_I") continue;
    for (const auto& v : *law["strain"].as_array()) strain.push_back(v.value_or(NAN));
    for (const auto& v : *law["force"].as_array()) force.push_back(v.value_or(NAN));
  }
  EXPECT_GE(strain.size(), 2u) << "no stitch_I bar_law in picture_frame_positive.toml";
  return {strain, force};
}

// Normalised shear force (N/m) of the 'I' pillar stitches when they follow the frame exactly
// (paper Eq. 4-5, workflow::pillar_shear_force: the law calibrate macro --stitch-bars uses), with
// the case's tabulated stitch_I law; pillars a gauge apart: the tow pitch (3.22 + 0.10 mm) times
// sqrt(2).
double pillar_stitch_force(double g_deg) {
  static const auto [strain, force] = pillar_law();
  return ncfsim::workflow::pillar_shear_force(strain, force, 3.32e-3 * std::sqrt(2.0), g_deg);
}

double force_at(const FrameRun& r, double g) {
  for (std::size_t i = 1; i < r.curve.size(); ++i)
    if (r.curve[i - 1].first <= g && g <= r.curve[i].first) {
      const auto [g0, f0] = r.curve[i - 1];
      const auto [g1, f1] = r.curve[i];
      return f0 + (f1 - f0) * (g - g0) / (g1 - g0);
    }
  ADD_FAILURE() << "the frame did not reach " << g << " deg";
  return NAN;
}

// lower < value < upper of the reference row `q`.
void expect_within(const Reference& ref, const std::string& q, double value) {
  const double lo = ref.at(q, "lower"), hi = ref.at(q, "upper");
  EXPECT_TRUE(within(value, lo, hi)) << q << " = " << value << ", expected in (" << lo << ", " << hi << ") ("
                                     << ref.file.string() << ")";
}

void expect_completed(const FrameRun& r, const Reference& ref) {
  ASSERT_FALSE(r.summary.is_null());
  EXPECT_EQ(r.summary["status"], "completed");
  expect_within(ref, "energy_balance_error_max", r.summary["energy_balance_error_max"].get<double>());
  ASSERT_FALSE(r.curve.empty());
  expect_within(ref, "final_shear_angle_deg", r.curve.back().first);
}

}  // namespace

TEST(CliRegressionPictureFrame, UnstitchedForceRisesSteeplyIntoLocking) {
  const Reference ref = case_reference("drape", "picture_frame_unstitched");
  const FrameRun u = run_frame("unstitched");
  expect_completed(u, ref);
  const double f_last = u.curve.back().second;
  double before = 0;
  for (const auto& [g, f] : u.curve)
    if (g > 4.0 && g < 12.5) before = std::max(before, std::abs(f));
  // The tows rotate freely until their gaps close (14.1 deg).
  expect_within(ref, "force_before_gap_closing_ratio", before / f_last);
  // The force must not drop once the tows compact (no overriding), to the end (52 deg).
  expect_within(ref, "force_drop_ratio_after_16deg", worst_drop_after(u, 16.0));
  const auto early = fit(u, 20.0, 25.0), late = fit(u, 42.0, 45.0);
  EXPECT_GT(early.second, 0.0);
  // Slope in the locking branch against the early compaction.
  expect_within(ref, "locking_slope_ratio", late.second / early.second);
  // Tangent-intersection locking angle (measured 39.4 deg): between the gap-closing angle and the
  // angle at which the tows reach the locking branch of the law (0.75 w: 43.4 deg).
  const double lock = (early.first - late.first) / (late.second - early.second);
  expect_within(ref, "locking_angle_deg", lock);
  // Still locking past the locking width (0.7 w at 47.2 deg): the slope keeps rising.
  expect_within(ref, "locked_slope_ratio_48_52deg", fit(u, 48.0, 52.0).second / early.second);
}

TEST(CliRegressionPictureFrame, StitchedPositiveAndNegativeCompleteWithShearBias) {
  // At the case's rate: at twice that rate (the test's until the stitch was held) the negative
  // cell inverted a tow element at 51.6 deg, packed to ~0.6 of the tows' width.
  const Reference rp = case_reference("drape", "picture_frame_positive"),
                  rn = case_reference("drape", "picture_frame_negative");
  const FrameRun p = run_frame("positive");
  const FrameRun n = run_frame("negative");
  expect_completed(p, rp);
  expect_completed(n, rn);
  // Before the gaps close only the stitches resist (unstitched: no force there).
  expect_within(rp, "mean_force_8_12deg", mean_force(p, 8.0, 12.0));
  expect_within(rn, "mean_force_8_12deg", mean_force(n, 8.0, 12.0));
  // Shear bias (measured 1.16 at 8-12 deg, 1.09 at 18-22 deg), fading as compaction takes over.
  expect_within(rp, "bias_ratio_8_12deg", mean_force(p, 8.0, 12.0) / mean_force(n, 8.0, 12.0));
  expect_within(rp, "bias_ratio_18_22deg", mean_force(p, 18.0, 22.0) / mean_force(n, 18.0, 22.0));
  expect_within(rp, "bias_ratio_25_30deg", mean_force(p, 25.0, 30.0) / mean_force(n, 25.0, 30.0));
  // The held stitch: positive - negative is the pillars' kinematic force (measured within 0.01 %;
  // 2 % allowed).
  for (double g : {5.0, 10.0, 20.0, 30.0, 40.0}) {
    const double kin = pillar_stitch_force(g);
    EXPECT_NEAR(force_at(p, g) - force_at(n, g), kin, 0.02 * kin) << "at " << g << " deg";
  }
  // Both lock like the unstitched fabric (positive: the tows' share, less the pillars' kinematic
  // force, whose slope would hide the locking), and keep locking without a drop to 52 deg.
  FrameRun p_tows = p;
  for (auto& [g, f] : p_tows.curve) f -= pillar_stitch_force(g);
  for (const auto& [r, ref] : {std::pair{&std::as_const(p_tows), &rp}, std::pair{&n, &rn}}) {
    const double early = fit(*r, 20.0, 25.0).second;
    expect_within(*ref, "locking_slope_ratio", fit(*r, 40.0, 43.0).second / early);
    expect_within(*ref, "locked_slope_ratio_48_52deg", fit(*r, 48.0, 52.0).second / early);
    const FrameRun& whole = r == &p_tows ? p : *r;  // the frame's force does not drop
    expect_within(*ref, "force_drop_ratio_after_16deg", worst_drop_after(whole, 16.0));
    expect_within(*ref, "force_drop_ratio_after_40deg", worst_drop_after(whole, 40.0));
  }
}
