// Hemisphere forming of the +-45 NCF blanket (issue #18, the paper's Fig. 17-18), end to end on the
// CI mesh: a 270 mm blank, one element across a tow, two tow pitches long (6.6k hexahedra, 12.8k
// stitch bars, 51.9k stitch-to-tow joints), mass-scaled to 8e-7 s (36 % added to the tows; the
// case's own 4e-7 s adds none). The acceptance of the issue: the punch reaches full depth (its
// equator at the blankholder plane), the energy balance stays under 2 %, kinetic / internal under
// 10 % over the forming, no tow passes through another or through a tool, the blankholder presses
// with 3.35 kPa over the blank it covers, the ring measure is written with its four quadrant
// maxima, and the punch force rises without ringing; the formed part transfers to the impregnated
// model with no element lost (issue #20). Bad input names the key.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <nlohmann/json.hpp>

#include "fem/io/stage_handoff.hpp"
#include "tests/workflow/cli_test_support.hpp"
#include "transfer/impregnation.hpp"

namespace ncfsim::test {
namespace {

const fs::path kCase = kSource / "cases/hemisphere/drape.toml";

// The CI-mesh chain through the workflow of the demo (cases/hemisphere/ci/workflow.toml): the
// tow's E11f calibrated to the fabric's bending length and handed to the meso drape (case.laws),
// the meso drape, the fishnet drape, the macro shell drape, the transfer of the dome and its crush,
// each in its sub-folder; a rerun with nothing changed skips every stage. On one rank: the suite
// runs two tests at a time on the 2-core machines, and MPI ranks spin while they wait, so on 2
// ranks beside another test it took as long (1282 s against 1278) and slowed the test beside it
// 2.5 times (the bias coupons: 537 s against 212).
TEST(CliRegressionHemisphereDrape, CiMeshFormsToFullDepthQuasiStatically) {
  const fs::path wf = fresh_dir("hemisphere_ci");
  const std::vector<std::string> wf_args = {
      "-q",
      "run",
      (kSource / "cases/hemisphere/ci/workflow.toml").string(),
      "-o",
      wf.string(),
      "--set",
      "output.figures=false",
      "--set",
      "output.report=false",
      "--set",
      "crush.time.end_time=0.0022"};  // 3 mm of crush: the demo's 10 mm would take minutes more
  const auto r = run_cli(wf_args);
  ASSERT_EQ(r.code, 0) << r.output;
  const auto ws = nlohmann::json::parse(slurp(wf / "summary.json"));
  EXPECT_EQ(ws["status"], "completed");
  ASSERT_EQ(ws["stages"].size(), 6u);  // tow_bending, drape, fishnet, macro, transfer, crush
  for (const auto& st : ws["stages"]) EXPECT_EQ(st["status"], "completed") << st["name"];
  {  // The macro shell drape beside it (issue #19): the symmetric law's four quadrants agree.
    const auto ms = nlohmann::json::parse(slurp(wf / "macro" / "summary.json"));
    const double q1 = ms["macro_max_shear_deg_q1"];
    for (int q = 2; q <= 4; ++q)
      EXPECT_NEAR(ms["macro_max_shear_deg_q" + std::to_string(q)].get<double>(), q1, 1.0) << q;
  }
  const fs::path out = wf / "drape";
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "completed");
  {  // The drape's tow law is the calibrated one (the stage hand-off).
    const auto tb = nlohmann::json::parse(slurp(wf / "tow_bending" / "summary.json"));
    EXPECT_TRUE(tb["converged"].get<bool>());
    const std::string laws = (wf / "tow_bending" / "laws.toml").string();
    bool handed = false;
    for (const auto& o : s["overrides"])
      handed = handed || o.get<std::string>().find(laws) != std::string::npos;
    EXPECT_TRUE(handed) << s["overrides"].dump();
    ASSERT_EQ(s["laws_replaced"].size(), 1u);
    EXPECT_NE(s["laws_replaced"][0].get<std::string>().find("'dry_tow' from " + laws), std::string::npos)
        << s["laws_replaced"].dump();
  }
  // Full depth: the punch centre starts 81 mm below the blankholder plane.
  EXPECT_GE(s["punch_displacement_m"].get<double>(), 0.081);
  EXPECT_LT(s["energy_balance_error_max"].get<double>(), 0.02);
  EXPECT_LT(s["kinetic_to_internal_max"].get<double>(), 0.10);
  // 3.35 kPa over the 270 mm square less the blankholder's 100 mm hole.
  const double area = 0.27 * 0.27 - M_PI * 0.100 * 0.100;
  EXPECT_NEAR(s["blankholder_pressed_area_m2"].get<double>(), area, 1e-3 * area);
  EXPECT_NEAR(s["blankholder_applied_force_N"].get<double>(), 3350.0 * area, 1e-3 * 3350.0 * area);
  // No tow through a tool or through another: the deepest penetration over the run stays a small
  // share of a tow's thickness (0.23 mm).
  const double tow = s["fabrics"]["ncf"]["tow_thickness_m"];
  for (const char* tool : {"punch", "blankholder", "blankholder_edge", "die", "die_fillet"})
    EXPECT_LT(s[std::string(tool) + "_max_penetration_m"].get<double>(), 0.25 * tow) << tool;
  // No tow element eroded (folded over or locked in compaction): every edge of the blank stays
  // under the blankholder to full depth (docs/fabric-data.md, "Hemisphere forming: the CI blank";
  // the 240 mm blank of before had its wale-axis edges drawn off it and into the die fillet in the
  // last 5 % of the stroke, and 18 tow elements folded or locked there and were eroded).
  const std::size_t hexes = s["elements"]["hex8"];
  EXPECT_EQ(s["eroded_elements"].get<std::size_t>(), 0u);
  // The ring measure: four quadrant maxima, every azimuth on the formed fabric.
  for (int q = 1; q <= 4; ++q) {
    const auto& v = s["max_shear_deg_q" + std::to_string(q)];
    ASSERT_TRUE(v.is_number()) << q;
    EXPECT_GT(v.get<double>(), 5.0) << q;
    EXPECT_LT(v.get<double>(), 60.0) << q;
  }
  // The pin-jointed net on the same ring (fishnet.toml): four equal quadrants, 26.3 deg.
  for (int q = 1; q <= 4; ++q)
    EXPECT_NEAR(s["kinematic_max_shear_deg_q" + std::to_string(q)].get<double>(), 26.28, 0.2) << q;
  const auto ring = read_history(out / "ring_shear.csv");
  ASSERT_EQ(ring.rows.size(), 360u);
  ASSERT_LT(ring.column("kinematic_shear_deg"), ring.columns.size());
  std::size_t hits = 0;
  for (const auto& row : ring.rows) hits += row[ring.column("hit")] > 0.5;
  EXPECT_GE(hits, 350u);
  // No ringing: over the forming (punch past 20 mm) the force departs from its 2 ms running mean
  // by under 10 % of the force at full depth.
  const auto h = read_history(out / "history.csv");
  const auto t = h.column("time"), f = h.column("punch_force_N"),
             d = h.column("punch_displacement_m");
  const double f_end = h.rows.back()[f];
  EXPECT_GT(f_end, 20.0);
  double worst = 0;
  for (std::size_t k = 0; k < h.rows.size(); ++k) {
    if (h.rows[k][d] < 0.02) continue;
    double sum = 0;
    int n = 0;
    for (const auto& row : h.rows)
      if (std::abs(row[t] - h.rows[k][t]) <= 1e-3) sum += row[f], ++n;
    worst = std::max(worst, std::abs(h.rows[k][f] - sum / n));
  }
  EXPECT_LT(worst, 0.10 * f_end) << "punch force rings";

