// Every engine case of the repository on 2 MPI ranks against 1 (issue #24, docs/parallel.md):
// each runnable case file under cases/ whose [case] kind is "engine" is either
//  - compared: run at its CI size (the resolution or overrides its regression test uses) for a
//    bounded time on 1 rank and with --np 2 (the launcher CMake found); every history.csv column
//    is compared row by row within a stated tolerance of the column's scale; or
//  - an expected refusal: it cannot be split today and `--np 2` exits 2 with the reason; or
//  - covered by another entry (the same case at its CI size).
// EveryEngineCaseIsListed fails for an engine case in none of the lists, so none is skipped
// silently. Not engine kind, so not here: transfer, kinematic_drape and workflow cases (they
// run on one rank), crush cases (they split over ranks too, but start from a transfer result:
// tests/workflow/test_mpi_runs.cpp's erosion case crushes a cube instead).
//
// Tolerances. The scale of a column is its largest magnitude over both runs; a component of a
// vector (columns <name>_x_<unit>, _y_, _z_) takes its vector's (the largest of the three: a
// small component of a contact resultant is what is left of large contributions), and
// energy_balance_error, already a fraction of the energy scale, is compared absolutely; and no
// column with a unit (_N, _J, _m, _deg, _N_per_m) has a scale below a millionth of the largest
// of its unit (a resultant that stays zero in an in-plane test is round-off of the others).
//  - kRoundOff = 1e-7: on 2 ranks a rank sums its own elements' and contacts' forces at a
//    partition-boundary node and the exchange adds the other rank's share; energies, works,
//    tool forces and friction are sums over the ranks: the same numbers summed in another
//    order, so they differ in the last bits. Where nothing amplifies that (elastic runs, and
//    contact runs whose contacts stick or slide steadily) the largest difference measured is
//    1.3e-8 (history.csv prints 9 significant digits: one unit of the last one is 1e-9 to 1e-8
//    of a value); 1e-7 leaves a margin of 8.
//  - kStickSlip = 1e-4: where frictional contacts start to slip the slipped distance is the
//    small excess of the trial force over mu N, so a last-bit difference in the forces becomes
//    a relative difference of 1e-6 to 1e-5 in the contact resultants and friction energy (as
//    between two builds). Measured on the CI bias coupons over 2 ms: 2e-5 of the ply-ply
//    contact resultant; the one-rank run with its safety factor moved by one ulp (0.9 ->
//    0.9000000000000001) differs from itself by the same 2e-5, so this is round-off amplified,
//    not the partition.
//  - The stitched picture frames are chaotic past 14 deg of shear: see kFrameLate.
// The largest difference of each case, with its column, is printed by the test.
#include <gtest/gtest.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <string>
#include <vector>

#include "fem/case/toml_reader.hpp"
#include "tests/workflow/cli_test_support.hpp"
#include "tests/workflow/mpi_test_support.hpp"

