// Checkpoints and --resume on several MPI ranks (issues #22 and #24, docs/parallel.md
// "Checkpoints"): every rank saves its own share of the state (rank k > 0 into
// checkpoint.rank<k>.cycle<c>.h5, the root last into checkpoint.h5, which names the cycle).
// The tow-on-tow friction sled (penalty contact with friction, ties, damping, a driven
// carriage; 12 ms, ~18,000 cycles) on 2 ranks: killed with SIGKILL (every process of the job, as
// a crashed node or a batch system's kill), stopped with Ctrl-C (SIGINT to the launcher's process
// group, as a terminal sends it) or by the cycle limit, then resumed with --resume --np 2, it
// gives the uninterrupted 2-rank run's history.csv and results.xdmf byte for byte and the same
// summary values: the same ranks reload the same shares, so the sums run in the same order. A
// checkpoint written on 2 ranks is refused on 1 rank, and one whose rank file is missing is
// refused, each with exit 2 and the reason.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/workflow/cli_test_support.hpp"
#include "tests/workflow/run_folder_support.hpp"

namespace ncfsim::test {
namespace {

const fs::path kSled = kSource / "cases/drape/friction_sled_tow_tow_0_90.toml";
const std::string kMpiexec = NCFSIM_MPIEXEC;

bool launcher_works() {
  if (kMpiexec.empty() || !fs::exists(kMpiexec)) return false;
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  return run_cli({"--version"}, {kMpiexec, "-n", "2"}).code == 0;
}

std::vector<std::string> sled_run(const fs::path& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> a = {"-q",
                                "run",
                                kSled.string(),
                                "-o",
                                out.string(),
                                "--np",
                                "2",
                                "--set",
                                "time.end_time=0.012",
                                "--set",
                                "output.figures=false",
                                "--set",
                                "output.checkpoint_every_cycles=2000"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

std::vector<std::string> rank_files(const fs::path& out) {
  std::vector<std::string> names;
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().filename().string().rfind("checkpoint.rank", 0) == 0)
      names.push_back(e.path().filename().string());
  return names;
}

// The uninterrupted 2-rank run, once for all tests.
const fs::path& uninterrupted() {
  static const fs::path out = [] {
    const fs::path o = fresh_dir("mpi_resume_uninterrupted");
    const auto r = run_cli(sled_run(o));
    EXPECT_EQ(r.code, 0) << r.output;
    return o;
  }();
  return out;
}

void expect_same_results(const fs::path& u, const fs::path& r) {
  EXPECT_EQ(slurp(u / "history.csv"), slurp(r / "history.csv"));
  EXPECT_EQ(slurp(u / "results.xdmf"), slurp(r / "results.xdmf"));
  EXPECT_FALSE(fs::exists(r / "checkpoint.h5")) << "a completed run removes its checkpoint";
  EXPECT_TRUE(rank_files(r).empty()) << "and every rank its state files";
  const auto su = summary(u), sr = summary(r);
  EXPECT_EQ(sr["status"], "completed");
  EXPECT_EQ(sr["mpi_ranks"].get<int>(), 2);
  ASSERT_TRUE(sr.contains("resumed"));
  for (const auto& [key, value] : su.items()) {
    if (is_process_fact(key)) continue;
    EXPECT_EQ(value, sr[key]) << key;
  }
}

}  // namespace

TEST(MpiRunsResume, KilledOnTwoRanksAndResumedGivesTheSameResults) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const fs::path u = uninterrupted();
  const fs::path r = fresh_dir("mpi_resume_sigkill");
  const fs::path log = r.string() + ".log";
  const pid_t pid = spawn(sled_run(r), log, {}, true);
  ASSERT_TRUE(wait_for_checkpoints(r, 2, 90)) << slurp(log);
  kill(-pid, SIGKILL);
  wait_code(pid);
  // The ranks, reparented, end when they find their launcher gone; the folder is theirs until then.
  ASSERT_TRUE(wait_gone(r)) << "the killed job's ranks are still running";
  ASSERT_TRUE(fs::exists(r / "checkpoint.h5"));
  EXPECT_FALSE(rank_files(r).empty());
  const auto res = run_cli(sled_run(r, {"--resume"}));
  ASSERT_EQ(res.code, 0) << res.output;
  EXPECT_NE(slurp(r / "log.txt").find("resumed from"), std::string::npos);
  expect_same_results(u, r);
  fs::remove_all(r);
  fs::remove(log);
}

TEST(MpiRunsResume, CtrlCStopsEveryRankAtOneCycleAndTheRunResumes) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const fs::path u = uninterrupted();
  const fs::path r = fresh_dir("mpi_resume_sigint");
  const fs::path log = r.string() + ".log";
  const pid_t pid = spawn(sled_run(r), log, {}, true);
  ASSERT_TRUE(wait_for_checkpoints(r, 1, 90)) << slurp(log);
  kill(-pid, SIGINT);
  wait_code(pid);
  EXPECT_EQ(summary(r)["status"], "interrupted") << slurp(log);
  // The checkpoint of the interrupt: the root's names the cycle every rank stopped at.
  const std::string text = slurp(r / "log.txt");
  const auto at = text.find("interrupted at t =");
  ASSERT_NE(at, std::string::npos) << text;
  const auto cycle = std::stol(text.substr(text.find("cycle ", at) + 6));
  EXPECT_EQ(rank_files(r),
            std::vector<std::string>{"checkpoint.rank1.cycle" + std::to_string(cycle) + ".h5"});
  EXPECT_NE(text.find("--np 2"), std::string::npos) << "the resume command names the ranks";
  const auto res = run_cli(sled_run(r, {"--resume"}));
  ASSERT_EQ(res.code, 0) << res.output;
  expect_same_results(u, r);
  fs::remove_all(r);
  fs::remove(log);
}