  // The transfer of the formed part (issue #20): every tow element mapped (none eroded, none
  // folded), each with an orthonormal, right-handed material frame and a positive Jacobian at
  // every corner, Vf between the undeformed and the locking value, the plies and tows tied. The
  // whole part is mapped with impregnation.min_corner_jacobian = 0 (every unfolded element): one
  // tow on the die fillet (r = 86 mm, outside the crush's dome) ends at 0.07, under the default
  // 0.1 that keeps strongly distorted tows out of a crush model (docs/fabric-data.md, "Hemisphere
  // forming: the CI blank"); the dome the workflow transfers for the crush loses none at 0.1.
  {
    const auto ds = nlohmann::json::parse(slurp(wf / "transfer" / "summary.json"));
    EXPECT_EQ(ds["elements_lost"].get<std::size_t>(), 0u);
    EXPECT_GT(ds["elements_mapped"].get<std::size_t>(), hexes / 4);
  }
  const fs::path tr = wf / "transfer_full";
  const auto tr_run =
      run_cli({"-q", "run", (kSource / "cases/hemisphere/transfer.toml").string(), "-o",
               tr.string(), "--set", "source.results=" + (out / "results.h5").string(), "--set",
               "impregnation.min_corner_jacobian=0.0"});
  ASSERT_EQ(tr_run.code, 0) << tr_run.output;
  const auto ts = nlohmann::json::parse(slurp(tr / "summary.json"));
  EXPECT_EQ(ts["elements_lost"].get<std::size_t>(), 0u);
  EXPECT_EQ(ts["elements_mapped"].get<std::size_t>(), hexes);
  {
    const auto model = fem::io::read_last_frame(tr / "results.h5");
    ASSERT_EQ(model.mesh.n_hex(), hexes);
    const auto* a1 = model.field("fibre_direction");
    const auto* a2 = model.field("material_axis_2");
    const auto* a3 = model.field("material_axis_3");
    ASSERT_TRUE(a1 && a2 && a3);
    auto axis = [](const fem::io::FrameField* f, std::size_t e) {
      return fem::V3{f->values[3 * e], f->values[3 * e + 1], f->values[3 * e + 2]};
    };
    double worst_corner = 1.0;
    for (std::size_t e = 0; e < hexes; ++e) {
      const fem::V3 u = axis(a1, e), v = axis(a2, e), w = axis(a3, e);
      ASSERT_NEAR(fem::dot(u, u), 1.0, 1e-9) << e;
      ASSERT_NEAR(fem::dot(v, v), 1.0, 1e-9) << e;
      ASSERT_NEAR(fem::dot(w, w), 1.0, 1e-9) << e;
      ASSERT_NEAR(fem::dot(u, v), 0.0, 1e-9) << e;
      ASSERT_NEAR(fem::dot(u, w), 0.0, 1e-9) << e;
      ASSERT_NEAR(fem::dot(v, w), 0.0, 1e-9) << e;
      ASSERT_NEAR(fem::dot(fem::cross(u, v), w), 1.0, 1e-9) << e;
      std::array<fem::V3, 8> x;
      for (std::size_t a = 0; a < 8; ++a) {
        const auto n = static_cast<std::size_t>(model.mesh.hex().conn[8 * e + a]);
        x[a] = fem::V3{model.coordinates[3 * n], model.coordinates[3 * n + 1],
                       model.coordinates[3 * n + 2]};
      }
      worst_corner = std::min(worst_corner, transfer::min_scaled_corner_jacobian(x));
    }
    EXPECT_GT(worst_corner, 0.0) << "a folded impregnated element";
  }
  EXPECT_GE(ts["vf_min"].get<double>(), 0.6 - 1e-12);
  EXPECT_LE(ts["vf_max"].get<double>(), 0.857 + 1e-12);
  EXPECT_GT(ts["vf_max"].get<double>(), 0.65) << "the flange's compaction shows";
  EXPECT_GT(ts["tie_pairs_interply"].get<std::size_t>(),
            s["elements"]["hex8"].get<std::size_t>() / 4);
  EXPECT_GT(ts["tie_pairs_intraply"].get<std::size_t>(), 0u);

