// Runs on several MPI ranks (issue #24, docs/parallel.md): the same case on 2 ranks gives the
// results of 1 rank within round-off, through `ncfsim run --np 2` (the launcher CMake found) and
// through the launcher itself; what cannot be split is refused with exit code 2 and the reason.
//
// Tolerances: a rank sums the forces of its elements and contacts, then the ghost exchange adds
// the other ranks' share at the partition boundary, so nodal forces differ from one rank's in the
// last bits; energies are sums over ranks in another order. On an elastic model those differences
// stay at round-off (below the 9 significant digits of history.csv: 1e-7 of a column's largest
// value is asked); with frictional contact they grow
// with the number of stick-slip events, so a contact case is compared on its reactions and
// energies: 1e-6 of the largest value over the first 5 ms, 2e-3 over 10 ms.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "tests/workflow/cli_test_support.hpp"
#include "tests/workflow/mpi_test_support.hpp"

namespace fs = std::filesystem;
using namespace ncfsim::test;

namespace {

// Largest difference of column c between two histories up to time t_end, relative to the
// column's largest value.
double relative_difference(const History& a, const History& b, const std::string& c,
                           double t_end = 1e300) {
  const std::size_t ia = a.column(c), ib = b.column(c);
  EXPECT_LT(ia, a.columns.size()) << c;
  EXPECT_LT(ib, b.columns.size()) << c;
  if (ia >= a.columns.size() || ib >= b.columns.size()) return 1.0;
  EXPECT_EQ(a.rows.size(), b.rows.size());
  double scale = 0, diff = 0;
  const std::size_t it = a.column("time");
  for (std::size_t r = 0; r < std::min(a.rows.size(), b.rows.size()); ++r) {
    if (a.rows[r][it] > t_end) break;
    scale = std::max({scale, std::abs(a.rows[r][ia]), std::abs(b.rows[r][ib])});
    diff = std::max(diff, std::abs(a.rows[r][ia] - b.rows[r][ib]));
  }
  return scale > 0 ? diff / scale : diff;
}

struct TwoRuns {
  nlohmann::json one, two;
  History h1, h2;
};

// The case on one rank and with --np 2, each into its own folder (removed after reading).
TwoRuns run_on_one_and_two(const std::string& name, std::vector<std::string> args) {
  TwoRuns t;
  for (int np : {1, 2}) {
    const fs::path out = fresh_dir(name + "_np" + std::to_string(np));
    std::vector<std::string> a = {"-q", "run"};
    a.insert(a.end(), args.begin(), args.end());
    a.insert(a.end(),
             {"-o", out.string(), "--set", "output.figures=false", "--set", "output.report=false"});
    if (np > 1) a.insert(a.end(), {"--np", std::to_string(np)});
    const Result r = run_cli(a);
    EXPECT_EQ(r.code, 0) << r.output;
    (np == 1 ? t.one : t.two) = nlohmann::json::parse(slurp(out / "summary.json"));
    (np == 1 ? t.h1 : t.h2) = read_history(out / "history.csv");
    EXPECT_TRUE(fs::exists(out / "results.xdmf")) << out;
    fs::remove_all(out);
  }
  return t;
}

// The split is reported: 2 ranks, each with elements, owned nodes, ghosts and ghost traffic.
void expect_rank_reports(const nlohmann::json& s) {
  EXPECT_EQ(s["mpi_ranks"].get<int>(), 2);
  ASSERT_EQ(s["mpi_per_rank"].size(), 2u) << s.dump(2);
  std::size_t elements = 0;
  for (const auto& r : s["mpi_per_rank"]) {
    EXPECT_GT(r["elements"].get<int>(), 0);
    EXPECT_GT(r["owned_nodes"].get<int>(), 0);
    EXPECT_GT(r["ghost_nodes"].get<int>(), 0);
    EXPECT_GT(r["ghost_bytes_per_cycle"].get<int>(), 0);
    elements += r["elements"].get<std::size_t>();
  }
  std::size_t total = 0;
  for (const auto& [kind, n] : s["elements"].items()) total += n.get<std::size_t>();
  EXPECT_EQ(elements, total);
}

}  // namespace

