#include "fem/petsc_vector.hpp"

#include <cstdlib>
#include <exception>

namespace ncfsim::fem {

PetscSession::PetscSession(int* argc, char*** argv) {
  PetscBool init = PETSC_FALSE;
  NCF_PETSC(PetscInitialized(&init));
  if (!init) {
    // PETSc must not install its own signal handler: the run loop handles SIGINT itself.
    NCF_PETSC(PetscOptionsSetValue(nullptr, "-no_signal_handler", nullptr));
    NCF_PETSC(PetscInitialize(argc, argv, nullptr, nullptr));
    owns_ = true;
  }
}

PetscSession::~PetscSession() {
  if (!owns_) return;
  // Left by an exception on several ranks (bad input every rank finds, e.g. a model that cannot
  // be split): the root reports it only after this scope, and MPI_Finalize lets the other ranks
  // exit, upon which the launcher ends the job, the root with it, often before its message was
  // out. Finalizing at process exit keeps every rank until the root has printed.
  if (std::uncaught_exceptions() > 0 && size() > 1) {
    std::atexit([] { PetscFinalize(); });
    return;
  }
  PetscFinalize();
}

bool PetscSession::active() {
  PetscBool init = PETSC_FALSE;
  PetscInitialized(&init);
  return init == PETSC_TRUE;
}

int PetscSession::rank() {
  int r = 0;
  MPI_Comm_rank(PETSC_COMM_WORLD, &r);
  return r;
}

int PetscSession::size() {
  int s = 1;
  MPI_Comm_size(PETSC_COMM_WORLD, &s);
  return s;
}

NodalVector::NodalVector(std::size_t n_owned_nodes, std::span<const PetscInt> ghost_nodes)
    : n_local_(n_owned_nodes + ghost_nodes.size()) {
  NCF_PETSC(VecCreateGhostBlock(PETSC_COMM_WORLD, 3, static_cast<PetscInt>(3 * n_owned_nodes),
                                PETSC_DECIDE, static_cast<PetscInt>(ghost_nodes.size()),
                                ghost_nodes.data(), &vec_));
  NCF_PETSC(VecSet(vec_, 0.0));
}

NodalVector::~NodalVector() {
  if (vec_) VecDestroy(&vec_);
}

NodalVector& NodalVector::operator=(NodalVector&& o) noexcept {
  if (this != &o) {
    if (vec_) VecDestroy(&vec_);
    vec_ = o.vec_;
    n_local_ = o.n_local_;
    o.vec_ = nullptr;
  }
  return *this;
}

void NodalVector::set(double value) { NCF_PETSC(VecSet(vec_, value)); }

NodalVector::View::View(Vec v, std::size_t n) : global_(v), n_(n) {
  NCF_PETSC(VecGhostGetLocalForm(global_, &local_));
  NCF_PETSC(VecGetArray(local_, &data_));
}

NodalVector::View::~View() {
  VecRestoreArray(local_, &data_);
  VecGhostRestoreLocalForm(global_, &local_);
}

}  // namespace ncfsim::fem