  // The crush (issue #21) of the dome trimmed at r = 76 mm (the workflow's transfer stage):
  // 3 mm of stroke at 1.5 m/s (cases/hemisphere/ci/crush.toml). The CI mesh's 6.6 mm tow elements
  // are too long for the literature's fracture energies (the crack band's snap-back limit): the
  // case lets the law raise them element by element (crack_band = "raise", reported).
  const fs::path dome = wf / "transfer", crush = wf / "crush";
  const std::vector<std::string> crush_args = {
      "run",   (kSource / "cases/hemisphere/ci/crush.toml").string(),
      "--set", "model.source=" + (dome / "results.h5").string(),
      "--set", "time.end_time=0.0022",
      "--set", "output.figures=false",
      "--set", "output.report=false"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> a = crush_args;
    a.insert(a.end(), extra.begin(), extra.end());
    return a;
  };
  const auto cs = nlohmann::json::parse(slurp(crush / "summary.json"));
  // A 1.5 m/s crush is dynamic: its kinetic share is stated, not checked (issue #42).
  EXPECT_FALSE(cs["kinetic_to_internal_exceeded"].get<bool>());
  EXPECT_EQ(cs["kinetic_to_internal_limit"].get<double>(), 0.0);
  EXPECT_NE(slurp(crush / "log.txt").find("(a dynamic run: not checked"), std::string::npos);
  EXPECT_EQ(cs["stage"], "crush");
  ASSERT_TRUE(cs["peak_force_N"].is_number());
  EXPECT_GT(cs["peak_force_N"].get<double>(), 50.0);
  EXPECT_LT(cs["peak_force_N"].get<double>(), 5000.0);
  EXPECT_GT(cs["energy_absorbed_J"].get<double>(), 0.0);
  EXPECT_GT(cs["stroke_at_peak_m"].get<double>(), 0.0);
  // The limit is 5 %, including erosion; it closes at 0.001 % (docs/fabric-data.md,
  // "Crush": 5.6 % before the hexahedron booked the work of its uniform-gradient forces).
  EXPECT_LT(cs["energy_balance_error"].get<double>(), 0.05);
  EXPECT_LT(cs["energy_balance_error_max"].get<double>(), 0.05);
  EXPECT_LT(cs["punch_max_penetration_m"].get<double>(), 0.1 * 0.23e-3) << "the punch sinks in";
  double failed = 0;
  for (const char* m : {"fibre_tension", "fibre_compression", "matrix_tension",
                        "matrix_compression", "in_plane_shear", "transverse_shear"})
    failed += cs[std::string("failed_fraction_") + m].get<double>();
  EXPECT_GT(failed, 0.0) << "no tow failed in 3 mm of crush";
  const History ch = read_history(crush / "history.csv");
  const std::size_t filtered = ch.column("punch_force_cfc600_N");
  ASSERT_LT(filtered, ch.columns.size());
  const std::size_t raw = ch.column("punch_force_N");
  for (const auto& row : ch.rows) {
    ASSERT_TRUE(std::isfinite(row[raw]));
    ASSERT_TRUE(std::isfinite(row[filtered]));
  }

