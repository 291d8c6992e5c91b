#include "workflow/run/mpi_launch.hpp"

#include <unistd.h>

#include <cstdlib>
#include <set>
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
  // A run's stop (Ctrl-C, time.max_cycles: exit 1, results valid) is not a job failure: without
  // this Open MPI adds its "job has been aborted" banner to ncfsim's own message.
  ::setenv("OMPI_MCA_orte_execute_quiet", "1", 0);
  if (static_cast<unsigned>(ranks) > std::thread::hardware_concurrency())
    ::setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 0);
  return {mpi_launcher(), "-n", std::to_string(ranks), self_executable()};
}

}  // namespace ncfsim::workflow
