// GoogleTest main for suites that use the engine: one PETSc session for the whole process.
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <system_error>

#include "fem/petsc_vector.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  // Open MPI's session files under a base of this process's own: CTest starts test processes
  // side by side, and singletons started together can remove each other's session directory
  // (tests/workflow/cli_test_support.hpp, mpi_session_base).
  namespace fs = std::filesystem;
  const fs::path base =
      fs::temp_directory_path() / ("ncfsim_test_ompi_" + std::to_string(getpid()));
  ::mkdir(base.c_str(), 0700);
  ::setenv("OMPI_MCA_orte_tmpdir_base", base.c_str(), 1);
  int code = 0;
  {
    ncfsim::fem::PetscSession petsc(&argc, &argv);
    code = RUN_ALL_TESTS();
  }
  std::error_code ec;
  fs::remove_all(base, ec);
  return code;
}
