#include "workflow/run/mpi_launch.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <regex>
#include <set>
#include <stdexcept>
#include <string_view>
#include <thread>

extern char** environ;

namespace ncfsim::workflow {

namespace {
// The environment's names before main(), so before MPI's start-up.
std::set<std::string> names_of(char** env) {
  std::set<std::string> names;
  for (char** e = env; e && *e; ++e) {
    const std::string_view item(*e);
    names.emplace(item.substr(0, item.find('=')));
  }
  return names;
}
const std::set<std::string> g_startup_names = names_of(environ);

bool set_by_mpi(std::string_view name) {
  for (std::string_view prefix : {"OMPI_", "PMIX_", "OPAL_", "ORTE_", "PRTE_", "PMI_", "HYDRA_"})
    if (name.substr(0, prefix.size()) == prefix) return true;
  return false;
}
}  // namespace

std::vector<std::string> launcher_environment() {
  std::vector<std::string> env;
  for (char** e = environ; e && *e; ++e) {
    const std::string item(*e);
    const std::string name = item.substr(0, item.find('='));
    const bool ours = name == "OMPI_ALLOW_RUN_AS_ROOT" ||
                      name == "OMPI_ALLOW_RUN_AS_ROOT_CONFIRM" ||
                      name == "OMPI_MCA_rmaps_base_oversubscribe" ||
                      name == "OMPI_MCA_orte_execute_quiet";
    if (set_by_mpi(name) && !ours && !g_startup_names.count(name)) continue;
    env.push_back(item);
  }
  return env;
}

const char* mpi_launcher() { return NCFSIM_MPIEXEC; }

std::string self_executable(const std::string& fallback) {
  char exe[4096];
  const ssize_t len = readlink("/proc/self/exe", exe, sizeof exe - 1);
  return len > 0 ? std::string(exe, static_cast<std::size_t>(len)) : fallback;
}

std::vector<std::string> mpi_launch_command(int ranks) {
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 0);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 0);
  // Oversubscribed, Open MPI yields the core while it waits (slower messages): only then.
  // Open MPI's banners about a rank's non-zero exit (a run's stop: Ctrl-C, time.max_cycles,
  // exit 1 with valid results) are left out by run_launcher, which reads the one about a rank
  // lost to a signal (execute_quiet would silence that one too).
  if (static_cast<unsigned>(ranks) > std::thread::hardware_concurrency())
    ::setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 0);
  return {mpi_launcher(), "-n", std::to_string(ranks), self_executable()};
}

std::string lost_rank_of(const std::string& text) {
  static const std::regex signal_re(
      R"(process rank (\d+) with PID \d+ on node (\S+) exited on signal (\d+)(?: \(([^)]*)\))?)");
  std::smatch m;
  if (std::regex_search(text, m, signal_re))
    return "rank " + m[1].str() + " (node " + m[2].str() + "): signal " + m[3].str() +
           (m[4].matched ? " (" + m[4].str() + ")" : "");
  return {};
}

namespace {

// Open MPI's messages are blocks between lines of dashes. Those about ranks that exited
// non-zero or were lost are held back (the ranks say why they stop; run_launcher's caller says
// which rank was lost); any other block, and every other line, passes through.
class LauncherStderr {
 public:
  void feed(const char* data, std::size_t n) {
    partial_.append(data, n);
    std::size_t nl;
    while ((nl = partial_.find('\n')) != std::string::npos) {
      line(partial_.substr(0, nl + 1));
      partial_.erase(0, nl + 1);
    }
  }
  void finish() {
    if (!partial_.empty()) line(partial_ + "\n");
    partial_.clear();
    if (in_block_) emit(block_);  // an unterminated block: shown as it is
    in_block_ = false;
  }
  const std::string& held_back() const { return held_; }

 private:
  static bool dashes(const std::string& l) {
    const std::size_t n = l.find_last_not_of("\r\n") + 1;
    return n >= 20 && l.find_first_not_of('-') >= n;
  }
  static void emit(const std::string& text) {
    std::fwrite(text.data(), 1, text.size(), stderr);
    std::fflush(stderr);
  }
  void line(const std::string& l) {
    if (!dashes(l)) {
      if (in_block_)
        block_ += l;
      else
        emit(l);
      return;
    }
    if (!in_block_) {
      in_block_ = true, block_ = l;
      return;
    }
    block_ += l;
    in_block_ = false;
    const bool about_exits = block_.find("non-zero exit code") != std::string::npos ||
                             block_.find("exited with non-zero status") != std::string::npos ||
                             block_.find("exited on signal") != std::string::npos;
    if (about_exits)
      held_ += block_;
    else
      emit(block_);
  }
  std::string partial_, block_, held_;
  bool in_block_ = false;
};

}  // namespace

LauncherExit run_launcher(const std::vector<std::string>& args, const std::vector<std::string>& env,
                          int death_signal, const std::function<bool()>& interrupted) {
  std::vector<std::string> a = args, e = env;
  std::vector<char*> cargs, cenv;
  for (auto& x : a) cargs.push_back(x.data());
  cargs.push_back(nullptr);
  for (auto& x : e) cenv.push_back(x.data());
  cenv.push_back(nullptr);
  int pipe_fd[2];
  if (pipe(pipe_fd) != 0)
    throw std::runtime_error(std::string("cannot start the MPI launcher: ") + std::strerror(errno));
  std::fflush(nullptr);
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0)
    throw std::runtime_error(std::string("cannot start the MPI launcher: ") + std::strerror(errno));
  if (pid == 0) {
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, death_signal);
    if (getppid() != parent) _exit(1);  // the parent died before prctl
    for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE}) std::signal(sig, SIG_DFL);
    dup2(pipe_fd[1], STDERR_FILENO);
    close(pipe_fd[0]), close(pipe_fd[1]);
    execve(cargs[0], cargs.data(), cenv.data());
    std::fprintf(stderr, "ncfsim: cannot start the MPI launcher '%s': %s\n", cargs[0],
                 std::strerror(errno));
    _exit(2);
  }
  setpgid(pid, pid);  // also here: no window where a signal to -pid misses it
  close(pipe_fd[1]);
  fcntl(pipe_fd[0], F_SETFL, fcntl(pipe_fd[0], F_GETFL) | O_NONBLOCK);
  LauncherStderr err;
  bool passed_on = false, open = true;
  int status = 0;
  char buf[4096];
  const auto drain = [&] {
    ssize_t n = -1;
    while (open && (n = read(pipe_fd[0], buf, sizeof buf)) != 0) {
      if (n < 0) {
        if (errno == EINTR) continue;
        break;  // EAGAIN: nothing more now
      }
      err.feed(buf, static_cast<std::size_t>(n));
    }
    if (open && n == 0) open = false;
  };
  while (true) {
    pollfd p{pipe_fd[0], POLLIN, 0};
    if (open)
      poll(&p, 1, 50);
    else
      usleep(50'000);
    drain();
    const pid_t r = waitpid(pid, &status, WNOHANG);
    if (r == pid) break;
    if (r < 0 && errno != EINTR) {
      status = -1;
      break;
    }
    if (!passed_on && interrupted && interrupted()) {
      kill(-pid, SIGINT);
      passed_on = true;
    }
  }
  // The ranks may still hold the pipe a moment after their launcher ended: what is there now.
  drain();
  close(pipe_fd[0]);
  err.finish();
  LauncherExit out;
  out.exit_code = status < 0 ? 1 : WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  out.lost_rank = lost_rank_of(err.held_back());
  return out;
}

}  // namespace ncfsim::workflow
