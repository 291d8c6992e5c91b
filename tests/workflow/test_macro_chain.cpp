// The chain meso virtual test -> macro fabric law (issue #19):
// - `ncfsim calibrate macro` on synthetic meso runs (a straight F_sh = k g comes back exactly, a
//   falling stretch is held at the running maximum and reported, bad input exits 2);
// - the ideal-trellis bias-extension force of a frame curve is the derivative of the law's energy;
// - the macro picture frames (cases/drape/macro, the law calibrated from the meso frames) give the
//   meso normalised shear force within 10 % from 5 to 40 deg (the acceptance of #19);
// - the macro bias extensions keep their measured force and centre shear (the negative one
//   trellises, Eq. 2); at the meso coupons' centre angles their force lies within 2-25 % of the
//   meso force (the acceptance's 10 % is not met; the numbers are printed, docs/fabric-data.md);
// - the stitched macro model (cases/drape/macro/stitched: the stitch as bars sewn onto the shells)
//   gives the meso frames back within 1 % and the meso bias coupons' force and centre shear at each
//   extension within 10 % / 1-3 deg, except the positive coupon's first 5 mm (+11 %) and the
//   negative one's 40 mm (not checked: +40 %);
// - a stitch line pulled through clamped shells carries the sum of its sliding forces (Coulomb).
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <cmath>
#include <fstream>
#include <limits>

#include "tests/workflow/cli_test_support.hpp"
#include "workflow/calibrate/calibrate_macro.hpp"

namespace ncfsim::test {
namespace {

// A run folder as a meso picture frame leaves it: summary.json and history.csv with the frame's
// angle and normalised force columns, F = force(g) every 0.25 deg from 0 to `top`.
template <class F>
fs::path fake_frame_run(const std::string& name, double top, F force,
                        const std::string& status = "completed") {
  const fs::path d = fresh_dir(name);
  fs::create_directories(d);
  std::ofstream(d / "summary.json") << R"({"case": ")" << name << R"(", "status": ")" << status
                                    << R"(", "ncfsim_version": "test"})";
  std::ofstream h(d / "history.csv");
  h << "time,frame_shear_angle_deg,frame_normalised_shear_force_N_per_m\n";
  for (int i = 0; i * 0.25 <= top + 1e-9; ++i)
    h << i << "," << i * 0.25 << "," << force(i * 0.25) << "\n";
  return d;
}

std::vector<double> numbers(const toml::table& t, const char* key) {
  std::vector<double> v;
  if (const auto* a = t.at_path(key).as_array())
    for (const auto& e : *a) v.push_back(e.value<double>().value_or(NAN));
  return v;
}

toml::table first_law(const fs::path& file) {
  const toml::table root = toml::parse_file(file.string());
  return *root["membrane_law"].as_array()->at(0).as_table();
}

