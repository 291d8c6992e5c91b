// The chain meso virtual test -> macro fabric law (issue #19):
// - `ncfsim calibrate macro` on synthetic meso runs (a straight F_sh = k g comes back exactly, a
//   falling stretch is held at the running maximum and reported, bad input exits 2);
// - the ideal-trellis bias-extension force of a frame curve is the derivative of the law's energy;
// - the macro picture frames (cases/drape/macro, the law calibrated from the meso frames) give the
//   meso normalised shear force within 10 % from 5 to 40 deg (the acceptance of #19);
// - the macro bias extensions keep their measured force and centre shear (the negative one
//   trellises, Eq. 2); at the meso coupons' centre angles their force lies within 2-25 % of the
//   meso force (the acceptance's 10 % is not met; the numbers are printed, docs/fabric-data.md).
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

// Acceptance of #19 for the frame: the macro picture frame with the calibrated law reproduces the
// meso frame's normalised shear force (cases/drape/reference/macro_chain_frame.csv, the meso runs
// fitted on the law's grid) within 10 % from 5 to 40 deg, for each sign.
TEST(CliVerificationMacroChain, PictureFramesReproduceTheMesoCurvesWithin10PercentTo40Deg) {
  const Reference ref = case_reference("drape", "macro_chain_frame");
  for (const auto& [cs, column] : {std::pair{"picture_frame", "positive_fitted"},
                                   {"picture_frame_negative", "negative_fitted"}}) {
    const fs::path out = fresh_dir(std::string("macro_") + cs);
    const auto r = run_cli(
        {"-q", "run", (kSource / "cases/drape/macro" / (std::string(cs) + ".toml")).string(), "-o",
         out.string(), "--set", "output.frames=none", "--set", "output.figures=false"});
    ASSERT_EQ(r.code, 0) << r.output;
    const History h = read_history(out / "history.csv");
    int checked = 0;
    for (std::size_t i = 0; i < ref.rows.size(); ++i) {
      const double g = ref.number(i, "shear_angle_deg");
      if (g < 5 || g > 40) continue;
      const double meso = ref.number(i, column), macro = frame_force_at(h, g);
      EXPECT_NEAR(macro, meso, 0.10 * meso) << cs << " at " << g << " deg";
      ++checked;
      if (g == 10 || g == 20 || g == 30 || g == 40)
        std::printf("%s %4.0f deg: macro %.3g N/m, meso %.3g N/m (%+.1f %%)\n", cs, g, macro, meso,
                    100 * (macro / meso - 1));
    }
    EXPECT_EQ(checked, 15);
  }
}

// The macro bias extension (cases/drape/macro/bias_extension_<sign>.toml): centre shear from its
// four probes on the fibre lines through the centre (90 deg - the angle of their chords).
void check_bias_extension(const std::string& sign) {
  const bool pos = sign == "positive";
  const std::string ax = pos ? "x" : "y";
  const double cx = pos ? 0.135 : 0.05, cy = pos ? 0.05 : 0.135, d = 0.0025;
  const fs::path out = fresh_dir("macro_bias_" + sign);
  const auto r = run_cli(
      {"-q", "run", (kSource / ("cases/drape/macro/bias_extension_" + sign + ".toml")).string(),
       "-o", out.string(), "--set", "output.frames=none", "--set", "output.figures=false"});
  ASSERT_EQ(r.code, 0) << r.output;
  const History h = read_history(out / "history.csv");
  const auto jd = h.column("grip_displacement_" + ax + "_m"),
             jf = h.column("pull_reaction_" + ax + "_N");
  ASSERT_LT(jd, h.columns.size());
  ASSERT_LT(jf, h.columns.size());
  auto point = [&](const std::vector<double>& row, const std::string& p, double ox, double oy) {
    return std::array<double, 2>{cx + ox + row[h.column(p + "_displacement_x_m")],
                                 cy + oy + row[h.column(p + "_displacement_y_m")]};
  };
  auto shear = [&](const std::vector<double>& row) {
    const auto pp = point(row, "c_pp", d, d), mm = point(row, "c_mm", -d, -d);
    const auto pm = point(row, "c_pm", d, -d), mp = point(row, "c_mp", -d, d);
    const double a0 = pp[0] - mm[0], a1 = pp[1] - mm[1], b0 = pm[0] - mp[0], b1 = pm[1] - mp[1];
    const double c = (a0 * b0 + a1 * b1) / std::hypot(a0, a1) / std::hypot(b0, b1);
    return std::abs(90 - 180 / M_PI * std::acos(c));
  };
  const Reference ref = case_reference("drape", "macro_chain_bias_" + sign);
  // The macro coupon's force at a centre shear angle (linear between its history rows; the centre
  // shears monotonically).
  auto macro_force_at_angle = [&](double g) {
    double g0 = 0, f0 = 0;
    for (std::size_t k = 1; k < h.rows.size(); ++k) {
      const double g1 = shear(h.rows[k]), f1 = std::abs(h.rows[k][jf]);
      if (g1 >= g && g1 > g0) return f0 + (f1 - f0) * (g - g0) / (g1 - g0);
      if (g1 > g0) g0 = g1, f0 = f1;
    }
    return std::numeric_limits<double>::quiet_NaN();  // the macro centre does not get there
  };
  for (std::size_t i = 0; i < ref.rows.size(); ++i) {
    const double mm = ref.number(i, "extension_mm");
    std::size_t k = 1;
    while (k < h.rows.size() && std::abs(h.rows[k][jd]) < 1e-3 * mm) ++k;
    ASSERT_LT(k, h.rows.size()) << "the run did not reach " << mm << " mm";
    const double w = (1e-3 * mm - std::abs(h.rows[k - 1][jd])) /
                     (std::abs(h.rows[k][jd]) - std::abs(h.rows[k - 1][jd]));
    const double force = std::abs(h.rows[k - 1][jf] + w * (h.rows[k][jf] - h.rows[k - 1][jf]));
    const double g = shear(h.rows[k - 1]) + w * (shear(h.rows[k]) - shear(h.rows[k - 1]));
    EXPECT_NEAR(force, ref.number(i, "macro_force_N"), 0.10 * ref.number(i, "macro_force_N"))
        << sign << " at " << mm << " mm";
    EXPECT_NEAR(g, ref.number(i, "macro_centre_shear_deg"), 1.0) << sign << " at " << mm << " mm";
    if (!pos && mm <= 20) {  // the soft negative coupon trellises
      EXPECT_NEAR(g, ref.number(i, "eq2_shear_deg"), 1.5) << sign << " at " << mm << " mm";
    }
    // Against the meso coupon (the chain's acceptance, 10 %, not met: the reference's header):
    // the macro force at the meso centre's angle, within the measured agreement.
    const double g_meso = ref.number(i, "meso_centre_shear_deg"),
                 f_meso = ref.number(i, "meso_force_N");
    const double f_macro = macro_force_at_angle(g_meso), band = ref.number(i, "meso_band");
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

TEST(CliVerificationMacroChain, BiasExtensionPositiveKeepsItsForceAndFollowsTheMesoCoupon) {
  check_bias_extension("positive");
}
TEST(CliVerificationMacroChain, BiasExtensionNegativeKeepsItsForceAndFollowsTheMesoCoupon) {
  check_bias_extension("negative");
}

}  // namespace
}  // namespace ncfsim::test
