#pragma once
// Helpers of the end-to-end tests that run the ncfsim executable (NCFSIM_EXE, from the sources in
// NCFSIM_SOURCE_DIR): spawn it with DISPLAY unset and its output in a log, read files back, read
// history.csv by column name, read a case's reference table (cases/<family>/reference/*.csv).
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

namespace ncfsim::test {

namespace fs = std::filesystem;

inline const fs::path kExe = NCFSIM_EXE;
inline const fs::path kSource = NCFSIM_SOURCE_DIR;

/// Built with AddressSanitizer (the asan preset, as ncfsim then is): its resident sets are the
/// sanitizer's shadow memory and quarantine, not the release build's, so memory checks skip.
#if defined(__SANITIZE_ADDRESS__)
inline constexpr bool kSanitizedBuild = true;
#else
inline constexpr bool kSanitizedBuild = false;
#endif

struct Result {
  int code = -1;
  std::string output;  // stdout + stderr
};

inline std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Open MPI keeps each job's session files under TMPDIR/ompi.HOST.UID, and processes started
/// without a launcher at the same moment can share a name there (isolated singletons are all
/// "jf.0/1"): one's clean-up then removes the directory the other is making, and that one fails
/// or stalls in MPI_Init. Each child of a test gets a base of its own, removed when reaped.
inline fs::path mpi_session_base(pid_t pid) {
  return fs::temp_directory_path() / ("ncfsim_test_ompi_" + std::to_string(pid));
}

/// In a forked child, before exec: its own session base.
inline void use_own_mpi_session_base() {
  const std::string dir = mpi_session_base(getpid()).string();
  ::mkdir(dir.c_str(), 0700);
  ::setenv("OMPI_MCA_orte_tmpdir_base", dir.c_str(), 1);
}

/// After the child `pid` was reaped.
inline void remove_mpi_session_base(pid_t pid) {
  std::error_code ec;
  fs::remove_all(mpi_session_base(pid), ec);
}

/// Starts ncfsim with args, stdout and stderr into `log`; returns the child's pid. With a
/// launcher (e.g. {mpiexec, -n, 2}) the child is the launcher, given ncfsim and args.
/// With `own_process_group` the child leads a process group of its own (its pid), so that a
/// signal to -pid reaches it and the MPI ranks its launcher starts, as Ctrl-C in a terminal does.
inline pid_t spawn(const std::vector<std::string>& args, const fs::path& log,
                   const std::vector<std::string>& launcher = {}, bool own_process_group = false) {
  const pid_t pid = fork();
  if (pid == 0) {
    if (own_process_group) setpgid(0, 0);
    const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, 1);
    dup2(fd, 2);
    ::unsetenv("DISPLAY");
    use_own_mpi_session_base();
    std::vector<std::string> all = launcher;
    all.push_back(kExe.string());
    all.insert(all.end(), args.begin(), args.end());
    std::vector<char*> argv;
    for (auto& a : all) argv.push_back(a.data());
    argv.push_back(nullptr);
    execv(all.front().c_str(), argv.data());
    _exit(127);
  }
  return pid;
}