namespace ncfsim::test {
namespace {

constexpr double kRoundOff = 1e-7;
constexpr double kStickSlip = 1e-4;

// A case compared on 2 ranks against 1.
struct Compared {
  std::string file;               // under cases/
  std::vector<std::string> sets;  // its CI size and a bounded run (--set)
  double tolerance;               // of a column's scale (above)
  // Chaotic cases: every column is compared up to `until` (s); after it only `late_columns`,
  // within `late_tolerance` (see kFrameLate).
  double until = 1e300;
  std::vector<std::string> late_columns = {};
  double late_tolerance = 0;
};
void PrintTo(const Compared& c, std::ostream* os) { *os << c.file; }

// A case that cannot be split today: `--np 2` exits 2 and the message holds `reason`.
struct Refused {
  std::string file;
  std::string reason;
};
void PrintTo(const Refused& c, std::ostream* os) { *os << c.file; }

// A case compared through another entry (the same case at its CI size).
struct Covered {
  std::string file;
  std::string by;
};

// The CI bias coupon (its regression test's mesh: docs/fabric-data.md), 2 ms of the pull.
const std::vector<std::string> kBiasCi = {"mesh.fabric[0].elements_across_tow=1",
                                          "mesh.fabric[0].element_length=6.64e-3",
                                          "time.end_time=0.002", "time.history_interval=2e-5"};
// The hemisphere drape at the CI mesh of cases/hemisphere/ci/drape.toml, 1.2 ms (1 500 cycles:
// the blankholder presses the blank on the die; the punch has not reached it).
const std::vector<std::string> kHemisphereCi = {"mesh.fabric[0].elements_across_tow=1",
                                                "mesh.fabric[0].element_length=6.64e-3",
                                                "mesh.fabric[0].size=[0.27,0.27]",
                                                "mesh.fabric[0].origin=[-0.135,-0.135,0.0]",
                                                "time.mass_scaling_dt=8e-7",
                                                "time.erosion_step_ratio=0.25",
                                                "time.end_time=0.0012",
                                                "time.history_interval=1.2e-5",
                                                "time.quasi_static_from=0"};
// With the fabric file's tow law (issue #43: 0.5 MPa compaction on the fibre-sheet spacing) the
// blankholder squeezes the CI blank further as it closes and the stitch-to-tow joints slide: the
// 2-rank run's last-bit differences first show in the joints' in-plane resultant and grow about
// tenfold per 0.1 ms from 0.3 ms (2.5e-9 at 0.1 ms, 7.8e-8 at 0.3, 1.7e-7 at 0.6 ms, then up to
// 7e-3 of the nearly-zero in-plane resultants' own scale at 1.2 ms), as in the pull-out (1e-6)
// and the coupons (1e-4). The stitch-free control on the same law stays within 1e-7 over the
// same 1.2 ms, so it is the joints' stick-slip, not the partition. So every column is compared
// up to 0.3 ms, and over the whole 1.2 ms the energies and the normal forces within 1e-3
// (measured: 1.2e-4 at most, the joints' normal resultant; energies 1.1e-5 to 3.4e-5).
constexpr double kHemisphereUntil = 3e-4;
constexpr double kHemisphereLate = 1e-3;
const std::vector<std::string> kHemisphereLateColumns = {
    "internal_energy_J",        "kinetic_energy_J",      "external_work_J",
    "contact_energy_J",         "blankholder_force_z_N", "ply1__ply2_force_z_N",
    "ncf_stitch_tow_force_z_N", "punch_displacement_m"};
// The friction sleds at their regression test's coarse mesh, 10 ms (pressed, then pulled).
const std::vector<std::string> kSled = {"mesh.resolution=coarse", "time.end_time=0.01",
                                        "time.history_interval=1e-4"};
// The picture frames sheared to their 52 deg in 6 ms instead of 57.4 ms (the frame reaches its
// final angle at the end time; the ramp stays 5 ms).
const std::vector<std::string> kFrame6ms = {"time.end_time=0.006", "time.history_interval=6e-5"};
// The stitched frames are chaotic once the tows meet (about 14 deg, 3.3 ms here): stick-slip at
// the tow-tow contacts and the stitch-to-tow joints lets a last-bit difference grow a
// hundredfold every 0.3 ms, to 1e-3 of the frame force and a few tenths of the joints' resultant
// at 52 deg. The one-rank run with its safety factor moved by one ulp wanders off as far (8e-4
// of the frame force, the joints' resultant by its whole size): chaos, not the partition. So
// every column is compared up to 2.8 ms (10 deg; measured 1.7e-5 positive, 7.6e-7 negative),
// and over the whole run the frame's normalised shear force (the case's result) and the
// energies within 1e-2 (measured 2.3e-3, 2.2e-3).
constexpr double kFrameUntil = 2.8e-3;
constexpr double kFrameLate = 1e-2;
const std::vector<std::string> kFrameLateColumns = {"frame_normalised_shear_force_N_per_m",
                                                    "internal_energy_J", "external_work_J"};

// The macro (shell) coupons: 8 ms of the pull (the 5 mm ramp and 3 mm at 1 m/s). Their small
// reactions (the clamps' transverse ones, a few thousandths of the pull) are chaotic past ~2 ms:
// the one-rank run with its safety factor moved by one ulp differs from itself as much as the
// 2-rank run does (negative coupon at 8 ms: clamp reaction 4.2e-2 against 5.5e-2 on 2 ranks, the
// pull force 7.1e-3 against 7.5e-3; positive: 2.0e-3 against 3.0e-4). So every column is
// compared up to 1.6 ms (measured 8e-13 negative, 5e-11 positive), and over the whole run
// the pull force and the energies within 2e-2.
const std::vector<std::string> kMacroBias = {"time.end_time=0.008", "time.history_interval=8e-5"};
constexpr double kMacroBiasUntil = 1.6e-3;
constexpr double kMacroBiasLate = 2e-2;
const std::vector<std::string> kMacroBiasLateColumns = {"pull_reaction_x_N", "pull_reaction_y_N",
                                                        "internal_energy_J", "external_work_J",
                                                        "kinetic_energy_J"};
// The macro picture frame's 8 x 8 shells are one kernel chunk: 16 x 16, sheared for 6 ms.
const std::vector<std::string> kMacroFrame = {"mesh.plate[0].divisions=[16,16]",
                                              "time.end_time=0.006", "time.history_interval=6e-5"};
// The macro hemisphere drapes, 1.2 ms (the blankholder closing, as kHemisphereCi).
const std::vector<std::string> kMacroHemisphere = {
    "time.end_time=0.0012", "time.history_interval=1.2e-5", "time.quasi_static_from=0"};

const std::vector<Compared>& compared() {
  static const std::vector<Compared> c = {
      {"drape/bias_extension_negative.toml", kBiasCi, kStickSlip},
      {"drape/bias_extension_positive.toml", kBiasCi, kStickSlip},
      {"drape/cantilever_bending.toml",
       {"time.end_time=0.004", "time.history_interval=4e-5"},
       kRoundOff},
      {"drape/friction_sled_aluminium.toml", kSled, kRoundOff},
      {"drape/friction_sled_tow_tow_0_0.toml", kSled, kRoundOff},
      {"drape/friction_sled_tow_tow_0_90.toml", kSled, kRoundOff},
      // The stitch-to-tow joints slide from the start of the pull (1e-6: stick-slip at the joints
      // on a small case; measured 2e-7).
      {"drape/tow_pullout.toml", {"time.end_time=0.004", "time.history_interval=4e-5"}, 1e-6},
      {"hemisphere/ci/drape.toml",
       {"time.end_time=0.0012", "time.history_interval=1.2e-5", "time.quasi_static_from=0"},
       kRoundOff,
       kHemisphereUntil,
       kHemisphereLateColumns,
       kHemisphereLate},
      {"hemisphere/drape_no_stitch.toml", kHemisphereCi, kRoundOff},
      // The frame's arms as walls push the edge tows of both ranks (measured: equal bit for bit).
      {"drape/picture_frame_unstitched.toml", kFrame6ms, kRoundOff},
      {"drape/picture_frame_positive.toml", kFrame6ms, kStickSlip, kFrameUntil, kFrameLateColumns,
       kFrameLate},
      {"drape/picture_frame_negative.toml", kFrame6ms, kStickSlip, kFrameUntil, kFrameLateColumns,
       kFrameLate},
      // The default 20 hexahedra are one kernel chunk (one rank at most): the fine mesh's 40.
      {"verification/cantilever.toml",
       {"mesh.resolution=fine", "time.end_time=0.004", "time.history_interval=4e-5"},
       kRoundOff},
      // Shells: their rotations are advanced on every rank that holds one of their elements,
      // from the nodal moments summed over the ranks. The default 40 shells are one kernel
      // chunk of 64: the fine mesh's 160.
      // Its clamp's axial reaction is a small difference of the bending forces at the root
      // nodes: 1.5e-6 of the reaction's scale on 2 ranks, 1.3e-6 on one rank with the safety
      // factor moved by one ulp (the rest within 2.4e-9).
      {"verification/shell_cantilever.toml",
       {"mesh.resolution=fine", "time.end_time=0.01", "time.history_interval=1e-4"},
       1e-5},
      // The stitched macro model: its sliders are computed where their stitch node is owned.
      // Positive: the stretched pillars' sliders sit at their sliding force in places, so a slip
      // decision can turn on round-off: the plane's in-plane reactions (1e-3 of the scale) differ
      // by 4.7e-6 of the scale at 6 ms, the rest within 1e-9.
      {"drape/macro/stitched/picture_frame_positive.toml", kMacroFrame, 1e-5},
      {"drape/macro/stitched/picture_frame_negative.toml", kMacroFrame, kRoundOff},
      {"drape/macro/stitched/bias_extension_positive.toml", kMacroBias, kRoundOff, kMacroBiasUntil,
       kMacroBiasLateColumns, kMacroBiasLate},
      {"drape/macro/stitched/bias_extension_negative.toml", kMacroBias, kRoundOff, kMacroBiasUntil,
       kMacroBiasLateColumns, kMacroBiasLate},
      {"drape/macro/bias_extension_negative.toml", kMacroBias, kRoundOff, kMacroBiasUntil,
       kMacroBiasLateColumns, kMacroBiasLate},
      {"drape/macro/bias_extension_positive.toml", kMacroBias, kRoundOff, kMacroBiasUntil,
       kMacroBiasLateColumns, kMacroBiasLate},
      {"drape/macro/picture_frame.toml", kMacroFrame, kRoundOff},
      {"drape/macro/picture_frame_negative.toml", kMacroFrame, kRoundOff},
      {"hemisphere/drape_macro.toml", kMacroHemisphere, kRoundOff},
      {"hemisphere/drape_macro_signed.toml", kMacroHemisphere, kRoundOff},
      // Stitched (its stitch's mass scaled to the shells' step: 1.1e-13; without the scaling the
      // blankholder's closing bounced chaotically: 9.6e-5 on 2 ranks, 7.6e-4 on one rank with the
      // safety factor moved by one ulp).
      {"hemisphere/drape_macro_stitched.toml", kMacroHemisphere, kRoundOff},
      {"hemisphere/ci/drape_macro.toml", kMacroHemisphere, kRoundOff},
  };
  return c;
}

const std::string kOneElement = "2 MPI ranks for 1 elements";

const std::vector<Refused>& refused() {
  static const std::vector<Refused> r = {
      // Single-element verification: one element does not split.
      {"verification/damage/fibre_compression.toml", kOneElement},
      {"verification/damage/fibre_tension.toml", kOneElement},
      {"verification/damage/in_plane_shear.toml", kOneElement},
      {"verification/damage/matrix_compression.toml", kOneElement},
      {"verification/damage/matrix_tension.toml", kOneElement},
      {"verification/damage/transverse_shear.toml", kOneElement},
  };
  return r;
}

const std::vector<Covered>& covered() {
  // The paper-density drape takes hours; its CI size is cases/hemisphere/ci/drape.toml.
  // The meso coupons held flat are their cases (the same included coupon) with two z holds.
  // The second fabric's CI hemisphere and virtual tests are the +-45 cases with another fabric
  // (the same kernels, contacts, tools and probes).
  static const std::vector<Covered> c = {
      {"hemisphere/drape.toml", "hemisphere/ci/drape.toml"},
      // The same with a speed profile for the punch (tests/fem/test_tool_velocity_curve.cpp).
      {"hemisphere/drape_slow_start.toml", "hemisphere/ci/drape.toml"},
      {"fabrics/biax_0_90_chain/hemisphere_ci.toml", "hemisphere/ci/drape.toml"},
      {"fabrics/biax_0_90_chain/bias_extension.toml", "drape/bias_extension_positive.toml"},
      {"fabrics/biax_0_90_chain/picture_frame.toml", "drape/picture_frame_positive.toml"},
      {"fabrics/biax_0_90_chain/cantilever_bending.toml", "drape/cantilever_bending.toml"},
      {"fabrics/biax_0_90_chain/sled_aluminium.toml", "drape/friction_sled_aluminium.toml"},
      {"fabrics/biax_0_90_chain/sled_tow_tow.toml", "drape/friction_sled_tow_tow_0_0.toml"},
      {"fabrics/biax_0_90_chain/sled_tow_tow_crossing.toml",
       "drape/friction_sled_tow_tow_0_90.toml"},
      {"drape/macro/stitched/meso_bias_extension_positive_flat.toml",
       "drape/bias_extension_positive.toml"},
      {"drape/macro/stitched/meso_bias_extension_negative_flat.toml",
       "drape/bias_extension_negative.toml"}};
  return c;
}

// "drape/bias_extension_negative.toml" -> "drape_bias_extension_negative" (a test name).
std::string test_name(const std::string& file) {
  std::string s = file.substr(0, file.size() - std::string(".toml").size());
  for (char& ch : s)
    if (!std::isalnum(static_cast<unsigned char>(ch))) ch = '_';
  return s;
}

// The scale of each column (see the tolerances above).
std::vector<double> column_scales(const History& a, const History& b) {
  const std::size_t nc = a.columns.size();
  std::vector<double> own(nc, 0.0);
  for (const History* h : {&a, &b})
    for (const auto& row : h->rows)
      for (std::size_t c = 0; c < nc && c < row.size(); ++c)
        own[c] = std::max(own[c], std::abs(row[c]));
  std::vector<double> scale = own;
  for (std::size_t c = 0; c < nc; ++c) {
    const std::string& name = a.columns[c];
    if (name == "energy_balance_error") {
      scale[c] = 1.0;
      continue;
    }
    for (const char* comp : {"_x_", "_y_", "_z_"}) {
      const std::size_t p = name.rfind(comp);
      if (p == std::string::npos) continue;
      double s = 0;
      bool vector = true;
      for (char k : {'x', 'y', 'z'}) {
        std::string sibling = name;
        sibling[p + 1] = k;
        const std::size_t j = a.column(sibling);
        if (j >= nc)
          vector = false;
        else
          s = std::max(s, own[j]);
      }
      if (vector) scale[c] = s;
      break;
    }
  }
  // A column below a millionth of the largest of its unit is round-off of the others.
  const auto unit = [](const std::string& name) -> std::string {
    for (const char* u : {"_N_per_m", "_N", "_J", "_m", "_deg"})
      if (name.size() > std::strlen(u) && name.ends_with(u)) return u;
    return "";
  };
  std::map<std::string, double> largest;
  for (std::size_t c = 0; c < nc; ++c)
    if (const std::string u = unit(a.columns[c]); !u.empty())
      largest[u] = std::max(largest[u], own[c]);
  for (std::size_t c = 0; c < nc; ++c)
    if (const std::string u = unit(a.columns[c]); !u.empty())
      scale[c] = std::max(scale[c], 1e-6 * largest[u]);
  return scale;
}

std::vector<std::string> run_args(const std::string& file, const std::vector<std::string>& sets,
                                  const fs::path& out, int np) {
  std::vector<std::string> a = {"-q",
                                "run",
                                (kSource / "cases" / file).string(),
                                "-o",
                                out.string(),
                                "--set",
                                "output.figures=false",
                                "--set",
                                "output.report=false",
                                "--set",
                                "output.frames=none"};
  for (const auto& s : sets) a.insert(a.end(), {"--set", s});
  if (np > 1) a.insert(a.end(), {"--np", std::to_string(np)});
  return a;
}

// The engine cases under cases/ (files with a [case] table whose kind, after its base, is
// "engine"), relative to cases/.
std::set<std::string> engine_cases() {
  std::set<std::string> out;
  const fs::path root = kSource / "cases";
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file() || e.path().extension() != ".toml") continue;
    const toml::table raw = toml::parse_file(e.path().string());
    if (!raw["case"].as_table()) continue;  // an include file, not a case
    const fem::CaseDocument doc = fem::CaseDocument::load(e.path(), {});
    const auto* c = doc.root()["case"].as_table();
    const std::string kind =
        c && c->contains("kind") ? (*c)["kind"].value_or(std::string("?")) : "engine";
    if (kind == "engine") out.insert(fs::relative(e.path(), root).generic_string());
  }
  return out;
}

}  // namespace