TEST(CliMacroCalibration, LineComesBackExactlyAndAFallIsHeldAtTheRunningMaximum) {
  // Positive: F = 2 g up to 40 deg, then falling to 70 % by 45 deg and rising again (a meso frame
  // whose tows override); negative: F = 1.5 g.
  const auto pos = fake_frame_run("mc_pos", 50, [](double g) {
    return g <= 40 ? 2 * g : g <= 45 ? 80 - 4.8 * (g - 40) : 56 + 10 * (g - 45);
  });
  const auto neg = fake_frame_run("mc_neg", 50, [](double g) { return 1.5 * g; });
  const fs::path out = fresh_dir("mc_out") / "law.toml";
  const auto r = run_cli({"calibrate", "macro", "--positive", pos.string(), "--negative",
                          neg.string(), "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("positive: the meso force falls from 42.5 deg"), std::string::npos)
      << r.output;
  const std::string text = slurp(out);
  EXPECT_NE(text.find("# MONOTONE: positive"), std::string::npos);
  const auto law = first_law(out);
  const auto a = numbers(law, "shear_angle_deg"), f = numbers(law, "shear_force");
  const auto an = numbers(law, "negative_shear_angle_deg"),
             fn = numbers(law, "negative_shear_force");
  ASSERT_EQ(a.size(), 21u);  // 0, 2.5, ..., 50
  ASSERT_EQ(an.size(), 21u);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(a[i], 2.5 * i, 1e-12);
    if (i) {
      EXPECT_GE(f[i], f[i - 1]) << "at " << a[i] << " deg";  // monotone
    }
    if (a[i] <= 37.5) {
      EXPECT_NEAR(f[i], 2 * a[i], 1e-3 * (1 + f[i]));  // a straight line: exact
    }
    EXPECT_NEAR(fn[i], 1.5 * a[i], 1e-3 * (1 + fn[i]));
  }
  EXPECT_EQ(f[0], 0.0);
  // 40 deg: the fit over 38.75-41.25 deg straddles the peak (80 N/m), below it, not above
  EXPECT_GT(f[16], 75);
  EXPECT_LE(f[16], 80);
  EXPECT_EQ(f[17], f[16]);  // 42.5 deg: held (the data: 68 N/m)
  EXPECT_EQ(f[18], f[16]);  // 45 deg: held (the data: 56 N/m)
  EXPECT_EQ(law["type"].value<std::string>(), "fabric");

  // A case includes the file: the law is valid for the reader (`ncfsim check`).
  const fs::path dir = out.parent_path();
  std::ofstream(dir / "frame.toml") << "include = \"law.toml\"\n"
                                       "[case]\nname = \"frame\"\n"
                                       "[[mesh.plate]]\npart = \"fabric\"\nsize = [0.01, 0.01]\n"
                                       "divisions = [2, 2]\n"
                                       "[[part]]\nname = \"fabric\"\nmembrane_law = \"ncf_macro\"\n"
                                       "thickness = 0.0005\n"
                                       "[time]\nend_time = 0.001\n";
  const auto c = run_cli({"check", (dir / "frame.toml").string()});
  EXPECT_EQ(c.code, 0) << c.output;
}

TEST(CliMacroCalibration, SymmetricIsTheMeanOfTheTwoSigns) {
  const auto pos = fake_frame_run("mcs_pos", 30, [](double g) { return 2 * g; });
  const auto neg = fake_frame_run("mcs_neg", 20, [](double g) { return 1.0 * g; });
  const fs::path out = fresh_dir("mcs_out") / "law.toml";
  const auto r = run_cli({"calibrate", "macro", "--positive", pos.string(), "--negative",
                          neg.string(), "--symmetric", "--step", "5", "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto law = first_law(out);
  const auto a = numbers(law, "shear_angle_deg"), f = numbers(law, "shear_force");
  ASSERT_EQ(a.size(), 5u);  // 0 .. 20: as far as both signs reach
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(f[i], 1.5 * a[i], 1e-6 * (1 + f[i]));
  EXPECT_FALSE(law.contains("negative_shear_force"));
}

// --stitch-bars: the positive frame less its pillars' kinematic force (paper Eq. 4-5, the pillar
// law and gauge of the positive run's case.toml) is the tows' curve; the pillar law is written
// beside the membrane law. A positive frame made of F = 2 g plus the pillars gives 2 g back.
TEST(CliMacroCalibration, StitchBarsSubtractThePillarsKinematicForce) {
  const std::vector<double> strain{0, 0.05, 0.4}, force{0, 1.0, 12.0};
  const double gauge = 4e-3;
  const auto pos = fake_frame_run("mcsb_pos", 40, [&](double g) {
    return 2 * g + workflow::pillar_shear_force(strain, force, gauge, g);
  });
  std::ofstream(pos / "case.toml")
      << "[[mesh.fabric]]\nname = \"cell\"\nstitch_law_I = \"pillar\"\nstitch_gauge = 4e-3\n"
         "[[bar_law]]\nname = \"pillar\"\ntype = \"tabulated\"\ntension_only = true\n"
         "linear_density = 7e-6\nstrain = [0, 0.05, 0.4]\nforce = [0, 1.0, 12.0]\n";
  const auto neg = fake_frame_run("mcsb_neg", 40, [](double g) { return 2 * g; });
  const fs::path out = fresh_dir("mcsb_out") / "law.toml";
  const auto r = run_cli({"calibrate", "macro", "--positive", pos.string(), "--negative",
                          neg.string(), "--stitch-bars", "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  // The pillars' force at 30 deg: e = sqrt(2) cos(30 deg) - 1 = 0.2247, T = 1 + 11 (0.1747 /
  // 0.35) = 6.49 N, de/dg = sqrt(2)/2 sin(30 deg) = 0.354: T de/dg / G / cos(30 deg) = 662.7 N/m.
  EXPECT_NEAR(workflow::pillar_shear_force(strain, force, gauge, 30), 662.7, 0.5);
  const auto law = first_law(out);
  const auto a = numbers(law, "shear_angle_deg"), f = numbers(law, "shear_force");
  ASSERT_EQ(a.size(), 17u);
  // Within the resampling's smoothing of the frame curve (a line through +-1.25 deg of rows; the
  // pillars' curve has a kink at 5.9 deg, e = 0.05): 0.5 % of the positive frame's force.
  for (std::size_t i = 1; i < a.size(); ++i)
    EXPECT_NEAR(f[i], 2 * a[i],
                0.005 * (2 * a[i] + workflow::pillar_shear_force(strain, force, gauge, a[i])))
        << a[i];
  const toml::table root = toml::parse_file(out.string());
  const auto* bars = root["bar_law"].as_array();
  ASSERT_TRUE(bars && bars->size() == 1);
  EXPECT_EQ((*bars->at(0).as_table())["name"].value<std::string>(), "pillar");
  // Without the meso case's fabric: exit 2 naming the key.
  fs::remove(pos / "case.toml");
  std::ofstream(pos / "case.toml") << "[case]\nname = \"x\"\n";
  const auto bad = run_cli({"calibrate", "macro", "--positive", pos.string(), "--negative",
                            neg.string(), "--stitch-bars", "-o", out.string()});
  EXPECT_EQ(bad.code, 2);
  EXPECT_NE(bad.output.find("mesh.fabric"), std::string::npos) << bad.output;
}

TEST(CliMacroCalibration, BadInputExits2NamingFileAndKey) {
  const auto good = fake_frame_run("mcb_good", 30, [](double g) { return g; });
  const auto broken = fake_frame_run(
      "mcb_broken", 30, [](double g) { return g; }, "numerical_failure");
  const fs::path out = fresh_dir("mcb_out") / "law.toml";
  auto r = run_cli({"calibrate", "macro", "--positive", good.string(), "--negative",
                    broken.string(), "-o", out.string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("summary.json"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("numerical_failure"), std::string::npos) << r.output;
  r = run_cli({"calibrate", "macro", "--positive", good.string(), "--negative", good.string(),
               "--frame", "rig", "-o", out.string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_NE(r.output.find("rig_shear_angle_deg"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("history.csv"), std::string::npos) << r.output;
  r = run_cli({"calibrate", "macro", "--positive", (good / "nothing").string(), "--negative",
               good.string(), "-o", out.string()});
  EXPECT_EQ(r.code, 2);
  EXPECT_FALSE(fs::exists(out));
}

// Ideal trellis: F dD = dE with E = A_A W(g) + A_B W(g/2), W(g) = int_0^g F_sh cos: the force is
// the derivative of that energy (here by a central difference of its quadrature).
TEST(MacroCalibration, TrellisForceIsTheDerivativeOfTheLawEnergy) {
  workflow::FrameCurve c{{0, 10, 20, 30, 40}, {0, 5, 12, 30, 90}};
  const double H = 0.25, W = 0.10;
  auto energy_density = [&](double g_deg) {  // int_0^g F_sh(g') cos g' dg', midpoint rule
    const int n = 4000;
    double s = 0;
    for (int i = 0; i < n; ++i) {
      const double g = (i + 0.5) / n * g_deg;
      s += workflow::curve_force(c, g) * std::cos(g * M_PI / 180);
    }
    return s * g_deg * M_PI / 180 / n;
  };
  auto energy = [&](double D) {
    const double L0 = H - W;
    const double g = 90 - 2 * 180 / M_PI * std::acos((L0 + D) / (std::sqrt(2.0) * L0));
    return W * (H - 1.5 * W) * energy_density(g) + W * W * energy_density(0.5 * g);
  };
  for (double D : {0.005, 0.02, 0.04}) {
    const double h = 1e-5;
    const double expected = (energy(D + h) - energy(D - h)) / (2 * h);
    EXPECT_NEAR(workflow::bias_extension_force_from_curve(c, H, W, D), expected, 2e-3 * expected)
        << "D = " << D;
  }
}

// The normalised frame force of a macro picture frame at angle g (linear in the history rows).
double frame_force_at(const History& h, double g) {
  const auto ia = h.column("frame_shear_angle_deg"),
             jf = h.column("frame_normalised_shear_force_N_per_m");
  for (std::size_t r = 1; r < h.rows.size(); ++r)
    if (h.rows[r][ia] >= g) {
      const double g0 = h.rows[r - 1][ia], g1 = h.rows[r][ia];
      const double w = g1 > g0 ? (g - g0) / (g1 - g0) : 1.0;
      return h.rows[r - 1][jf] + w * (h.rows[r][jf] - h.rows[r - 1][jf]);
    }
  return NAN;
}

// The macro frames of a folder (cases/drape/macro/<dir>: `positive` and `negative` case names)
// against the meso frames' normalised shear force (macro_chain_frame.csv) from 5 to 40 deg: within
// 10 % (the acceptance of #19) and within `measured` of the meso force (plus 0.2 N/m).
void check_macro_frames(const std::string& dir, const std::string& positive,
                        const std::string& negative, double measured) {
  const Reference ref = case_reference("drape", "macro_chain_frame");
  for (const auto& [cs, column] :
       {std::pair{positive, "positive_fitted"}, {negative, "negative_fitted"}}) {
    const fs::path out = fresh_dir("macro_" + dir + "_" + cs);
    const auto r =
        run_cli({"-q", "run", (kSource / "cases/drape" / dir / (cs + ".toml")).string(), "-o",
                 out.string(), "--set", "output.frames=none", "--set", "output.figures=false"});
    ASSERT_EQ(r.code, 0) << r.output;
    const History h = read_history(out / "history.csv");
    int checked = 0;
    for (std::size_t i = 0; i < ref.rows.size(); ++i) {
      const double g = ref.number(i, "shear_angle_deg");
      if (g < 5 || g > 40) continue;
      const double meso = ref.number(i, column), macro = frame_force_at(h, g);
      EXPECT_NEAR(macro, meso, 0.10 * meso) << cs << " at " << g << " deg";
      EXPECT_NEAR(macro, meso, measured * meso + 0.2) << cs << " at " << g << " deg (as measured)";
      ++checked;
      if (g == 10 || g == 20 || g == 30 || g == 40)
        std::printf("%s/%s %4.0f deg: macro %.3g N/m, meso %.3g N/m (%+.1f %%)\n", dir.c_str(),
                    cs.c_str(), g, macro, meso, 100 * (macro / meso - 1));
    }
    EXPECT_EQ(checked, 15);
  }
}

// Acceptance of #19 for the frame: the macro picture frame with the calibrated law reproduces the
// meso frame's normalised shear force (cases/drape/reference/macro_chain_frame.csv, the meso runs
// fitted on the law's grid) within 10 % from 5 to 40 deg, for each sign.
TEST(CliVerificationMacroChain, PictureFramesReproduceTheMesoCurvesWithin10PercentTo40Deg) {
  check_macro_frames("macro", "picture_frame", "picture_frame_negative", 0.02);
}

// A macro bias-extension run (case `case_rel` under the source tree): force and centre shear at a
// grip extension, centre shear from its four probes on the fibre lines through the centre (90 deg
// - the angle of their chords).
struct MacroBiasRun {
  History h;
  std::string sign;
  std::size_t jd = 0, jf = 0;
  double cx = 0, cy = 0;
  std::array<double, 2> point(const std::vector<double>& row, const std::string& p, double ox,
                              double oy) const {
    return {cx + ox + row[h.column(p + "_displacement_x_m")],
            cy + oy + row[h.column(p + "_displacement_y_m")]};
  }
  double shear(const std::vector<double>& row) const {
    const double d = 0.0025;
    const auto pp = point(row, "c_pp", d, d), mm = point(row, "c_mm", -d, -d);
    const auto pm = point(row, "c_pm", d, -d), mp = point(row, "c_mp", -d, d);
    const double a0 = pp[0] - mm[0], a1 = pp[1] - mm[1], b0 = pm[0] - mp[0], b1 = pm[1] - mp[1];
    const double c = (a0 * b0 + a1 * b1) / std::hypot(a0, a1) / std::hypot(b0, b1);
    return std::abs(90 - 180 / M_PI * std::acos(c));
  }
  // {force N, centre shear deg} at extension mm (linear between the history rows); NaN past the
  // end.
  std::array<double, 2> at_extension(double mm) const {
    std::size_t k = 1;
    while (k < h.rows.size() && std::abs(h.rows[k][jd]) < 1e-3 * mm) ++k;
    if (k >= h.rows.size()) return {NAN, NAN};
    const double w = (1e-3 * mm - std::abs(h.rows[k - 1][jd])) /
                     (std::abs(h.rows[k][jd]) - std::abs(h.rows[k - 1][jd]));
    return {std::abs(h.rows[k - 1][jf] + w * (h.rows[k][jf] - h.rows[k - 1][jf])),
            shear(h.rows[k - 1]) + w * (shear(h.rows[k]) - shear(h.rows[k - 1]))};
  }
  // The force at a centre shear angle (linear between rows; the centre shears monotonically).
  double force_at_angle(double g) const {
    double g0 = 0, f0 = 0;
    for (std::size_t k = 1; k < h.rows.size(); ++k) {
      const double g1 = shear(h.rows[k]), f1 = std::abs(h.rows[k][jf]);
      if (g1 >= g && g1 > g0) return f0 + (f1 - f0) * (g - g0) / (g1 - g0);
      if (g1 > g0) g0 = g1, f0 = f1;
    }
    return std::numeric_limits<double>::quiet_NaN();  // the macro centre does not get there
  }
};

// Row i of a reference: the run's {force, centre shear} at its extension, checked against the
// reference's own macro columns (regression: force within force_tol, centre within 1 deg).
std::array<double, 2> expect_reference_row(const MacroBiasRun& run, const Reference& ref,
                                           std::size_t i, double force_tol) {
  const double mm = ref.number(i, "extension_mm");
  const auto fg = run.at_extension(mm);
  EXPECT_FALSE(std::isnan(fg[0])) << "the run did not reach " << mm << " mm";
  EXPECT_NEAR(fg[0], ref.number(i, "macro_force_N"), force_tol * ref.number(i, "macro_force_N"))
      << run.sign << " at " << mm << " mm";
  EXPECT_NEAR(fg[1], ref.number(i, "macro_centre_shear_deg"), 1.0)
      << run.sign << " at " << mm << " mm";
  return fg;
}

MacroBiasRun run_macro_bias(const std::string& case_rel, const std::string& sign) {
  MacroBiasRun r;
  r.sign = sign;
  const bool pos = sign == "positive";
  const std::string ax = pos ? "x" : "y";
  r.cx = pos ? 0.135 : 0.05, r.cy = pos ? 0.05 : 0.135;
  const fs::path out = fresh_dir("macro_bias_" + sign);
  const auto c = run_cli({"-q", "run", (kSource / case_rel).string(), "-o", out.string(), "--set",
                          "output.frames=none", "--set", "output.figures=false"});
  EXPECT_EQ(c.code, 0) << c.output;
  if (c.code != 0) return r;
  r.h = read_history(out / "history.csv");
  r.jd = r.h.column("grip_displacement_" + ax + "_m"),
  r.jf = r.h.column("pull_reaction_" + ax + "_N");
  EXPECT_LT(r.jd, r.h.columns.size());
  EXPECT_LT(r.jf, r.h.columns.size());
  return r;
}

// The classic macro bias extension (cases/drape/macro/bias_extension_<sign>.toml).
void check_bias_extension(const std::string& sign) {
  const bool pos = sign == "positive";
  const MacroBiasRun run =
      run_macro_bias("cases/drape/macro/bias_extension_" + sign + ".toml", sign);
  ASSERT_FALSE(run.h.rows.empty());
  const Reference ref = case_reference("drape", "macro_chain_bias_" + sign);
  for (std::size_t i = 0; i < ref.rows.size(); ++i) {
    const double mm = ref.number(i, "extension_mm");
    const auto [force, g] = expect_reference_row(run, ref, i, 0.10);
    if (std::isnan(force)) return;
    if (!pos && mm <= 20) {  // the soft negative coupon trellises
      EXPECT_NEAR(g, ref.number(i, "eq2_shear_deg"), 1.5) << sign << " at " << mm << " mm";
    }
    // Against the meso coupon (the chain's acceptance, 10 %, not met: the reference's header):
    // the macro force at the meso centre's angle, within the measured agreement.
    const double g_meso = ref.number(i, "meso_centre_shear_deg"),
                 f_meso = ref.number(i, "meso_force_N");
    const double f_macro = run.force_at_angle(g_meso), band = ref.number(i, "meso_band");
    if (!std::isnan(band)) {
      EXPECT_NEAR(f_macro, f_meso, band * f_meso)
          << sign << " at the meso centre's " << g_meso << " deg (" << mm << " mm)";
    }
    std::printf(
        "%s %2.0f mm: macro %.3g N, %.1f deg | meso %.3g N, %.1f deg | macro at %.1f deg: %.3g N "
        "(%+.0f %%) | trellis %.3g N, Eq. 2 %.1f deg\n",
        sign.c_str(), mm, force, g, f_meso, g_meso, g_meso, f_macro, 100 * (f_macro / f_meso - 1),
        ref.number(i, "trellis_force_N"), ref.number(i, "eq2_shear_deg"));
  }
}

// The stitched macro bias extension (cases/drape/macro/stitched/bias_extension_<sign>.toml)
// against the meso coupon held flat as the macro one is (meso_bias_extension_<sign>_flat.toml), as
// the paper compares bias tests (Figs. 14, 15): force and centre shear at each extension, within
// the reference's bands (10 %: the chain's acceptance).
void check_stitched_bias_extension(const std::string& sign) {
  const MacroBiasRun run =
      run_macro_bias("cases/drape/macro/stitched/bias_extension_" + sign + ".toml", sign);
  ASSERT_FALSE(run.h.rows.empty());
  const Reference ref = case_reference("drape", "macro_chain_stitched_bias_" + sign);
  for (std::size_t i = 0; i < ref.rows.size(); ++i) {
    const double mm = ref.number(i, "extension_mm");
    const auto [force, g] = expect_reference_row(run, ref, i, 0.05);
    if (std::isnan(force)) return;
    const double f_meso = ref.number(i, "meso_force_N"),
                 g_meso = ref.number(i, "meso_centre_shear_deg");
    const double band = ref.number(i, "meso_force_band"),
                 gband = ref.number(i, "meso_shear_band_deg");
    if (!std::isnan(band)) {
      EXPECT_NEAR(force, f_meso, band * f_meso)
          << sign << " at " << mm << " mm, against the meso coupon";
      EXPECT_NEAR(g, g_meso, gband) << sign << " at " << mm << " mm, against the meso coupon";
    }
    std::printf("stitched %s %2.0f mm: macro %.3g N, %.1f deg | meso %.3g N, %.1f deg (%+.1f %%)\n",
                sign.c_str(), mm, force, g, f_meso, g_meso, 100 * (force / f_meso - 1));
  }
}

TEST(CliVerificationMacroChain, BiasExtensionPositiveKeepsItsForceAndFollowsTheMesoCoupon) {
  check_bias_extension("positive");
}
TEST(CliVerificationMacroChain, BiasExtensionNegativeKeepsItsForceAndFollowsTheMesoCoupon) {
  check_bias_extension("negative");
}

TEST(CliVerificationMacroChain, StitchedBiasExtensionPositiveFollowsTheMesoCouponHeldFlat) {
  check_stitched_bias_extension("positive");
}
TEST(CliVerificationMacroChain, StitchedBiasExtensionNegativeFollowsTheMesoCouponHeldFlat) {
  check_stitched_bias_extension("negative");
}

// The stitched macro frames: the shells' tows' curves and the pillars' bars together give the meso
// frames back (the acceptance's 10 %, measured within 1 %): the pillars' bars, sewn on and held at
// their ends by the frame, carry their Eq. 4-5 force.
TEST(CliVerificationMacroChain, StitchedPictureFramesReproduceTheMesoCurvesWithin10PercentTo40Deg) {
  check_macro_frames("macro/stitched", "picture_frame_positive", "picture_frame_negative", 0.02);
}

// A 40 mm line of 17 stitch nodes 2.5 mm apart (gauge and stitch length equal to the line's
// spacings: 16 penetrations of 0.05 N, a line end standing for half of one) sewn onto clamped
// shells and pulled out by its end at 50 mm/s: once every node slides the pull is the sum of their
// sliding forces, 0.8 N (Coulomb), and the friction work grows at that force times the speed.
TEST(CliVerificationShellStitch, LinePulledThroughClampedFabricCarriesTheSumOfItsSlidingForces) {
  const fs::path dir = fresh_dir("shell_stitch_pull");
  fs::create_directories(dir);
  std::ofstream(dir / "pull.toml") << R"([case]
name = "stitch_pull_through"
[[mesh.plate]]
part = "fabric"
size = [0.04, 0.005]
divisions = [16, 3]
[[mesh.shell_stitch]]
name = "stitch"
part = "fabric"
direction = [1.0, 0.0, 0.0]
law = "yarn"
gauge = 0.005
stitch_length = 0.0025
line_spacing = 0.005
point_spacing = 0.0025
sliding_force = 0.05
[[material]]
name = "steel"
type = "elastic_isotropic"
density = 7850.0
youngs_modulus = 200e9
poisson_ratio = 0.3
[[bar_law]]
name = "yarn"
type = "tabulated"
tension_only = true
linear_density = 1e-3
strain = [0.0, 0.1]
force = [0.0, 100.0]
[[part]]
name = "fabric"
material = "steel"
thickness = 0.001
[[boundary.fixed]]
name = "fabric"
nodes = { part = "fabric", all = true }
rotations = ["x", "y", "z"]
[[boundary.velocity]]
name = "pull"
nodes = { box_min = [0.0399, 0.0024, -1.0], box_max = [0.0401, 0.0026, 1.0] }
velocity = [0.05, 0.0, 0.0]
dofs = ["x", "y", "z"]
ramp_time = 0.002
[time]
end_time = 0.02
history_interval = 2e-4
[output]
frames = "none"
figures = false
)";
  const auto r = run_cli({"-q", "run", (dir / "pull.toml").string(), "-o", (dir / "out").string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const History h = read_history(dir / "out" / "history.csv");
  const auto jt = h.column("time"), jf = h.column("pull_reaction_x_N"),
             jw = h.column("friction_energy_J"), je = h.column("energy_balance_error");
  double sum = 0, w0 = NAN, t0 = NAN, w1 = 0, t1 = 0;
  int n = 0;
  for (const auto& row : h.rows) {
    if (row[jt] < 0.01 - 1e-9) continue;
    sum += std::abs(row[jf]), ++n;
    if (std::isnan(w0)) w0 = row[jw], t0 = row[jt];
    w1 = row[jw], t1 = row[jt];
    EXPECT_LT(std::abs(row[je]), 0.01);
  }
  ASSERT_GT(n, 10);
  EXPECT_NEAR(sum / n, 16 * 0.05, 0.02 * 0.8) << "mean pull over 10-20 ms";
  EXPECT_NEAR((w1 - w0) / (t1 - t0), 0.8 * 0.05, 0.02 * 0.8 * 0.05) << "friction power";
}

// The sliders' slips are in the checkpoint: the stitched positive coupon stopped at 6000 cycles
// (18 ms, its sliders sliding) and resumed gives the uninterrupted run's history bit for bit.
TEST(CliRegressionShellStitch, StitchedCouponResumesBitForBit) {
  const std::string c =
      (kSource / "cases/drape/macro/stitched/bias_extension_positive.toml").string();
  const fs::path full = fresh_dir("stitch_resume_full"), part = fresh_dir("stitch_resume_part");
  const std::vector<std::string> quiet = {"--set", "output.frames=none", "--set",
                                          "output.figures=false"};
  auto args = [&](const fs::path& out, std::vector<std::string> more) {
    std::vector<std::string> a = {"-q", "run", c, "-o", out.string()};
    a.insert(a.end(), quiet.begin(), quiet.end());
    a.insert(a.end(), more.begin(), more.end());
    return a;
  };
  ASSERT_EQ(run_cli(args(full, {})).code, 0);
  ASSERT_EQ(run_cli(args(part, {"--set", "time.max_cycles=6000"})).code, 1);  // stopped, kept
  const auto r = run_cli(args(part, {"--resume"}));
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_EQ(slurp(full / "history.csv"), slurp(part / "history.csv"));
}

// Bad [[mesh.shell_stitch]] input: exit 2 naming the file and the key (and never a run that
// allocates a line per nanometre).
TEST(CliShellStitch, BadInputExits2NamingTheKey) {
  const std::string c =
      (kSource / "cases/drape/macro/stitched/bias_extension_positive.toml").string();
  for (const auto& [set, key] :
       {std::pair{"mesh.shell_stitch[0].line_spacing=1e-9", "mesh.shell_stitch[0].line_spacing"},
        {"mesh.shell_stitch[0].law='nothing'", "mesh.shell_stitch[0].law"},
        {"mesh.shell_stitch[0].part='nothing'", "mesh.shell_stitch[0].part"},
        {"mesh.shell_stitch[0].direction=[0.0, 0.0, 1.0]", "mesh.shell_stitch[0].direction"},
        {"mesh.shell_stitch[0].sliding_force=0", "mesh.shell_stitch[0].sliding_force"},
        {"mesh.shell_stitch[0].name='fabric'", "mesh.shell_stitch[0].name"}}) {
    const auto r = run_cli({"check", c, "--set", set});
    EXPECT_EQ(r.code, 2) << set << ": " << r.output;
    EXPECT_NE(r.output.find(key), std::string::npos) << set << ": " << r.output;
    EXPECT_NE(r.output.find("bias_extension_positive.toml"), std::string::npos) << r.output;
  }
}

}  // namespace
}  // namespace ncfsim::test
