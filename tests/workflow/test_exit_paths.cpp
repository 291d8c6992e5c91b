// Every way a run ends, against docs/cli.md's table of exit codes and statuses:
//  * stopped by time.max_cycles: exit 1, status max_cycles (results valid, end not reached);
//  * SIGTERM, SIGHUP, SIGQUIT mid-run end like Ctrl-C: exit 1, status interrupted, summary.json
//    and results readable; so does a signal the moment the handler is in place, before the case
//    is read (before, a signal in the first 0.4 s left no output folder);
//  * two signals within a second (a batch system or pkill signalling every process of a job, and
//    the launcher of --np passing it on) are one request: the run still writes its summary;
//  * a closed stdout (ncfsim run ... | head -1) does not kill the run: it completes, exit 0, and
//    log.txt keeps every line.
#include <gtest/gtest.h>

#include <chrono>
#include <nlohmann/json.hpp>
#include <thread>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

const fs::path kCube = kSource / "tests/cases/erosion/crushed_cube.toml";
const fs::path kCantilever = kSource / "cases/verification/cantilever.toml";

nlohmann::json summary(const fs::path& out) {
  return nlohmann::json::parse(slurp(out / "summary.json"));
}

std::vector<std::string> long_run(const fs::path& out) {
  return {"run",   kCantilever.string(),  "-o",    out.string(),
          "--set", "time.end_time=100.0", "--set", "output.figures=false",
          "--set", "output.report=false"};
}

// Whether the run writing into out reports itself running within 30 s.
bool reaches_running(const fs::path& out) {
  for (int i = 0; i < 600; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    try {
      if (fs::exists(out / "summary.json") && summary(out)["status"] == "running") return true;
    } catch (const std::exception&) {
    }
  }
  return false;
}

TEST(CliExitPaths, CycleLimitExitsOne) {
  const fs::path out = fresh_dir("exit_max_cycles");
  const auto r =
      run_cli({"-q", "run", kCube.string(), "-o", out.string(), "--set", "time.max_cycles=10"});
  EXPECT_EQ(r.code, 1) << r.output;
  EXPECT_EQ(summary(out)["status"], "max_cycles");
}

TEST(CliExitPaths, TerminationSignalsEndLikeCtrlC) {
  for (int sig : {SIGTERM, SIGHUP, SIGQUIT}) {
    const fs::path out = fresh_dir("exit_signal_" + std::to_string(sig));
    const fs::path log = out.string() + ".log";
    const pid_t pid = spawn(long_run(out), log);
    ASSERT_TRUE(reaches_running(out)) << slurp(log);
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
    kill(pid, sig);
    EXPECT_EQ(wait_code(pid), 1) << "signal " << sig << ": " << slurp(log);
    EXPECT_EQ(summary(out)["status"], "interrupted") << "signal " << sig;
  }
}

// A job's processes signalled all at once (scancel, pkill, and --np's launcher passing one on):
// a rank may get the request twice within moments. Before, the second aborted the run (exit 130)
// with its checkpoint written and summary.json left "running".
TEST(CliExitPaths, TwoSignalsWithinASecondAreOneRequest) {
  const fs::path out = fresh_dir("exit_two_signals");
  const fs::path log = out.string() + ".log";
  const pid_t pid = spawn(long_run(out), log);
  ASSERT_TRUE(reaches_running(out)) << slurp(log);
  kill(pid, SIGTERM);
  kill(pid, SIGINT);
  EXPECT_EQ(wait_code(pid), 1) << slurp(log);
  EXPECT_EQ(summary(out)["status"], "interrupted");
}

// Whether process pid catches signal sig yet (/proc/<pid>/status, SigCgt).
bool catches(pid_t pid, int sig) {
  std::ifstream in("/proc/" + std::to_string(pid) + "/status");
  std::string line;
  while (std::getline(in, line))
    if (line.rfind("SigCgt:", 0) == 0) {
      const unsigned long long mask = std::stoull(line.substr(7), nullptr, 16);
      return (mask >> (sig - 1)) & 1u;
    }
  return false;
}

