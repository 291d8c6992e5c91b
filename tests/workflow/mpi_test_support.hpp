#pragma once
// Helpers of the tests that run ncfsim on several MPI ranks (test_mpi_runs.cpp,
// test_mpi_cases.cpp): the launcher CMake found (NCFSIM_MPIEXEC) and whether it starts here.
#include <cstdlib>
#include <filesystem>
#include <string>

#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {

inline const std::string kMpiexec = NCFSIM_MPIEXEC;

/// Open MPI refuses root and more ranks than cores unless told (ncfsim run --np sets these
/// itself; a test that calls the launcher directly must too).
inline void allow_launcher() {
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT", "1", 1);
  ::setenv("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1", 1);
  ::setenv("OMPI_MCA_rmaps_base_oversubscribe", "1", 1);
}

/// Whether `mpiexec -n 2 ncfsim --version` runs here (the tests skip, saying so, when not).
inline bool launcher_works() {
  if (kMpiexec.empty() || !std::filesystem::exists(kMpiexec)) return false;
  allow_launcher();
  return run_cli({"--version"}, {kMpiexec, "-n", "2"}).code == 0;
}

}  // namespace ncfsim::test
