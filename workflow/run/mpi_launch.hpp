#pragma once
// Starting ncfsim on N MPI ranks with the launcher CMake found (docs/parallel.md): `ncfsim run
// --np N` relaunches itself through it, and a workflow starts its engine stages through it.
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

}  // namespace ncfsim::workflow
