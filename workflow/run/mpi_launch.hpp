#pragma once
// Starting ncfsim on N MPI ranks with the launcher CMake found (docs/parallel.md): `ncfsim run
// --np N` relaunches itself through it, and a workflow starts its engine stages through it.
#include <functional>
#include <string>
#include <vector>

namespace ncfsim::workflow {

/// This executable's path (/proc/self/exe; `fallback` where it cannot be read).
std::string self_executable(const std::string& fallback = "ncfsim");

/// {launcher, "-n", N, this executable}: the command's head for N ranks of ncfsim. Sets in this
/// process's environment (unless already set) Open MPI's switches to run as root and, for more
/// ranks than cores, to oversubscribe: the user asked for N.
std::vector<std::string> mpi_launch_command(int ranks);

/// The environment for a launcher started by this process, as `NAME=value` items: this process's,
/// less what MPI's own start-up here added (Open MPI's singleton puts its OMPI_/PMIX_ variables
/// in the environment, and a launcher that inherits them exits at once). Variables the user had
/// at start-up are kept.
std::vector<std::string> launcher_environment();

/// The launcher's path (empty when CMake found none).
const char* mpi_launcher();

/// How a launcher run by run_launcher ended.
struct LauncherExit {
  int exit_code = 0;      // the launcher's exit code (128 + the signal where it was killed)
  std::string lost_rank;  // the rank it reported lost: "rank 1 (node vm): signal 9 (Killed)"
};

/// Runs a launcher command (mpi_launch_command's head and ncfsim's arguments) with the
/// environment `env` as a child in a process group of its own, which gets `death_signal` if this
/// process dies. While it runs, the first time `interrupted()` is true one SIGINT goes to the
/// child's group (as a terminal's Ctrl-C would: every rank checkpoints at one cycle). Its stderr
/// passes through this process, less Open MPI's banners about ranks that exited non-zero (the
/// ranks say why they stop) and with the rank it lost, if any, in LauncherExit::lost_rank.
LauncherExit run_launcher(const std::vector<std::string>& args, const std::vector<std::string>& env,
                          int death_signal, const std::function<bool()>& interrupted);

/// Reads Open MPI's report of a rank that ended abnormally out of the launcher's stderr text:
/// "rank N (node H): signal S (NAME)" or "rank N: exit code C"; empty when there is none.
std::string lost_rank_of(const std::string& launcher_stderr);

}  // namespace ncfsim::workflow
