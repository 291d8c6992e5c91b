// Resumable runs (issue #22, docs/checkpoint-plan.md tests 6.3-6.4) on a contact case: the
// tow-on-tow friction sled (penalty contact with friction, ties, a load, damping, a velocity-driven
// carriage), cut to 12 ms (~18,000 cycles, a few seconds). U runs to the end; R is killed with
// SIGKILL after its second checkpoint (output.checkpoint_every_cycles), or stopped with SIGINT,
// or by time.max_cycles, then continued with --resume. R must give U's history.csv byte for
// byte, the same summary.json values (energies, forces, friction coefficient; wall time and
// memory aside), the same results.xdmf, results.h5 frames and results.pvd. A checkpoint of
// another case or another ncfsim version, or --resume where there is no checkpoint, is refused
// with exit 2 and a message that says why.
#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "fem/checkpoint.hpp"
#include "fem/io/hdf5_checkpoint.hpp"
#include "fem/io/result_reader.hpp"
#include "tests/flat_blanket_case.hpp"
#include "tests/workflow/cli_test_support.hpp"
#include "tests/workflow/run_folder_support.hpp"

namespace ncfsim::test {
namespace {

const fs::path kSled = kSource / "cases/drape/friction_sled_tow_tow_0_90.toml";

std::vector<std::string> sled_run(const fs::path& out, std::vector<std::string> extra = {}) {
  std::vector<std::string> a = {"-q",
                                "run",
                                kSled.string(),
                                "-o",
                                out.string(),
                                "--set",
                                "time.end_time=0.012",
                                "--set",
                                "output.figures=false",
                                "--set",
                                "output.frames=both",
                                "--set",
                                "output.checkpoint_every_cycles=2000"};
  a.insert(a.end(), extra.begin(), extra.end());
  return a;
}

// The uninterrupted run, once for all tests.
const fs::path& uninterrupted() {
  static const fs::path out = [] {
    const fs::path o = fresh_dir("resume_uninterrupted");
    const auto r = run_cli(sled_run(o));
    EXPECT_EQ(r.code, 0) << r.output;
    return o;
  }();
  return out;
}

// R against U: the same files and values.
void expect_same_results(const fs::path& u, const fs::path& r) {
  EXPECT_EQ(slurp(u / "history.csv"), slurp(r / "history.csv"));
  EXPECT_EQ(slurp(u / "results.xdmf"), slurp(r / "results.xdmf"));
  EXPECT_EQ(slurp(u / "results.pvd"), slurp(r / "results.pvd"));
  EXPECT_FALSE(fs::exists(r / "checkpoint.h5")) << "a completed run removes its checkpoint";
  const auto su = summary(u), sr = summary(r);
  EXPECT_EQ(sr["status"], "completed");
  ASSERT_TRUE(sr.contains("resumed"));
  for (const auto& [key, value] : su.items()) {
    if (is_process_fact(key)) continue;
    EXPECT_EQ(value, sr[key]) << key;
  }
  const fem::io::ResultReader hu(u / "results.h5"), hr(r / "results.h5");
  ASSERT_EQ(hu.n_frames(), hr.n_frames());
  for (std::size_t k = 0; k < hu.n_frames(); ++k) {
    const auto fu = hu.frame(k), fr = hr.frame(k);
    EXPECT_EQ(fu.time, fr.time);
    EXPECT_EQ(fu.cycle, fr.cycle);
    EXPECT_EQ(fu.coordinates, fr.coordinates) << "frame " << k;
  }
}

TEST(CliRegressionResume, KilledWithSigkillAndResumedGivesTheSameResults) {
  const fs::path u = uninterrupted();
  const fs::path r = fresh_dir("resume_sigkill");
  const fs::path log = r.string() + ".log";
  const pid_t pid = spawn(sled_run(r), log);
  ASSERT_TRUE(wait_for_checkpoints(r, 2)) << slurp(log);
  kill(pid, SIGKILL);
  wait_code(pid);
  ASSERT_TRUE(fs::exists(r / "checkpoint.h5"));
  EXPECT_EQ(summary(r)["status"], "running");
  const auto res = run_cli(sled_run(r, {"--resume"}));
  ASSERT_EQ(res.code, 0) << res.output;
  EXPECT_NE(slurp(r / "log.txt").find("resumed from"), std::string::npos);
  expect_same_results(u, r);
}

TEST(CliRegressionResume, InterruptedWithSigintKeepsTheCheckpointAndSaysHowToResume) {
  const fs::path u = uninterrupted();
  const fs::path r = fresh_dir("resume_sigint");
  const fs::path log = r.string() + ".log";
  const pid_t pid = spawn(sled_run(r), log);
  ASSERT_TRUE(wait_for_checkpoints(r, 1)) << slurp(log);
  kill(pid, SIGINT);
  EXPECT_EQ(wait_code(pid), 1) << slurp(log);
  EXPECT_EQ(summary(r)["status"], "interrupted");
  ASSERT_TRUE(fs::exists(r / "checkpoint.h5"));
  EXPECT_NE(slurp(log).find("--resume continues the run"), std::string::npos) << slurp(log);
  const auto res = run_cli(sled_run(r, {"--resume"}));
  ASSERT_EQ(res.code, 0) << res.output;
  expect_same_results(u, r);
}

TEST(CliRegressionResume, CycleLimitThenResumeWithoutIt) {
  const fs::path u = uninterrupted();
  const fs::path r = fresh_dir("resume_max_cycles");
  const auto first = run_cli(sled_run(r, {"--set", "time.max_cycles=7000"}));
  ASSERT_EQ(first.code, 1) << first.output;
  EXPECT_EQ(summary(r)["status"], "max_cycles");
  const auto res = run_cli(sled_run(r, {"--resume"}));
  ASSERT_EQ(res.code, 0) << res.output;
  expect_same_results(u, r);
}

TEST(CliRegressionResume, CheckpointOfAnotherCaseOrVersionOrNoneIsRefused) {
  // No checkpoint: a completed run's folder.
  {
    const auto res = run_cli(sled_run(uninterrupted(), {"--resume"}));
    EXPECT_EQ(res.code, 2) << res.output;
    EXPECT_NE(res.output.find("holds no checkpoint.h5"), std::string::npos) << res.output;
  }
  const fs::path r = fresh_dir("resume_refusals");
  ASSERT_EQ(run_cli(sled_run(r, {"--set", "time.max_cycles=3000"})).code, 1);
  ASSERT_TRUE(fs::exists(r / "checkpoint.h5"));
  const std::string before = slurp(r / "history.csv");
  // Another case (another key value).
  {
    const auto res =
        run_cli(sled_run(r, {"--set", "load.nodal_force[0].ramp_time=0.004", "--resume"}));
    EXPECT_EQ(res.code, 2) << res.output;
    EXPECT_NE(res.output.find("is a checkpoint of case 'friction_sled_tow_tow_0_90'"),
              std::string::npos)
        << res.output;
    EXPECT_NE(res.output.find("not of this case"), std::string::npos) << res.output;
  }
  // Another ncfsim version.
  {
    fem::CheckpointTree t = fem::io::read_checkpoint_file(r / "checkpoint.h5");
    t.root().values["ncfsim_version"] = std::string("0.0.1-other");
    fem::io::write_checkpoint_file(r / "checkpoint.h5", t);
    const auto res = run_cli(sled_run(r, {"--resume"}));
    EXPECT_EQ(res.code, 2) << res.output;
    EXPECT_NE(res.output.find("is a checkpoint of ncfsim 0.0.1-other, this is ncfsim"),
              std::string::npos)
        << res.output;
  }
  // Refused before anything was written.
  EXPECT_EQ(slurp(r / "history.csv"), before);
  EXPECT_EQ(summary(r)["status"], "max_cycles");
}

// A workflow stopped in its second stage keeps the first and the stage's checkpoint, says how to
// go on; `--resume` skips the first, resumes the second and runs the third: the second stage's
// results equal an unbroken workflow's.
TEST(CliRegressionResume, WorkflowStoppedInAStageResumesIt) {
  const fs::path chain = kSource / "tests/cases/workflow/chain.toml";
  const fs::path w1 = fresh_dir("resume_workflow_unbroken");
  const auto u = run_cli({"-q", "run", chain.string(), "-o", w1.string()});
  ASSERT_EQ(u.code, 0) << u.output;
  const fs::path w2 = fresh_dir("resume_workflow");
  const auto first =
      run_cli({"run", chain.string(), "-o", w2.string(), "--set", "b.time.max_cycles=40"});
  ASSERT_EQ(first.code, 1) << first.output;
  EXPECT_NE(first.output.find("kept: a"), std::string::npos) << first.output;
  EXPECT_NE(first.output.find("stage 'b' kept its checkpoint"), std::string::npos) << first.output;
  EXPECT_NE(first.output.find(" -o " + w2.string() + " --resume continues it"), std::string::npos)
      << first.output;
  ASSERT_TRUE(fs::exists(w2 / "b/checkpoint.h5"));
  const auto res = run_cli({"run", chain.string(), "-o", w2.string(), "--resume"});
  ASSERT_EQ(res.code, 0) << res.output;
  EXPECT_NE(res.output.find("resuming from its checkpoint"), std::string::npos) << res.output;
  EXPECT_EQ(slurp(w1 / "b/history.csv"), slurp(w2 / "b/history.csv"));
  const auto s1 = summary(w1 / "b"), s2 = summary(w2 / "b");
  EXPECT_EQ(s2["status"], "completed");
  for (const auto& [key, value] : s1.items()) {
    if (value.is_number_float() && !is_process_fact(key)) {
      EXPECT_EQ(value, s2[key]) << key;
    }
  }
  EXPECT_TRUE(fs::exists(w2 / "c/summary.json"));
}

// Ctrl-C in a workflow's long stage: the finished stage and the stage's checkpoint are kept, the
// console says so and gives the command; --resume continues the stage to the uninterrupted
// run's history.csv.
TEST(CliRegressionResume, WorkflowInterruptedWithSigintKeepsStagesAndCheckpoint) {
  const fs::path dir = fresh_dir("resume_workflow_sigint");
  fs::create_directories(dir);
  std::ofstream(dir / "workflow.toml")
      << "[case]\nname = \"two\"\nkind = \"workflow\"\n[[stage]]\nname = \"a\"\ncase = \""
      << (kSource / "tests/cases/workflow/cube_a.toml").string()
      << "\"\n[[stage]]\nname = \"sled\"\ncase = \"" << kSled.string() << "\"\nafter = [\"a\"]\n";
  const fs::path out = dir / "out";
  const std::vector<std::string> args = {"run",   (dir / "workflow.toml").string(),
                                         "-o",    out.string(),
                                         "--set", "sled.time.end_time=0.012",
                                         "--set", "sled.output.figures=false",
                                         "--set", "sled.output.frames=both",
                                         "--set", "sled.output.checkpoint_every_cycles=2000"};
  const fs::path log = dir / "console.log";
  const pid_t pid = spawn(args, log);
  ASSERT_TRUE(wait_for_checkpoints(out / "sled", 1)) << slurp(log);
  kill(pid, SIGINT);
  EXPECT_EQ(wait_code(pid), 1) << slurp(log);
  const std::string console = slurp(log);
  EXPECT_NE(console.find("kept: a"), std::string::npos) << console;
  EXPECT_NE(console.find("stage 'sled' kept its checkpoint"), std::string::npos) << console;
  EXPECT_NE(console.find("--resume continues it"), std::string::npos) << console;
  ASSERT_TRUE(fs::exists(out / "sled/checkpoint.h5"));
  EXPECT_EQ(summary(out / "a")["status"], "completed");
  std::vector<std::string> again = args;
  again.push_back("--resume");
  const auto res = run_cli(again);
  ASSERT_EQ(res.code, 0) << res.output;
  EXPECT_NE(res.output.find("[1/2 a] unchanged"), std::string::npos) << res.output;
  EXPECT_NE(res.output.find("resuming from its checkpoint"), std::string::npos) << res.output;
  EXPECT_EQ(slurp(uninterrupted() / "history.csv"), slurp(out / "sled/history.csv"));
  EXPECT_EQ(summary(out / "sled")["status"], "completed");
  fs::remove_all(dir);
}

// The crush stage (tow damage with erosion, cohesive resin ties, penalty contact, the punch force
// filtered at CFC 600 over the whole curve when the run ends) of
// tests/workflow/test_crush_case.cpp, stopped by its cycle limit and resumed: the same history.csv
// (the filtered column included) and summary.json values as an uninterrupted crush.
TEST(CliRegressionResume, CrushStoppedAndResumedGivesTheSameResults) {
  const fs::path dir = fresh_dir("resume_crush");
  fs::create_directories(dir);
  std::ofstream(dir / "blanket.toml") << kFlatBlanketBriefRun;
  std::ofstream(dir / "transfer.toml") << R"([case]
name = "flat_transfer"
kind = "transfer"
[source]
results = "drape/results.h5"
[output]
figures = false
)";
  ASSERT_EQ(
      run_cli({"-q", "run", (dir / "blanket.toml").string(), "-o", (dir / "drape").string()}).code,
      0);
  ASSERT_EQ(
      run_cli({"-q", "run", (dir / "transfer.toml").string(), "-o", (dir / "transfer").string()})
          .code,
      0);
  const auto crush = [&](const fs::path& out, std::vector<std::string> extra) {
    std::vector<std::string> a = {"-q",
                                  "run",
                                  (kSource / "cases/hemisphere/crush.toml").string(),
                                  "-o",
                                  out.string(),
                                  "--set",
                                  "model.source=" + (dir / "transfer" / "results.h5").string(),
                                  "--set",
                                  "model.damage.fracture_energy.fibre_tension=300000.0",
                                  "--set",
                                  "model.damage.fracture_energy.fibre_compression=110000.0",
                                  "--set",
                                  "model.damage.fracture_energy.matrix_tension=1400.0",
                                  "--set",
                                  "model.damage.fracture_energy.transverse_shear=1600.0",
                                  "--set",
                                  "tool[0].point=[0.03,0.03,0.02551]",
                                  "--set",
                                  "tool[0].ramp_time=1e-6",
                                  "--set",
                                  "tool[1].seat_clearance=1e-5",
                                  "--set",
                                  "time.end_time=1.5e-4",
                                  "--set",
                                  "time.quasi_static_from=8e-5",
                                  "--set",
                                  "time.history_interval=2.5e-6",
                                  "--set",
                                  "time.frame_interval=5e-5",
                                  "--set",
                                  "output.figures=false",
                                  "--set",
                                  "output.report=false"};
    a.insert(a.end(), extra.begin(), extra.end());
    return run_cli(a);
  };
  const fs::path u = dir / "crush_u", r = dir / "crush_r";
  const auto ru = crush(u, {});
  ASSERT_EQ(ru.code, 0) << ru.output;
  const auto su = summary(u);
  ASSERT_GT(su["cycles"].get<double>(), 100.0);
  const auto stop = static_cast<int>(0.6 * su["cycles"].get<double>());
  const auto first = crush(r, {"--set", "time.max_cycles=" + std::to_string(stop)});
  ASSERT_EQ(first.code, 1) << first.output;
  const auto res = crush(r, {"--resume"});
  ASSERT_EQ(res.code, 0) << res.output;
  EXPECT_EQ(slurp(u / "history.csv"), slurp(r / "history.csv"));
  // Elements failed and were eroded after the restart, too.
  const History h = read_history(u / "history.csv");
  const std::size_t c_failed = h.column("failed_elements"), c_time = h.column("time");
  ASSERT_LT(c_failed, h.columns.size());
  ASSERT_LT(c_time, h.columns.size());
  const double t_stop = summary(r)["resumed"][0]["time"].get<double>();
  double failed_at_stop = 0;
  for (const auto& row : h.rows)
    if (row[c_time] <= t_stop) failed_at_stop = row[c_failed];
  EXPECT_GT(h.rows.back()[c_failed], failed_at_stop) << "no element failed after the restart";
  const auto sr = summary(r);
  for (const auto& [key, value] : su.items()) {
    if (is_process_fact(key)) continue;
    EXPECT_EQ(value, sr[key]) << key;
  }
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ncfsim::test