// Erosion across ranks: a cube of 4 x 4 x 8 hexahedra (split between the ranks through its
// height; its one-element neighbour goes with one of them), crushed in uniaxial strain until its
// elements' steps fall below half: the same elements erode at the same cycle on 2 ranks as on 1,
// on both ranks, with the same eroded energy and balance.
TEST(MpiRuns, ErosionOnTwoRanksMatchesOneRank) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const TwoRuns t = run_on_one_and_two(
      "mpi_erosion", {(kSource / "tests/cases/erosion/crushed_cube.toml").string(), "--set",
                      "mesh.block[0].divisions=[4,4,8]"});
  EXPECT_EQ(t.one["mpi_ranks"].get<int>(), 1);
  expect_rank_reports(t.two);
  EXPECT_EQ(t.two["status"], "completed");
  EXPECT_GT(t.one["eroded_elements"].get<int>(), 1);
  EXPECT_EQ(t.one["eroded_elements"], t.two["eroded_elements"]);
  EXPECT_NEAR(t.one["eroded_internal_energy_J"].get<double>(),
              t.two["eroded_internal_energy_J"].get<double>(),
              1e-9 * t.one["eroded_internal_energy_J"].get<double>());
  for (const char* c :
       {"kinetic_energy_J", "internal_energy_J", "external_work_J", "eroded_elements",
        "crush_reaction_z_N", "base_reaction_z_N", "pair_shear_angle_deg"})
    EXPECT_LT(relative_difference(t.h1, t.h2, c), 1e-7) << c;  // history.csv: 9 digits
}

// Contact across ranks: the CI-mesh positive bias coupon (2.4k tow hexahedra, stitch bars and
// joints, tow-tow self contact in each ply and ply-ply contact, clamps) pulled for 10 ms. Its
// two ranks each hold a half of the coupon along the space-filling curve, so every contact kind
// crosses the partition boundary: reactions and energies agree with one rank's.
TEST(MpiRunsContact, BiasCouponOnTwoRanksMatchesOneRank) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const TwoRuns t = run_on_one_and_two(
      "mpi_bias", {(kSource / "cases/drape/bias_extension_positive.toml").string(), "--set",
                   "mesh.fabric[0].elements_across_tow=1", "--set",
                   "mesh.fabric[0].element_length=6.64e-3", "--set", "time.end_time=0.01"});
  expect_rank_reports(t.two);
  EXPECT_EQ(t.two["status"], "completed");
  // Round-off at first, then amplified by friction's stick and slip (as between two builds).
  for (const char* c : {"pull_reaction_x_N", "pull_reaction_y_N", "internal_energy_J",
                        "kinetic_energy_J", "contact_energy_J", "external_work_J"}) {
    EXPECT_LT(relative_difference(t.h1, t.h2, c, 0.005), 1e-6) << c;
    EXPECT_LT(relative_difference(t.h1, t.h2, c), 2e-3) << c;
  }
  EXPECT_NEAR(t.one["energy_balance_error"].get<double>(),
              t.two["energy_balance_error"].get<double>(), 1e-4);
}

// Started by the launcher directly (mpiexec -n 2 ncfsim run ...), as a cluster job would.
TEST(MpiRuns, StartedByTheLauncher) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const fs::path out = fresh_dir("mpi_launcher");
  const Result r =
      run_cli({"-q", "run", (kSource / "tests/cases/erosion/crushed_cube.toml").string(), "-o",
               out.string(), "--set", "mesh.block[0].divisions=[4,4,4]", "--set",
               "output.figures=false", "--set", "output.report=false"},
              {kMpiexec, "-n", "2"});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["mpi_ranks"].get<int>(), 2);
  EXPECT_EQ(s["status"], "completed");
  fs::remove_all(out);
}

