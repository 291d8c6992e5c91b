// The ncfsim command line end to end: bad input gives exit code 2 and names the key; the
// cantilever verification case runs to Euler-Bernoulli through the CLI (regression); an
// interrupted run leaves readable results; the report references its figures by relative path.
#include <gtest/gtest.h>
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include <nlohmann/json.hpp>

#include "drape/stitch_calibration.hpp"
#include "fem/io/result_reader.hpp"
#include "tests/workflow/cli_test_support.hpp"

namespace fs = std::filesystem;
using namespace ncfsim::test;

namespace {

}  // namespace

struct BadCase {
  const char* file;
  const char* key;
};
void PrintTo(const BadCase& c, std::ostream* os) { *os << c.file; }

class BadInput : public ::testing::TestWithParam<BadCase> {};

TEST_P(BadInput, ExitCodeTwoNamingTheKey) {
  const fs::path file = kSource / "tests/cases/bad" / GetParam().file;
  for (const char* cmd : {"check", "run"}) {
    const fs::path out = fresh_dir("bad");
    std::vector<std::string> args{cmd, file.string()};
    if (std::string(cmd) == "run") args.insert(args.end(), {"-o", out.string()});
    const Result r = run_cli(args);
    EXPECT_EQ(r.code, 2) << cmd << ": " << r.output;
    EXPECT_NE(r.output.find(std::string("'") + GetParam().key + "'"), std::string::npos)
        << cmd << " should name the key " << GetParam().key << ": " << r.output;
    EXPECT_NE(r.output.find(file.filename().string()), std::string::npos) << "should name the file";
    EXPECT_FALSE(fs::exists(out)) << "bad input must not leave a half-written output folder";
  }
}

INSTANTIATE_TEST_SUITE_P(MalformedCases, BadInput,
                         ::testing::Values(BadCase{"unknown_key.toml", "material[0].youngs_modulos"},
                                           BadCase{"negative_modulus.toml", "material[0].youngs_modulus"},
                                           BadCase{"missing_mesh.toml", "mesh"},
                                           BadCase{"wrong_type.toml", "time.end_time"},
                                           BadCase{"zero_density.toml", "material[0].density"},
                                           BadCase{"missing_stl.toml", "tool[0].file"}),
                         [](const ::testing::TestParamInfo<BadCase>& info) {
                           const std::string f = info.param.file;
                           return f.substr(0, f.find('.'));
                         });

// Command-line values a run cannot use: an empty output folder (it used to fall back to
// results/<name> silently), a progress interval that is not a finite positive number (NaN passed),
// a folder given as the case file.
TEST(Cli, RefusesAnEmptyOutputFolderAndANanInterval) {
  const auto c = (kSource / "cases/verification/cantilever.toml").string();
  auto r = run_cli({"run", c, "-o", ""});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("empty output folder"), std::string::npos) << r.output;
  r = run_cli({"run", c, "--progress-interval", "nan", "-o", fresh_dir("nan_interval").string()});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("progress-interval"), std::string::npos) << r.output;
  r = run_cli({"check", (kSource / "cases").string()});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("is a folder"), std::string::npos) << r.output;
}