TEST(MpiRunsResume, CheckpointOfTwoRanksIsRefusedOnOneOrWithoutItsRankFile) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const fs::path r = fresh_dir("mpi_resume_refused");
  const auto first = run_cli(sled_run(r, {"--set", "time.max_cycles=5000"}));
  ASSERT_EQ(first.code, 1) << first.output;
  EXPECT_EQ(summary(r)["status"], "max_cycles");
  ASSERT_EQ(rank_files(r).size(), 1u);
  {
    std::vector<std::string> one = sled_run(r, {"--resume"});
    one[6] = "1";  // --np 1
    const auto res = run_cli(one);
    EXPECT_EQ(res.code, 2) << res.output;
    EXPECT_NE(res.output.find("was written on 2 MPI ranks"), std::string::npos) << res.output;
    EXPECT_NE(res.output.find("--np 2"), std::string::npos) << res.output;
  }
  {
    const fs::path moved = r.parent_path() / (r.filename().string() + "_rank1.h5");
    fs::rename(r / rank_files(r).front(), moved);
    const auto res = run_cli(sled_run(r, {"--resume"}));
    EXPECT_EQ(res.code, 2) << res.output;
    EXPECT_NE(res.output.find("state file checkpoint.rank1.cycle5000.h5 is missing"),
              std::string::npos)
        << res.output;
    fs::remove(moved);
  }
  fs::remove_all(r);
}

}  // namespace ncfsim::test