// Every engine case is compared, an expected refusal, or covered by another entry; every entry
// names an engine case that exists.
TEST(MpiRunsEveryCase, EveryEngineCaseIsListed) {
  const std::set<std::string> cases = engine_cases();
  ASSERT_GT(cases.size(), 20u);
  std::set<std::string> listed;
  const auto add = [&](const std::string& f) {
    EXPECT_TRUE(listed.insert(f).second) << f << " is listed twice";
    EXPECT_TRUE(cases.count(f)) << f << " is listed but is not an engine case under cases/";
  };
  for (const auto& c : compared()) add(c.file);
  for (const auto& r : refused()) add(r.file);
  for (const auto& c : covered()) {
    add(c.file);
    EXPECT_TRUE(std::any_of(compared().begin(), compared().end(),
                            [&](const Compared& k) { return k.file == c.by; }))
        << c.file << " is covered by " << c.by << ", which is not compared";
  }
  for (const auto& f : cases)
    EXPECT_TRUE(listed.count(f))
        << "cases/" << f
        << " is an engine case in no list of tests/workflow/test_mpi_cases.cpp: compare it on 2 "
           "ranks, or list it as an expected refusal with the reason";
}

class MpiRunsEveryCase : public ::testing::TestWithParam<Compared> {};

// The case on 1 rank and with --np 2: both complete; every history.csv column agrees row by row
// within the case's tolerance of the column's scale.
TEST_P(MpiRunsEveryCase, TwoRanksMatchOneRank) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const Compared& c = GetParam();
  History h[2];
  for (int np : {1, 2}) {
    const fs::path out = fresh_dir("mpi_case_" + test_name(c.file) + "_np" + std::to_string(np));
    const Result r = run_cli(run_args(c.file, c.sets, out, np));
    ASSERT_EQ(r.code, 0) << c.file << " on " << np << " rank(s):\n" << r.output;
    const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
    EXPECT_EQ(s["status"], "completed");
    EXPECT_EQ(s["mpi_ranks"].get<int>(), np);
    if (np == 2) {
      ASSERT_EQ(s["mpi_per_rank"].size(), 2u);
      for (const auto& rank : s["mpi_per_rank"]) EXPECT_GT(rank["elements"].get<int>(), 0);
    }
    h[np - 1] = read_history(out / "history.csv");
    fs::remove_all(out);
  }
  ASSERT_EQ(h[0].columns, h[1].columns);
  ASSERT_EQ(h[0].rows.size(), h[1].rows.size());
  ASSERT_GT(h[0].rows.size(), 10u);
  const std::vector<double> scale = column_scales(h[0], h[1]);
  double worst = 0, worst_late = 0;
  std::string worst_column, worst_late_column;
  for (std::size_t j = 0; j < h[0].columns.size(); ++j) {
    const std::string& name = h[0].columns[j];
    const bool late =
        std::find(c.late_columns.begin(), c.late_columns.end(), name) != c.late_columns.end();
    double diff = 0, diff_late = 0;
    std::size_t at = 0, at_late = 0;
    for (std::size_t r = 0; r < h[0].rows.size(); ++r) {
      const double d = std::abs(h[0].rows[r].at(j) - h[1].rows[r].at(j));
      if (h[0].rows[r][0] <= c.until) {
        if (d > diff) diff = d, at = r;
      } else if (d > diff_late) {
        diff_late = d, at_late = r;
      }
    }
    const double rel = scale[j] > 0 ? diff / scale[j] : diff;
    EXPECT_LE(rel, c.tolerance) << c.file << ": column " << name << " differs by " << diff
                                << " (scale " << scale[j] << ") at t = " << h[0].rows[at][0]
                                << " s";
    if (rel >= worst) worst = rel, worst_column = name;
    if (late) {
      const double rel_late = scale[j] > 0 ? diff_late / scale[j] : diff_late;
      EXPECT_LE(rel_late, c.late_tolerance)
          << c.file << ": column " << name << " differs by " << diff_late << " (scale " << scale[j]
          << ") at t = " << h[0].rows[at_late][0] << " s";
      if (rel_late >= worst_late) worst_late = rel_late, worst_late_column = name;
    }
  }
  std::cout << c.file << ": largest difference " << worst << " of its scale (" << worst_column
            << "), tolerance " << c.tolerance;
  if (c.until < 1e300)
    std::cout << " up to " << c.until << " s; after it " << worst_late << " (" << worst_late_column
              << "), tolerance " << c.late_tolerance;
  std::cout << "\n";
  RecordProperty("largest_difference", std::to_string(worst) + " " + worst_column);
}

INSTANTIATE_TEST_SUITE_P(Cases, MpiRunsEveryCase, ::testing::ValuesIn(compared()),
                         [](const ::testing::TestParamInfo<Compared>& i) {
                           return test_name(i.param.file);
                         });

class MpiRunsEveryCaseRefused : public ::testing::TestWithParam<Refused> {};

// A case that cannot be split today: exit 2 with the reason, on 2 ranks.
TEST_P(MpiRunsEveryCaseRefused, ExitsTwoWithTheReason) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const Refused& c = GetParam();
  const fs::path out = fresh_dir("mpi_refused_" + test_name(c.file));
  const Result r = run_cli(run_args(c.file, {}, out, 2));
  EXPECT_EQ(r.code, 2) << c.file << ":\n" << r.output;
  EXPECT_NE(r.output.find(c.reason), std::string::npos) << c.file << ":\n" << r.output;
  fs::remove_all(out);
}

INSTANTIATE_TEST_SUITE_P(Cases, MpiRunsEveryCaseRefused, ::testing::ValuesIn(refused()),
                         [](const ::testing::TestParamInfo<Refused>& i) {
                           return test_name(i.param.file);
                         });

}  // namespace ncfsim::test