// Several case files in one check: each as alone, its outcome on its own line, the exit code the
// worst of them (2 where one is bad input), and the valid ones still reported valid.
TEST(Cli, CheckOfSeveralFilesReportsEachAndExitsWithTheWorst) {
  const std::string good = (kSource / "cases/verification/cantilever.toml").string();
  const std::string pullout = (kSource / "cases/drape/tow_pullout.toml").string();
  const std::string bad = (kSource / "tests/cases/bad/negative_modulus.toml").string();
  Result r = run_cli({"check", good, pullout});
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("check " + good + ": valid (exit 0)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("check " + pullout + ": valid (exit 0)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("checked 2 case files: 2 valid, 0 bad input, 0 failed"),
            std::string::npos)
      << r.output;
  r = run_cli({"check", good, bad, pullout});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("'material[0].youngs_modulus'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("check " + bad + ": bad input (exit 2)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("check " + pullout + ": valid (exit 0)"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("checked 3 case files: 2 valid, 1 bad input, 0 failed"),
            std::string::npos)
      << r.output;
}

TEST(Cli, SetOverridesAreCheckedLikeTheFile) {
  const fs::path c = kSource / "cases/verification/cantilever.toml";
  Result r = run_cli({"check", c.string(), "--set", "time.end_tme=1"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("time.end_tme"), std::string::npos) << r.output;
  r = run_cli({"check", c.string(), "--set", "mesh.resolution=medium"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("'coarse'"), std::string::npos) << "should list the allowed values: " << r.output;
  r = run_cli({"check", c.string(), "--set", "mesh.resolution=coarse"});
  EXPECT_EQ(r.code, 0) << r.output;
  for (const char* bad : {"time.erosion_step_ratio=1.0", "time.erosion_step_ratio=1e-5"}) {
    r = run_cli({"check", c.string(), "--set", bad});
    EXPECT_EQ(r.code, 2) << bad << ": " << r.output;
    EXPECT_NE(r.output.find("time.erosion_step_ratio"), std::string::npos) << r.output;
  }
  r = run_cli({"check", c.string(), "--set", "time.erosion_step_ratio=0.3"});
  EXPECT_EQ(r.code, 0) << r.output;
  // A tow whose stretch has its own modulus bends with E11f only with one hexahedron through it.
  const fs::path be = kSource / "cases/drape/bias_extension_positive.toml";
  r = run_cli({"check", be.string(), "--set", "material[0].E11f_axial=5e9", "--set",
               "mesh.fabric[0].elements_through_thickness=2"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("elements_through_thickness"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("E11f_axial"), std::string::npos) << r.output;
  r = run_cli({"check", be.string(), "--set", "material[0].E11f_axial=5e9"});
  EXPECT_EQ(r.code, 0) << r.output;
  r = run_cli({"check", be.string(), "--set", "material[0].E11f_axial=-1"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("E11f_axial"), std::string::npos) << r.output;
  r = run_cli({"check", be.string(), "--set", "mesh.fabric[0].connection_transverse_force=-0.1"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("mesh.fabric[0].connection_transverse_force"), std::string::npos)
      << r.output;
}

// Regression: the default case through the CLI reproduces Euler-Bernoulli within 5 %.
TEST(CliRegression, CantileverCaseMatchesEulerBernoulli) {
  const fs::path out = fresh_dir("cantilever");
  const Result r = run_cli({"run", (kSource / "cases/verification/cantilever.toml").string(), "-o", out.string(),
                           "--set", "mesh.resolution=coarse"});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "completed");
  EXPECT_EQ(s["case"], "cantilever");
  EXPECT_EQ(s["elements"]["hex8"], 10);
  const double L = 0.2, h = 0.01, E = 200e9, P = 50, I = h * h * h * h / 12;
  const double analytic = P * L * L * L / (3 * E * I);
  const double tip = -s["tip_displacement_m"][1].get<double>();
  EXPECT_NEAR(tip, analytic, 0.05 * analytic);
  EXPECT_LT(s["energy_balance_error"].get<double>(), 0.01);
  EXPECT_LT(s["hourglass_to_internal_ratio"].get<double>(), 0.10);
  for (const char* f : {"history.csv", "log.txt", "results.h5", "results.xdmf", "report.html"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  const std::string header = slurp(out / "history.csv").substr(0, 200);
  EXPECT_EQ(header.rfind("time,cycle,time_step_s,kinetic_energy_J,internal_energy_J", 0), 0u) << header;
  // The log holds what the console showed.
  EXPECT_NE(slurp(out / "log.txt").find("energy balance at t ="), std::string::npos);
  // The report references existing figures by relative path.
  const std::string html = slurp(out / "report.html");
  std::smatch m;
  std::string rest = html;
  int images = 0;
  while (std::regex_search(rest, m, std::regex("<img src=\"([^\"]+)\""))) {
    EXPECT_TRUE(fs::path(m[1].str()).is_relative()) << m[1];
    EXPECT_TRUE(fs::exists(out / m[1].str())) << m[1];
    ++images;
    rest = m.suffix();
  }
  EXPECT_GE(images, 3) << "energy balance, tip displacement and the deformed shape";
  fs::remove_all(out);
}

// SIGINT stops a run after the current cycle; results.h5/.xdmf and summary.json stay readable.
TEST(CliRegression, InterruptedRunLeavesReadableResults) {
  const fs::path out = fresh_dir("sigint");
  const fs::path log = out.string() + ".log";
  const pid_t pid = spawn({"run", (kSource / "cases/verification/cantilever.toml").string(), "-o", out.string(),
                           "--set", "time.end_time=100.0", "--set", "time.frame_interval=1e-3",
                           "--set", "output.figures=false", "--set", "output.report=false"},
                          log);
  // Wait until a few frames are out.
  bool ready = false;
  for (int i = 0; i < 600 && !ready; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    if (fs::exists(out / "results.h5")) {
      try {
        ready = ncfsim::fem::io::ResultReader(out / "results.h5").n_frames() >= 3;
      } catch (const std::exception&) {
      }
    }
  }
  ASSERT_TRUE(ready) << slurp(log);
  kill(pid, SIGINT);
  const int code = wait_code(pid);
  EXPECT_EQ(code, 1) << "an interrupted run ends with exit code 1: " << slurp(log);
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "interrupted");
  EXPECT_LT(s["time_reached_s"].get<double>(), 100.0);
  ncfsim::fem::io::ResultReader reader(out / "results.h5");
  ASSERT_GE(reader.n_frames(), 3u);
  const auto last = reader.frame(reader.n_frames() - 1);
  EXPECT_EQ(last.coordinates.size(), reader.mesh().points.size());
  const std::string xdmf = slurp(out / "results.xdmf");
  std::size_t times = 0;
  for (std::size_t p = xdmf.find("<Time "); p != std::string::npos; p = xdmf.find("<Time ", p + 1)) ++times;
  EXPECT_EQ(times, reader.n_frames()) << "every frame named by the XDMF is in the HDF5 file";
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_NE(e.path().extension(), ".tmp") << "left a temporary file: " << e.path();
  fs::remove_all(out);
  fs::remove(log);
}

// `ncfsim calibrate stitch` round trip: synthetic bias-extension data (mm, irregular) made with a
// known 'Lambda' stitch law through the Eq. 2-6 model give that law back within 5 %.
// Erosion through the command line (tests/cases/erosion/crushed_cube.toml): a cube crushed in
// uniaxial strain at 0.5 m/s is eroded when half as high (t = 10 ms, within a step of 0.1 ms);
// the run completes, the log names the element and the cause, summary.json counts it and its
// elastic energy, history.csv gets the eroded count from then on, a shear probe leaves it out, and
// the frames get an 'eroded' field.
TEST(Cli, ErosionIsReportedEverywhere) {
  const fs::path out = fresh_dir("erosion");
  const Result r = run_cli({"run", (kSource / "tests/cases/erosion/crushed_cube.toml").string(),
                            "-o", out.string(), "--set", "output.figures=false"});
  ASSERT_EQ(r.code, 0) << r.output;
  EXPECT_NE(r.output.find("hexahedron 1 (part cube) eroded at t = 0.01"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("time.erosion_step_ratio = 0.5"), std::string::npos) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "completed");
  EXPECT_EQ(s["eroded_elements"].get<int>(), 1);
  EXPECT_GT(s["eroded_internal_energy_J"].get<double>(), 0.0);
  EXPECT_LT(s["energy_balance_error"].get<double>(), 0.002);
  const History h = read_history(out / "history.csv");
  const std::size_t t = h.column("time"), n = h.column("eroded_elements");
  ASSERT_LT(n, h.columns.size());
  ASSERT_LT(h.column("eroded_internal_energy_J"), h.columns.size());
  for (const auto& row : h.rows)
    EXPECT_EQ(row[n], row[t] < 0.0099 ? 0.0 : row[t] > 0.0102 ? 1.0 : row[n]) << row[t];
  // The shear probe over the crushed cube and its untouched neighbour (parallel axes: 90 deg)
  // measures until the crushed cube is gone, then has nothing to measure.
  const std::size_t p = h.column("pair_shear_angle_deg");
  ASSERT_LT(p, h.columns.size());
  for (const auto& row : h.rows) {
    if (row[t] < 0.0099) {
      EXPECT_NEAR(row[p], 90.0, 1e-6) << row[t];
    } else if (row[t] > 0.0102) {
      EXPECT_TRUE(std::isnan(row[p])) << row[t] << ": " << row[p];
    }
  }
  EXPECT_NE(slurp(out / "results.xdmf").find("Name=\"eroded\""), std::string::npos);
  fs::remove_all(out);
}

// A run stopped by a non-finite state writes its energies as null in summary.json: its report
// is still written, saying so.
TEST(Cli, ReportOfARunThatBlewUp) {
  const fs::path out = fresh_dir("blown_up");
  fs::create_directories(out);
  std::ofstream(out / "summary.json") << R"({"case": "blown", "status": "numerical_failure",
    "error": "bar 17 (part 3) has a non-finite force at (0.1, 0.2, 0) m",
    "energy_balance_error": null, "energy_balance_limit": 0.05, "kinetic_energy_J": null})";
  const Result r = run_cli({"report", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const std::string html = slurp(out / "report.html");
  EXPECT_NE(html.find("energy balance error <span class=\"bad\">not finite</span>"),
            std::string::npos)
      << html;
  EXPECT_NE(html.find("bar 17 (part 3) has a non-finite force"), std::string::npos);
  fs::remove_all(out);
}

TEST(Cli, CalibrateStitchRoundTrip) {
  const fs::path dir = fresh_dir("calibrate");
  fs::create_directories(dir);
  ncfsim::drape::BiasExtensionCoupon c;
  ncfsim::drape::StitchLaw truth;
  for (int k = 0; k <= 30; ++k) {
    const double e = 0.015 * k;
    truth.strain.push_back(e);
    truth.force.push_back(25 * e + 900 * e * e * e);
  }
  std::vector<double> D;
  for (int k = 1; k <= 45; ++k) D.push_back(1e-3 * (0.9 * k + 0.3 * std::sin(k)));
  const auto F = ncfsim::drape::coupon_force(c, ncfsim::drape::ShearSign::Negative, truth, D);
  {
    std::ofstream out(dir / "bias.csv");
    out << "extension_mm,force_N\n";
    for (std::size_t i = 0; i < D.size(); ++i) out << 1e3 * D[i] << "," << F[i] << "\n";
  }
  const Result r = run_cli({"calibrate", "stitch", (dir / "bias.csv").string(), "--extension-column", "extension_mm",
                            "--extension-scale", "1e-3", "--shear", "negative", "-o", (dir / "out").string()});
  ASSERT_EQ(r.code, 0) << r.output;
  std::ifstream law(dir / "out/stitch_law.csv");
  std::string line;
  std::getline(law, line);
  EXPECT_EQ(line, "strain,force_N");
  int checked = 0;
  while (std::getline(law, line)) {
    const double e = std::stod(line.substr(0, line.find(','))), f = std::stod(line.substr(line.find(',') + 1));
    if (e < 0.02) continue;
    const double expected = 25 * e + 900 * e * e * e;
    EXPECT_NEAR(f, expected, 0.05 * expected) << "strain " << e;
    ++checked;
  }
  EXPECT_GE(checked, 8);
  EXPECT_TRUE(fs::exists(dir / "out/stitch_law.toml"));
  // The same as a stage of kind calibration (what a characterisation workflow runs): the same law,
  // handed on as laws.toml (a [[bar_law]] that a case's case.laws takes).
  std::ofstream(dir / "stitch.toml")
      << "[case]\nname = \"stitch_Lambda\"\nkind = \"calibration\"\n[calibration]\nmethod = "
         "\"stitch\"\n"
         "data = \"bias.csv\"\nextension_column = \"extension_mm\"\nextension_scale = 1e-3\n"
         "shear = \"negative\"\nlaw_name = \"stitch_Lambda\"\n";
  const Result st =
      run_cli({"-q", "run", (dir / "stitch.toml").string(), "-o", (dir / "stage").string()});
  ASSERT_EQ(st.code, 0) << st.output;
  EXPECT_EQ(slurp(dir / "stage/stitch_law.csv"), slurp(dir / "out/stitch_law.csv"));
  const std::string laws = slurp(dir / "stage/laws.toml");
  EXPECT_NE(laws.find("[[bar_law]]\nname = \"stitch_Lambda\""), std::string::npos) << laws;
  const auto ss = nlohmann::json::parse(slurp(dir / "stage/summary.json"));
  EXPECT_EQ(ss["stage"], "calibration");
  EXPECT_EQ(ss["bar_law"], "stitch_Lambda");
  EXPECT_EQ(ss["laws_file"], "laws.toml");
  const Result bad = run_cli({"calibrate", "stitch", (dir / "bias.csv").string()});
  EXPECT_EQ(bad.code, 2) << "a missing column is bad input: " << bad.output;
  EXPECT_NE(bad.output.find("extension_m"), std::string::npos) << bad.output;
  fs::remove_all(dir);
}

// Virtual cantilever bending (ASTM D1388) of one tow: the bending length from the tip angle matches
// beam theory c = (E1 t^3 / 12 / w)^(1/3) of the tow's modulus within 5 %; the calibration command
// finds the E11f that gives a target bending length (within its 1 % tolerance) and the bending
// length of that modulus still matches beam theory within 5 %.
TEST(CliRegression, CantileverBendingMatchesBeamTheoryAndCalibrates) {
  const fs::path out = fresh_dir("bending");
  const fs::path case_file = kSource / "cases/drape/cantilever_bending.toml";
  Result r = run_cli({"-q", "run", case_file.string(), "-o", out.string(), "--set", "mesh.resolution=coarse",
                      "--set", "output.figures=false", "--set", "output.report=false"});
  ASSERT_EQ(r.code, 0) << r.output;
  auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  const double c = s["tow_bending_length_m"].get<double>(), beam = s["tow_beam_theory_bending_length_m"].get<double>();
  EXPECT_NEAR(c, beam, 0.05 * beam);
  EXPECT_NEAR(s["tow_tip_angle_deg"].get<double>(), 41.5, 5.0) << "the overhang is about twice the bending length";

  const double target = 0.028;
  r = run_cli({"calibrate", "tow-bending", case_file.string(), "--target-bending-length", std::to_string(target),
               "--set", "mesh.resolution=coarse", "-o", (out / "calibration").string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto cal = nlohmann::json::parse(slurp(out / "calibration/calibration.json"));
  EXPECT_TRUE(cal["converged"].get<bool>());
  EXPECT_NEAR(cal["bending_length_m"].get<double>(), target, 0.01 * target);
  const auto& last = cal["runs"].back();
  EXPECT_NEAR(last["bending_length_m"].get<double>(), last["beam_theory_bending_length_m"].get<double>(),
              0.05 * last["beam_theory_bending_length_m"].get<double>());
  fs::remove_all(out);
}

// Picture frame on the unstitched 6.64 mm unit cell with pinned tow ends: the tows rotate freely
// until neighbouring tows meet, at the gap-closing angle acos(w / p) = 14.1 deg (w = 3.22 mm,
// p = 3.32 mm); before it (after the start-up ramp) the shear force stays below 1 % of its value
// at 28 deg, after it rises.
TEST(CliRegression, PictureFrameForceRisesAtTheGapClosingAngle) {
  const fs::path out = fresh_dir("picture_frame");
  const Result r = run_cli({"-q", "run", (kSource / "cases/drape/picture_frame_unstitched.toml").string(), "-o",
                            out.string(), "--set", "boundary.picture_frame[0].final_shear_angle_deg=30",
                            "--set", "time.end_time=0.03", "--set", "output.figures=false", "--set",
                            "output.report=false"});
  ASSERT_EQ(r.code, 0) << r.output;
  const History h = read_history(out / "history.csv");
  const auto ca = h.column("frame_shear_angle_deg"), cf = h.column("frame_normalised_shear_force_N_per_m");
  ASSERT_LT(cf, h.columns.size());
  double before = 0, at28 = 0;
  for (const auto& v : h.rows) {
    const double g = v[ca], f = v[cf];
    if (g > 4.0 && g < 12.5) before = std::max(before, std::abs(f));  // after the start-up ramp
    if (g > 27.5 && g < 28.5) at28 = f;
  }
  const Reference ref = case_reference("drape", "picture_frame_unstitched");
  const double gap_closing = std::acos(3.22 / 3.32) * 180 / M_PI;
  EXPECT_TRUE(within(gap_closing, ref.at("gap_closing_angle_deg", "lower"), ref.at("gap_closing_angle_deg", "upper")))
      << gap_closing;
  EXPECT_GT(at28, 0.0);
  const double ratio = before / at28;
  EXPECT_TRUE(within(ratio, std::nan(""), ref.at("force_before_gap_closing_over_force_at_28deg", "upper")))
      << "the tows must rotate freely before their gaps close: " << ratio;
  fs::remove_all(out);
}

// The virtual bias extension coupons against Eq. 2 run in the CI characterisation of their fabric
// (tests/workflow/test_characterisation.cpp), with the other virtual tests.