// Bad input: no rank, more ranks than the model splits into, a model part that cannot be split
// (shells), a stage that runs on one rank: exit 2 with the reason, nothing half written.
TEST(MpiRuns, WhatCannotBeSplitIsRefused) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const std::string cantilever = (kSource / "cases/verification/cantilever.toml").string();
  Result r = run_cli({"run", cantilever, "-o", fresh_dir("mpi_np0").string(), "--np", "0"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("--np"), std::string::npos) << r.output;

  // 20 hexahedra: one kernel chunk, so one rank at most.
  r = run_cli({"run", cantilever, "-o", fresh_dir("mpi_too_many").string(), "--np", "2"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("2 MPI ranks for 20 elements"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("cantilever.toml: key '--np': 2 MPI ranks"), std::string::npos)
      << "the case file and the key, each once: " << r.output;

  // 40 shells: one kernel chunk of 64.
  r = run_cli({"run", (kSource / "cases/verification/shell_cantilever.toml").string(), "-o",
               fresh_dir("mpi_shells").string(), "--np", "2"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("2 MPI ranks for 40 elements"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("64 shells"), std::string::npos) << r.output;

  // A workflow started by mpirun (`--np` runs its engine stages on N ranks each instead:
  // tests/workflow/test_mpi_resume.cpp).
  r = run_cli({"run", (kSource / "cases/hemisphere/ci/workflow.toml").string(), "-o",
               fresh_dir("mpi_workflow").string()},
              {kMpiexec, "-n", "2"});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("runs on one MPI rank"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("runs its engine and crush stages on N ranks"), std::string::npos)
      << r.output;
  for (const char* d : {"mpi_np0", "mpi_too_many", "mpi_shells", "mpi_workflow"})
    fs::remove_all(fresh_dir(d));
}

// A contact halo too small for the sliding (here for the mesh itself: 2 mm against tow elements
// of about that size): an owned node reaches the edge of the segments its rank reads, and the run
// stops with exit 3 naming the contact, the node and the key, instead of missing contacts.
// A blow-up that only one rank sees (a kicked corner node turns its hexahedron inside out in the
// first cycle; 2 ranks split the block) reaches the others at the cycle's next collective (the
// step's reduction, or the erosion count when erosion is on): every rank stops, the run exits 3
// with the kernel's report naming the element and its position, as on one rank.
TEST(MpiRuns, BlowUpOnOneRankStopsEveryRankWithItsReport) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const std::string what =
      "hexahedron 128 (part 0) has a non-positive volume -5.38932e-08 m^3 at (0.00875, "
      "0.00875, 0.0131539) m";
  for (const char* erosion : {"0", "0.5"}) {
    for (const char* np : {"1", "2"}) {
      SCOPED_TRACE(std::string("--np ") + np + ", erosion_step_ratio " + erosion);
      const fs::path out = fresh_dir(std::string("mpi_blow_up_") + np + "_" + erosion);
      const Result r = run_cli(
          {"-q", "run", (kSource / "tests/cases/mpi/kicked_corner.toml").string(), "-o",
           out.string(), "--np", np, "--set", std::string("time.erosion_step_ratio=") + erosion});
      EXPECT_EQ(r.code, 3) << r.output;
      EXPECT_NE(r.output.find(what), std::string::npos) << r.output;
      const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
      EXPECT_EQ(s["status"], "numerical_failure");
      EXPECT_EQ(s["error"], what);
      fs::remove_all(out);
    }
  }
}

// A block pressed by 5 N and dragged 40 mm over a plate cut in two by the partition
// (tests/cases/mpi/sliding_block.toml): with the contact halo fixed at the start it slides past
// the segments its rank reads and the run stops (exit 3); built again as the nodes move (the
// default parallel.contact_halo_refresh) the run ends on 2 ranks as on 1: every history column
// within 1e-6 of its scale (round-off of the sums' order), and the drag is mu P = 0.2 x 5 N;
// stopped half-way and resumed, the same history and builds.
TEST(MpiRuns, ContactHaloIsBuiltAgainAsTheSurfacesSlide) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const fs::path file = kSource / "tests/cases/mpi/sliding_block.toml";
  const fs::path fixed = fresh_dir("mpi_halo_fixed"), moving = fresh_dir("mpi_halo_moving"),
                 one = fresh_dir("mpi_halo_one");
  const Result rf = run_cli({"run", file.string(), "-o", fixed.string(), "--np", "2", "--set",
                             "parallel.contact_halo_refresh=0"});
  EXPECT_EQ(rf.code, 3) << rf.output;
  EXPECT_NE(rf.output.find("reached the edge of the segments this rank reads"), std::string::npos)
      << rf.output;
  const Result r2 = run_cli({"run", file.string(), "-o", moving.string(), "--np", "2"});
  ASSERT_EQ(r2.code, 0) << r2.output;
  const auto s = nlohmann::json::parse(slurp(moving / "summary.json"));
  EXPECT_EQ(s["status"], "completed");
  // 40 mm of travel, a build every 1.25 mm of it (half of 0.25 x 10 mm: each surface's share).
  EXPECT_GE(s["contact_halo_builds"].get<int>(), 25);
  EXPECT_LE(s["contact_halo_builds"].get<int>(), 40);
  const Result r1 = run_cli({"run", file.string(), "-o", one.string()});
  ASSERT_EQ(r1.code, 0) << r1.output;
  const History h1 = read_history(one / "history.csv"), h2 = read_history(moving / "history.csv");
  ASSERT_EQ(h1.rows.size(), h2.rows.size());
  ASSERT_EQ(h1.columns, h2.columns);
  for (std::size_t c = 0; c < h1.columns.size(); ++c) {
    if (h1.columns[c] == "energy_balance_error") continue;  // a ratio of round-off
    double scale = 0, diff = 0;
    for (std::size_t k = 0; k < h1.rows.size(); ++k) {
      scale = std::max(scale, std::abs(h1.rows[k][c]));
      diff = std::max(diff, std::abs(h1.rows[k][c] - h2.rows[k][c]));
    }
    EXPECT_LE(diff, 1e-6 * std::max(scale, 1e-30)) << h1.columns[c];
  }
  const std::size_t drag = h1.column("drag_reaction_x_N");
  ASSERT_LT(drag, h1.columns.size());
  EXPECT_NEAR(h1.rows.back()[drag], 0.2 * 5.0, 0.02);
  // Stopped half-way through the slide (14 builds done) and resumed: the checkpoint keeps the
  // last build's positions, so the same builds follow and the history is the same bit for bit.
  const fs::path resumed = fresh_dir("mpi_halo_resumed");
  const Result rs = run_cli(
      {"run", file.string(), "-o", resumed.string(), "--np", "2", "--set", "time.max_cycles=2237"});
  EXPECT_EQ(rs.code, 1) << rs.output;
  const Result rr = run_cli({"run", file.string(), "-o", resumed.string(), "--np", "2", "--set",
                             "time.max_cycles=100000", "--resume"});
  ASSERT_EQ(rr.code, 0) << rr.output;
  EXPECT_EQ(slurp(moving / "history.csv"), slurp(resumed / "history.csv"));
  const auto sr = nlohmann::json::parse(slurp(resumed / "summary.json"));
  EXPECT_EQ(sr["contact_halo_builds"], s["contact_halo_builds"]);
  for (const auto& d : {fixed, moving, one, resumed}) fs::remove_all(d);
}

TEST(MpiRuns, ContactReachingTheEdgeOfTheHaloStopsTheRun) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const fs::path out = fresh_dir("mpi_halo_edge");
  const Result r =
      run_cli({"run", (kSource / "cases/drape/friction_sled_tow_tow_0_90.toml").string(), "-o",
               out.string(), "--np", "2", "--set", "output.figures=false", "--set",
               "parallel.contact_halo=0.002"});
  EXPECT_EQ(r.code, 3) << r.output;
  EXPECT_NE(r.output.find("contact 'tow_tow': surface node"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("reached the edge of the segments this rank reads"), std::string::npos)
      << r.output;
  EXPECT_NE(r.output.find("raise parallel.contact_halo"), std::string::npos) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["status"], "numerical_failure");
  fs::remove_all(out);
}