TEST(CliExitPaths, SignalRightAfterTheStartLeavesAnInterruptedRun) {
  const fs::path out = fresh_dir("exit_early_signal");
  const fs::path log = out.string() + ".log";
  const pid_t pid = spawn(long_run(out), log);
  // The signal as soon as the handler is in place: before the case is read, before any output.
  bool ready = false;
  for (int i = 0; i < 20000 && !ready; ++i) {
    ready = catches(pid, SIGTERM);
    if (!ready) std::this_thread::sleep_for(std::chrono::microseconds(500));
  }
  ASSERT_TRUE(ready) << slurp(log);
  kill(pid, SIGTERM);
  EXPECT_EQ(wait_code(pid), 1) << slurp(log);
  ASSERT_TRUE(fs::exists(out / "summary.json")) << slurp(log);
  EXPECT_EQ(summary(out)["status"], "interrupted");
}

// Ctrl-C after the last cycle, while the figures are drawn (the log's energy-balance line comes
// just before them; drawing takes a good fraction of a second): the results are complete, but
// the run must not end "completed" with exit 0 as if nothing had happened.
TEST(CliExitPaths, InterruptWhileFiguresAreDrawnEndsInterrupted) {
  const fs::path out = fresh_dir("exit_sigint_figures");
  const fs::path log = out.string() + ".log";
  const pid_t pid = spawn({"run", kCube.string(), "-o", out.string()}, log);
  bool drawing = false;
  for (int i = 0; i < 30000 && !drawing; ++i) {
    drawing = slurp(out / "log.txt").find("energy balance at t") != std::string::npos;
    if (!drawing) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  ASSERT_TRUE(drawing) << slurp(log);
  kill(pid, SIGINT);
  EXPECT_EQ(wait_code(pid), 1) << slurp(log);
  const auto s = summary(out);
  EXPECT_EQ(s["status"], "interrupted");
  EXPECT_EQ(s["figures_complete"], false);
  EXPECT_GT(s["time_reached_s"].get<double>(), 0.0149) << "the run itself had completed";
}

TEST(CliExitPaths, ClosedStdoutDoesNotKillTheRun) {
  const fs::path out = fresh_dir("exit_closed_pipe");
  int fds[2];
  ASSERT_EQ(pipe(fds), 0);
  const pid_t pid = fork();
  if (pid == 0) {
    close(fds[0]);
    dup2(fds[1], 1);
    dup2(fds[1], 2);
    ::unsetenv("DISPLAY");
    use_own_mpi_session_base();
    std::vector<std::string> args = {
        kExe.string(), "run", kCube.string(), "-o", out.string(), "--progress-interval", "0.001"};
    std::vector<char*> argv;
    for (auto& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(argv[0], argv.data());
    _exit(127);
  }
  close(fds[1]);
  close(fds[0]);  // nobody reads: the run's first write to stdout meets a closed pipe
  EXPECT_EQ(wait_code(pid), 0);
  EXPECT_EQ(summary(out)["status"], "completed");
  EXPECT_NE(slurp(out / "log.txt").find("results in"), std::string::npos)
      << "log.txt keeps the lines the console lost";
}

}  // namespace
}  // namespace ncfsim::test

namespace ncfsim::test {
namespace {

// A model too large for the machine is bad input naming the key that sizes it, before anything
// is allocated (it was std::bad_alloc, exit 1, or the kernel's OOM killer).
TEST(CliExitPaths, ModelTooLargeForTheMachineIsBadInput) {
  const fs::path out = fresh_dir("exit_too_large");
  struct Big {
    std::string file, set, key;
  };
  for (const Big& b :
       std::vector<Big>{{"tests/cases/erosion/crushed_cube.toml",
                         "mesh.block[0].divisions=[1000,1000,1000]", "mesh.block[0].divisions"},
                        {"cases/drape/bias_extension_positive.toml",
                         "mesh.fabric[0].element_length=1e-9", "mesh.fabric[0].element_length"},
                        {"cases/drape/bias_extension_positive.toml",
                         "mesh.fabric[0].size=[1e5,1e5]", "mesh.fabric[0].size"}}) {
    const auto t0 = std::chrono::steady_clock::now();
    const auto r =
        run_cli({"run", (kSource / b.file).string(), "-o", out.string(), "--set", b.set});
    EXPECT_EQ(r.code, 2) << b.set << ": " << r.output;
    EXPECT_NE(r.output.find(b.key), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("too large for this machine"), std::string::npos) << r.output;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 10.0);
    EXPECT_FALSE(fs::exists(out)) << "refused before the output folder is made";
  }
}

}  // namespace
}  // namespace ncfsim::test