  // Ten times the punch speed over the same stroke, where the case asks for a limit on the
  // kinetic share (0.3): it is warned about (0.45 against 0.14 at 1.5 m/s), not passed silently.
  const fs::path fast = wf / "crush_fast";
  const auto fast_run = run_cli(
      with({"-o", fast.string(), "--set", "tool[0].velocity=[0.0,0.0,-15.0]", "--set",
            "tool[0].ramp_time=2e-5", "--set", "time.end_time=2.2e-4", "--set",
            "time.quasi_static_from=1.2e-4", "--set", "time.history_interval=2.5e-6", "--set",
            "time.frame_interval=2.2e-5", "--set", "time.kinetic_to_internal_limit=0.3"}));
  ASSERT_EQ(fast_run.code, 0) << fast_run.output;
  const auto fs_ = nlohmann::json::parse(slurp(fast / "summary.json"));
  EXPECT_TRUE(fs_["kinetic_to_internal_exceeded"].get<bool>());
  EXPECT_NE(fast_run.output.find("kinetic / internal energy"), std::string::npos)
      << fast_run.output;

  // The workflow again, nothing changed: every stage skipped, in seconds.
  fs::remove_all(tr);
  fs::remove_all(fast);
  const auto t0 = std::chrono::steady_clock::now();
  const auto again = run_cli(wf_args);
  ASSERT_EQ(again.code, 0) << again.output;
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 30.0);
  for (const auto& st : nlohmann::json::parse(slurp(wf / "summary.json"))["stages"])
    EXPECT_EQ(st["status"], "skipped") << st["name"];
  fs::remove_all(wf);
}

TEST(CliHemisphereDrape, BadInputNamesTheKey) {
  struct Bad {
    std::vector<std::string> sets;
    std::string key;
  };
  const std::vector<Bad> bad = {
      {{"tool[0].point=[0.0,0.0,-0.077]"}, "tool[0].point"},  // punch starts inside the blank
      {{"tool[1].pressure=0.0"}, "tool[1].pressure"},
      {{"tool[1].pressure=-100.0"}, "tool[1].pressure"},
      {{"mesh.fabric[0].size=[0.17,0.17]", "mesh.fabric[0].origin=[-0.085,-0.085,0.0]"},
       "tool[1].radius"},  // the blank is smaller than the die opening
      {{"output.ring_shear[0].height=0.03"}, "output.ring_shear[0].kinematic_case"},  // other ring
  };
  for (const auto& b : bad) {
    std::vector<std::string> args = {"check", kCase.string(), "--set", "mesh.resolution=coarse"};
    for (const auto& s : b.sets) args.insert(args.end(), {"--set", s});
    const auto r = run_cli(args);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(b.key), std::string::npos) << r.output;
  }
  EXPECT_EQ(run_cli({"check", kCase.string(), "--set", "mesh.resolution=coarse"}).code, 0);
}

}  // namespace
}  // namespace ncfsim::test