namespace ncfsim::test {

// A workflow with --np 2 runs its engine stage on 2 ranks (a launcher of its own, in a process
// group of its own) and its kinematic stage on one. Ctrl-C to the workflow's process group (a
// terminal's) stops the workflow, which passes one interrupt on to the stage's ranks: they
// checkpoint at one cycle, the console gives the command with --np 2, and --resume continues the
// stage to the history.csv of the uninterrupted 2-rank run. A rerun skips both stages.
TEST(MpiRunsResume, WorkflowRunsItsEngineStageOnTwoRanksAndResumesIt) {
  if (!launcher_works()) GTEST_SKIP() << "the MPI launcher does not start here";
  const fs::path u = uninterrupted();
  const fs::path dir = fresh_dir("mpi_resume_workflow");
  fs::create_directories(dir);
  std::ofstream(dir / "workflow.toml")
      << "[case]\nname = \"two\"\nkind = \"workflow\"\n[[stage]]\nname = \"fishnet\"\ncase = \""
      << (kSource / "cases/hemisphere/fishnet.toml").string()
      << "\"\n[[stage]]\nname = \"sled\"\ncase = \"" << kSled.string()
      << "\"\nafter = [\"fishnet\"]\n";
  const fs::path out = dir / "out";
  const std::vector<std::string> args = {"run",   (dir / "workflow.toml").string(),
                                         "-o",    out.string(),
                                         "--np",  "2",
                                         "--set", "sled.time.end_time=0.012",
                                         "--set", "sled.output.figures=false",
                                         "--set", "sled.output.checkpoint_every_cycles=2000"};
  const fs::path log = dir / "console.log";
  const pid_t pid = spawn(args, log, {}, true);
  ASSERT_TRUE(wait_for_checkpoints(out / "sled", 1, 90)) << slurp(log);
  kill(-pid, SIGINT);
  EXPECT_EQ(wait_code(pid), 1) << slurp(log);
  const std::string console = slurp(log);
  EXPECT_NE(console.find("[2/2 sled] on 2 MPI ranks"), std::string::npos) << console;
  EXPECT_NE(console.find("stage 'sled' kept its checkpoint"), std::string::npos) << console;
  EXPECT_NE(console.find("--np 2 --set sled.time.end_time=0.012"), std::string::npos) << console;
  EXPECT_EQ(summary(out / "sled")["status"], "interrupted");
  EXPECT_EQ(rank_files(out / "sled").size(), 1u);
  std::vector<std::string> again = args;
  again.push_back("--resume");
  const auto res = run_cli(again);
  ASSERT_EQ(res.code, 0) << res.output;
  EXPECT_NE(res.output.find("[1/2 fishnet] unchanged"), std::string::npos) << res.output;
  EXPECT_NE(res.output.find("resuming from its checkpoint"), std::string::npos) << res.output;
  EXPECT_EQ(slurp(u / "history.csv"), slurp(out / "sled/history.csv"));
  EXPECT_EQ(summary(out / "sled")["mpi_ranks"].get<int>(), 2);
  const auto ws = summary(out);
  EXPECT_EQ(ws["stages"][0]["mpi_ranks"].get<int>(), 1);
  EXPECT_EQ(ws["stages"][1]["mpi_ranks"].get<int>(), 2);
  const auto rerun = run_cli(args);
  ASSERT_EQ(rerun.code, 0) << rerun.output;
  EXPECT_NE(rerun.output.find("[2/2 sled] unchanged"), std::string::npos) << rerun.output;
  fs::remove_all(dir);
}

// `ranks` of a stage that is not split over ranks is bad input naming the stage.
TEST(MpiRunsResume, WorkflowRefusesRanksForAKinematicStage) {
  const fs::path dir = fresh_dir("mpi_workflow_ranks");
  fs::create_directories(dir);
  std::ofstream(dir / "workflow.toml")
      << "[case]\nname = \"one\"\nkind = \"workflow\"\n[[stage]]\nname = \"fishnet\"\ncase = \""
      << (kSource / "cases/hemisphere/fishnet.toml").string() << "\"\nranks = 2\n";
  const auto res = run_cli({"run", (dir / "workflow.toml").string(), "-o", (dir / "out").string()});
  EXPECT_EQ(res.code, 2) << res.output;
  EXPECT_NE(res.output.find("stage.ranks"), std::string::npos) << res.output;
  EXPECT_NE(res.output.find("stage 'fishnet' is a 'kinematic_drape' stage"), std::string::npos)
      << res.output;
  fs::remove_all(dir);
}

}  // namespace ncfsim::test
