// GoogleTest main for suites that use the engine: one PETSc session for the whole process.
#include <gtest/gtest.h>

#include "fem/petsc_vector.hpp"

int main(int argc, char** argv) {
  ::testing::InitGoogleTest(&argc, argv);
  ncfsim::fem::PetscSession petsc(&argc, &argv);
  return RUN_ALL_TESTS();
}