/// Exit code from a waitpid status (128 + signal when the child was killed).
inline int exit_code(int status) {
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

/// Exit code of the child (128 + signal when it was killed).
inline int wait_code(pid_t pid) {
  int status = 0;
  waitpid(pid, &status, 0);
  remove_mpi_session_base(pid);
  return exit_code(status);
}

/// Exit code of the child, or -1 when it was still running after `seconds` (it is then sent
/// SIGTERM, SIGKILL 30 s later if it is still there, and reaped).
inline int wait_code_within(pid_t pid, double seconds) {
  auto reaped = [pid](double limit, int* code) {
    for (double waited = 0; waited < limit; waited += 0.05) {
      int status = 0;
      if (waitpid(pid, &status, WNOHANG) == pid) {
        remove_mpi_session_base(pid);
        *code = exit_code(status);
        return true;
      }
      usleep(50000);
    }
    return false;
  };
  int code = 0;
  if (reaped(seconds, &code)) return code;
  kill(pid, SIGTERM);
  if (!reaped(30.0, &code)) {
    kill(pid, SIGKILL);
    wait_code(pid);
  }
  return -1;
}

/// Kills (SIGKILL) and reaps, as the test ends however it ends, the children it names that are
/// still running: a failed assertion never leaves a long run behind on the machine.
struct ChildGuard {
  std::vector<pid_t> pids;
  ~ChildGuard() {
    for (const pid_t p : pids) {
      int status = 0;
      if (waitpid(p, &status, WNOHANG) == 0) {  // ours and still running
        kill(p, SIGKILL);
        waitpid(p, &status, 0);
      }
      remove_mpi_session_base(p);
    }
  }
};

/// Processes whose command line names ncfsim and `out` (a run's ranks and its launcher), less
/// `except`.
inline std::vector<pid_t> processes_naming(const fs::path& out, pid_t except = -1) {
  std::vector<pid_t> pids;
  for (const auto& e : fs::directory_iterator("/proc")) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const pid_t p = static_cast<pid_t>(std::stol(name));
    if (p == except) continue;
    std::ifstream in(e.path() / "cmdline", std::ios::binary);
    std::string cmd((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    for (char& c : cmd)
      if (c == '\0') c = ' ';
    if (cmd.find(kExe.string()) != std::string::npos && cmd.find(out.string()) != std::string::npos)
      pids.push_back(p);
  }
  return pids;
}

/// Waits (up to `seconds`) until no process names `out`: the ranks of a job whose launcher was
/// killed outlive it for a moment, holding the folder. True when they are gone.
inline bool wait_gone(const fs::path& out, double seconds = 60) {
  for (double t = 0; t < seconds; t += 0.05) {
    if (processes_naming(out).empty()) return true;
    usleep(50000);
  }
  return false;
}

/// Runs ncfsim with args to the end (through `launcher` when one is given).
inline Result run_cli(const std::vector<std::string>& args,
                      const std::vector<std::string>& launcher = {}) {
  const fs::path log = fs::temp_directory_path() / ("ncfsim_cli_" + std::to_string(getpid()) + ".log");
  Result r;
  r.code = wait_code(spawn(args, log, launcher));
  r.output = slurp(log);
  fs::remove(log);
  return r;
}

/// An output folder in the temporary directory that does not exist yet.
inline fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("ncfsim_test_" + name + "_" + std::to_string(getpid()));
  fs::remove_all(d);
  return d;
}

/// history.csv: column names and rows of numbers.
struct History {
  std::vector<std::string> columns;
  std::vector<std::vector<double>> rows;
  /// Index of a column; columns.size() when there is none.
  std::size_t column(const std::string& name) const {
    return static_cast<std::size_t>(std::find(columns.begin(), columns.end(), name) - columns.begin());
  }
};

inline History read_history(const fs::path& file) {
  History h;
  std::ifstream in(file);
  std::string line;
  if (!std::getline(in, line)) return h;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) h.columns.push_back(c);
  }
  while (std::getline(in, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) v.push_back(std::stod(c));
    h.rows.push_back(std::move(v));
  }
  return h;
}

/// A reference table beside a case (cases/<family>/reference/<name>.csv): '#' lines (source,
/// tolerance, what each column means), a header row, then rows whose first cell names the row (a
/// quantity, or the x of a curve). An empty cell is NaN (no bound, no check).
struct Reference {
  fs::path file;
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  std::size_t column(const std::string& name) const {
    const auto it = std::find(columns.begin(), columns.end(), name);
    if (it == columns.end()) throw std::out_of_range(file.string() + ": no column '" + name + "'");
    return static_cast<std::size_t>(it - columns.begin());
  }
  /// Cell of row r (0-based) in `col` as a number; NaN when empty.
  double number(std::size_t r, const std::string& col) const {
    const std::string& cell = rows.at(r).at(column(col));
    return cell.empty() ? std::numeric_limits<double>::quiet_NaN() : std::stod(cell);
  }
  /// Cell `col` of the row whose first cell is `name`.
  double at(const std::string& name, const std::string& col) const {
    for (std::size_t r = 0; r < rows.size(); ++r)
      if (!rows[r].empty() && rows[r][0] == name) return number(r, col);
    throw std::out_of_range(file.string() + ": no row '" + name + "'");
  }
};

inline Reference read_reference(const fs::path& file) {
  Reference t;
  t.file = file;
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  auto split = [](const std::string& line) {
    std::vector<std::string> cells;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) cells.push_back(c);
    if (!line.empty() && line.back() == ',') cells.emplace_back();
    return cells;
  };
  for (std::string line; std::getline(in, line);) {
    if (line.empty() || line[0] == '#') continue;
    if (t.columns.empty()) {
      t.columns = split(line);
      continue;
    }
    auto cells = split(line);
    cells.resize(t.columns.size());
    t.rows.push_back(std::move(cells));
  }
  return t;
}

/// cases/<family>/reference/<name>.csv of the sources.
inline Reference case_reference(const std::string& family, const std::string& name) {
  return read_reference(kSource / "cases" / family / "reference" / (name + ".csv"));
}

/// lower < value < upper for the bounds a reference row gives (NaN: no bound).
inline bool within(double value, double lower, double upper) {
  return (std::isnan(lower) || value > lower) && (std::isnan(upper) || value < upper);
}

}  // namespace ncfsim::test
