// One run per output folder and a true status after every way a run ends (issue #45):
//  * two runs started together into one folder: one is refused at once (exit 2, naming the folder
//    and the process holding it), the other's files are its own; once it has ended the folder is
//    free again; a 2-rank run refused a folder in use ends on both ranks with exit 2;
//  * render, report and export are refused while a run writes the folder;
//  * a run killed (kill -9, on 1 rank, and one rank of 2) leaves summary.json "running": `ncfsim
//    status` finds no process holding the folder, says killed and rewrites the summary so; the
//    next run into the folder warns that the last one ended without a status;
//  * a history.csv the file system refuses (a file-size limit standing in for a full disk) ends
//    the run with exit 1 naming the file, and summary.json says failed with the reason.
#include <gtest/gtest.h>
#include <sys/resource.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/workflow/cli_test_support.hpp"
#include "tests/workflow/mpi_test_support.hpp"
#include "workflow/run/mpi_launch.hpp"

namespace ncfsim::test {
namespace {

const fs::path kCantilever = kSource / "cases/verification/cantilever.toml";

nlohmann::json summary(const fs::path& out) {
  try {
    return nlohmann::json::parse(slurp(out / "summary.json"));
  } catch (const std::exception&) {
    return nullptr;
  }
}

// A run that lasts until it is stopped (the cantilever for 100 s of simulated time).
std::vector<std::string> long_run(const fs::path& out, const std::vector<std::string>& more = {}) {
  std::vector<std::string> a = {"run",   kCantilever.string(),  "-o",    out.string(),
                                "--set", "time.end_time=100.0", "--set", "output.figures=false",
                                "--set", "output.report=false"};
  for (const auto& m : more) a.push_back("--set"), a.push_back(m);
  return a;
}

bool wait_running(const fs::path& out, double seconds = 60) {
  for (double t = 0; t < seconds; t += 0.05) {
    const auto s = summary(out);
    if (s.is_object() && s.value("status", "") == "running") return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

// Exit code of pid, or -1 when it is still running (not reaped then).
int poll_code(pid_t pid) {
  int status = 0;
  if (waitpid(pid, &status, WNOHANG) != pid) return -1;
  remove_mpi_session_base(pid);
  return exit_code(status);
}

TEST(CliRunFolder, TwoRunsStartedTogetherIntoOneFolderOneIsRefused) {
  const fs::path out = fresh_dir("folder_two_runs");
  const fs::path log_a = out.string() + ".a.log", log_b = out.string() + ".b.log";
  const pid_t a = spawn(long_run(out), log_a);
  const pid_t b = spawn(long_run(out, {"material[0].density=9000"}), log_b);
  const ChildGuard guard{{a, b}};
  // The one refused ends at once; the other runs until it is stopped.
  int code_a = -1, code_b = -1;
  for (int i = 0; i < 1200 && code_a < 0 && code_b < 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    code_a = poll_code(a);
    if (code_a < 0) code_b = poll_code(b);
  }
  ASSERT_TRUE(code_a >= 0 || code_b >= 0) << "neither run was refused";
  const bool a_won = code_a < 0;
  const pid_t winner = a_won ? a : b;
  const int loser_code = a_won ? code_b : code_a;
  const std::string loser_log = slurp(a_won ? log_b : log_a);
  EXPECT_EQ(loser_code, 2) << loser_log;
  EXPECT_NE(loser_log.find("is in use by process " + std::to_string(winner)), std::string::npos)
      << loser_log;
  EXPECT_NE(loser_log.find(out.string()), std::string::npos) << loser_log;
  // render / report / export wait for the run too.
  ASSERT_TRUE(wait_running(out)) << slurp(a_won ? log_a : log_b);
  for (const std::string cmd : {"render", "report"}) {
    const auto r = run_cli({cmd, out.string()});
    EXPECT_EQ(r.code, 2) << cmd << ": " << r.output;
    EXPECT_NE(r.output.find("is in use by process"), std::string::npos) << r.output;
  }
  kill(winner, SIGTERM);
  EXPECT_EQ(wait_code_within(winner, 120), 1) << slurp(a_won ? log_a : log_b);
  // The winner's files are its own: its overrides, its status; the lock is gone with it.
  const auto s = summary(out);
  ASSERT_TRUE(s.is_object());
  EXPECT_EQ(s["status"], "interrupted");
  const bool has_density = s["overrides"].dump().find("density=9000") != std::string::npos;
  EXPECT_EQ(has_density, !a_won) << s["overrides"].dump();
  EXPECT_FALSE(fs::exists(out / ".ncfsim_lock"));
  // Free again: the next run into the folder is not refused.
  const auto next = run_cli({"-q", "run", kCantilever.string(), "-o", out.string(), "--set",
                             "time.max_cycles=20", "--set", "output.figures=false"});
  EXPECT_EQ(next.code, 1) << next.output;  // max_cycles
  EXPECT_EQ(summary(out)["status"], "max_cycles");
  fs::remove(log_a), fs::remove(log_b);
}

// summary.json "running", no live process: status finds it killed. A run that lost a rank may
// also have said so itself before it was ended (failed, with the MPI error): never "running".
void expect_found_killed(const fs::path& out, bool may_have_failed = false) {
  const std::string before = summary(out)["status"];
  if (may_have_failed && before == "failed") return;
  ASSERT_EQ(before, "running");
  const auto st = run_cli({"status", out.string()});
  EXPECT_EQ(st.code, 0) << st.output;
  EXPECT_NE(st.output.find("killed"), std::string::npos) << st.output;
  EXPECT_EQ(summary(out)["status"], "killed");
  EXPECT_NE(summary(out)["error"].get<std::string>().find("MPI rank"), std::string::npos);
  // Read again, it stays so.
  EXPECT_NE(run_cli({"status", out.string()}).output.find("killed"), std::string::npos);
}

TEST(CliRunFolder, KilledRunIsFoundKilledByStatusAndTheNextRun) {
  const fs::path out = fresh_dir("folder_killed");
  const fs::path log = out.string() + ".log";
  const pid_t pid = spawn(long_run(out), log);
  ChildGuard guard{{pid}};
  ASSERT_TRUE(wait_running(out)) << slurp(log);
  // While it runs, status says so and changes nothing.
  const auto live = run_cli({"status", out.string()});
  EXPECT_EQ(live.code, 0) << live.output;
  EXPECT_NE(live.output.find("running"), std::string::npos) << live.output;
  EXPECT_NE(live.output.find("process " + std::to_string(pid)), std::string::npos) << live.output;
  kill(pid, SIGKILL);
  EXPECT_EQ(wait_code(pid), 128 + SIGKILL);
  // Again, killed: the next run warns that the last one ended without a status.
  const pid_t again = spawn(long_run(out), log);
  guard.pids.push_back(again);
  ASSERT_TRUE(wait_running(out)) << slurp(log);
  kill(again, SIGKILL);
  wait_code(again);
  expect_found_killed(out);
  const auto next = run_cli({"run", kCantilever.string(), "-o", out.string(), "--set",
                             "time.max_cycles=20", "--set", "output.figures=false"});
  EXPECT_EQ(next.code, 1) << next.output;
  EXPECT_EQ(next.output.find("ended without a status"), std::string::npos)
      << "status had already set it right: " << next.output;
  // A summary left "running" by a killed run, not yet read by status: the next run says so.
  const pid_t third = spawn(long_run(out), log);
  guard.pids.push_back(third);
  ASSERT_TRUE(wait_running(out)) << slurp(log);
  kill(third, SIGKILL);
  wait_code(third);
  const auto after = run_cli({"run", kCantilever.string(), "-o", out.string(), "--set",
                              "time.max_cycles=20", "--set", "output.figures=false"});
  EXPECT_EQ(after.code, 1) << after.output;
  EXPECT_NE(after.output.find("ended without a status"), std::string::npos) << after.output;
  fs::remove(log);
}

// The ranks of a 2-rank run: processes whose command line names the output folder, less the
// launcher itself.
std::vector<pid_t> ranks_of(const fs::path& out, pid_t launcher) {
  return processes_naming(out, launcher);
}

TEST(CliRunFolder, RunThatLostAnMpiRankIsFoundKilledByStatus) {
  if (!launcher_works()) GTEST_SKIP() << "no MPI launcher that starts here";
  const fs::path out = fresh_dir("folder_lost_rank");
  const fs::path log = out.string() + ".log";
  // 320 hexahedra: enough to split over 2 ranks (a kernel chunk of 32 each at least).
  const pid_t pid =
      spawn(long_run(out, {"mesh.block[0].divisions=[80,2,2]"}), log, {kMpiexec, "-n", "2"});
  const ChildGuard guard{{pid}};
  ASSERT_TRUE(wait_running(out)) << slurp(log);
  std::vector<pid_t> ranks;
  for (int i = 0; i < 100 && ranks.size() < 2; ++i) {
    ranks = ranks_of(out, pid);
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(ranks.size(), 2u) << slurp(log);
  kill(std::max(ranks[0], ranks[1]), SIGKILL);  // one of the two ranks
  EXPECT_NE(wait_code_within(pid, 120), 0) << slurp(log);
  for (const pid_t r : ranks) kill(r, SIGKILL);  // whatever the launcher left
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  expect_found_killed(out, true);
  fs::remove(log);
}

// Open MPI's report of a rank lost to a signal (as mpiexec 4.1 prints it), and of ranks that
// only exited non-zero (not a lost rank: the ranks say why they stop).
TEST(CliRunFolder, LauncherReportOfALostRankIsRead) {
  const std::string lost =
      "-----\nmpiexec noticed that process rank 1 with PID 0 on node vm exited on signal 9 "
      "(Killed).\n-----\n";
  EXPECT_EQ(workflow::lost_rank_of(lost), "rank 1 (node vm): signal 9 (Killed)");
  const std::string exited =
      "mpiexec detected that one or more processes exited with non-zero status, thus causing\n"
      "the job to be terminated. The first process to do so was:\n\n  Process name: "
      "[[269,1],0]\n  Exit code:    3\n";
  EXPECT_EQ(workflow::lost_rank_of(exited), "");
}

// `ncfsim run --np 2` waits for its launcher: a rank lost (SIGKILL) ends the job without the
// run's status, and the process the user started writes it: failed, naming the rank and the
// signal (a raw mpiexec's run, above, is found killed by ncfsim status instead).
TEST(CliRunFolder, RunOnTwoRanksThatLostOneSaysFailedNamingTheRank) {
  if (!launcher_works()) GTEST_SKIP() << "no MPI launcher that starts here";
  const fs::path out = fresh_dir("folder_np_lost_rank");
  const fs::path log = out.string() + ".log";
  std::vector<std::string> args = long_run(out, {"mesh.block[0].divisions=[80,2,2]"});
  args.insert(args.end(), {"--np", "2"});
  const pid_t pid = spawn(args, log);
  ChildGuard guard{{pid}};
  ASSERT_TRUE(wait_running(out)) << slurp(log);
  // The ranks: the processes naming the folder that this one did not start (ncfsim, launcher)
  // and whose command is ncfsim's (not the launcher's).
  std::vector<pid_t> ranks;
  for (int i = 0; i < 100 && ranks.size() < 2; ++i) {
    ranks.clear();
    for (const pid_t p : processes_naming(out, pid)) {
      std::ifstream in("/proc/" + std::to_string(p) + "/cmdline", std::ios::binary);
      std::string first;
      std::getline(in, first, '\0');
      if (first == kExe.string()) ranks.push_back(p);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  ASSERT_EQ(ranks.size(), 2u) << slurp(log);
  guard.pids.insert(guard.pids.end(), ranks.begin(), ranks.end());
  kill(std::max(ranks[0], ranks[1]), SIGKILL);
  EXPECT_NE(wait_code_within(pid, 120), 0) << slurp(log);
  const auto s = summary(out);
  EXPECT_EQ(s["status"], "failed") << slurp(log);
  const std::string error = s.value("error", "");
  EXPECT_NE(error.find("MPI rank "), std::string::npos) << error;
  EXPECT_NE(error.find("signal 9"), std::string::npos) << error;
  EXPECT_NE(slurp(log).find("was lost"), std::string::npos) << slurp(log);
  // Open MPI's own banners about the job's end are not passed on.
  EXPECT_EQ(slurp(log).find("Primary job"), std::string::npos) << slurp(log);
  const auto st = run_cli({"status", out.string()});
  EXPECT_NE(st.output.find("failed"), std::string::npos) << st.output;
  EXPECT_NE(st.output.find("was lost"), std::string::npos) << st.output;
  fs::remove(log);
}

// A 2-rank run refused its folder: the root says why and ends, and the other rank, told so
// before the model's first collective, ends with it (it used to wait there for ever).
TEST(CliRunFolder, TwoRankRunIntoAFolderInUseIsRefusedAndEnds) {
  if (!launcher_works()) GTEST_SKIP() << "no MPI launcher that starts here";
  const fs::path out = fresh_dir("folder_refused_two_ranks");
  const fs::path log = out.string() + ".log", log_two = out.string() + ".two.log";
  const pid_t holder = spawn(long_run(out), log);
  ChildGuard guard{{holder}};
  ASSERT_TRUE(wait_running(out)) << slurp(log);
  const pid_t two =
      spawn(long_run(out, {"mesh.block[0].divisions=[80,2,2]"}), log_two, {kMpiexec, "-n", "2"});
  guard.pids.push_back(two);
  EXPECT_EQ(wait_code_within(two, 120), 2) << slurp(log_two);
  EXPECT_NE(slurp(log_two).find("is in use by process " + std::to_string(holder)),
            std::string::npos)
      << slurp(log_two);
  std::vector<pid_t> left = processes_naming(out, holder);
  EXPECT_TRUE(left.empty()) << left.size() << " processes of the refused run are still there";
  kill(holder, SIGTERM);
  EXPECT_EQ(wait_code_within(holder, 120), 1) << slurp(log);
  EXPECT_EQ(summary(out)["status"], "interrupted");
  fs::remove(log), fs::remove(log_two);
}

TEST(CliRunFolder, HistoryTheDiskRefusesEndsTheRunFailedNamingTheFile) {
  const fs::path out = fresh_dir("folder_disk_full");
  const fs::path log = out.string() + ".log";
  // A file-size limit stands in for a full disk: history.csv (a row per cycle) passes it within a
  // few hundred cycles; summary.json stays well under it.
  const pid_t pid = fork();
  if (pid == 0) {
    signal(SIGXFSZ, SIG_IGN);  // the write fails with EFBIG instead of killing the process
    // MPI's start-up keeps its shared-memory store in files that pass the limit: no daemon,
    // no store (as the fuzz test's checks).
    ::setenv("OMPI_MCA_ess_singleton_isolated", "1", 1);
    ::setenv("PMIX_MCA_gds", "hash", 1);
    use_own_mpi_session_base();
    rlimit lim{256 * 1024, 256 * 1024};
    setrlimit(RLIMIT_FSIZE, &lim);
    std::vector<std::string> args = {
        kExe.string(),          "run",   kCantilever.string(),         "-o",
        out.string(),           "--set", "time.history_interval=1e-9", "--set",
        "output.frames='none'", "--set", "output.figures=false",       "--set",
        "output.report=false",  "--set", "time.end_time=100.0"};
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1), dup2(fd, 2);
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  const int code = wait_code_within(pid, 300);
  const std::string text = slurp(log);
  EXPECT_EQ(code, 1) << text;
  EXPECT_NE(text.find("history.csv"), std::string::npos) << text;
  const auto s = summary(out);
  ASSERT_TRUE(s.is_object()) << text;
  EXPECT_EQ(s["status"], "failed") << s.dump(1);
  EXPECT_NE(s["error"].get<std::string>().find("history.csv"), std::string::npos) << s.dump(1);
  EXPECT_NE(s["error"].get<std::string>().find("large"), std::string::npos)
      << "the system's reason (EFBIG: File too large): " << s.dump(1);
  const auto st = run_cli({"status", out.string()});
  EXPECT_NE(st.output.find("failed"), std::string::npos) << st.output;
  fs::remove(log);
}

}  // namespace
}  // namespace ncfsim::test
