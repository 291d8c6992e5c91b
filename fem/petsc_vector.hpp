#pragma once
// RAII wrappers over PETSc objects used by the engine: the library session and nodal vectors.
// Nodal vectors have block size 3 and are created ghosted (owned entries first, then ghosts) so
// that an MPI decomposition only adds the ghost exchange; in serial the ghost list is empty.
#include <cstddef>
#include <span>
#include <vector>

#include <petscvec.h>

#include "fem/errors.hpp"

namespace ncfsim::fem {

/// PetscInitialize/PetscFinalize for the life of the object (one per process).
class PetscSession {
 public:
  PetscSession(int* argc = nullptr, char*** argv = nullptr);
  ~PetscSession();
  PetscSession(const PetscSession&) = delete;
  PetscSession& operator=(const PetscSession&) = delete;
  static bool active();
  static int rank();
  static int size();

 private:
  bool owns_ = false;
};

/// A nodal field of 3 components per node held in a PETSc Vec.
class NodalVector {
 public:
  NodalVector() = default;
  NodalVector(std::size_t n_owned_nodes, std::span<const PetscInt> ghost_nodes = {});
  ~NodalVector();
  NodalVector(NodalVector&& o) noexcept : vec_(o.vec_), n_local_(o.n_local_) { o.vec_ = nullptr; }
  NodalVector& operator=(NodalVector&& o) noexcept;
  NodalVector(const NodalVector&) = delete;
  NodalVector& operator=(const NodalVector&) = delete;

  Vec vec() const { return vec_; }
  std::size_t n_local_nodes() const { return n_local_; }
  void set(double value);

  /// Local array (owned + ghost entries), [3*n_local_nodes], valid until the view dies.
  class View {
   public:
    View(Vec v, std::size_t n);
    ~View();
    View(const View&) = delete;
    View& operator=(const View&) = delete;
    double* data() { return data_; }
    double& operator[](std::size_t i) { return data_[i]; }
    std::size_t size() const { return n_; }

   private:
    Vec global_ = nullptr, local_ = nullptr;
    double* data_ = nullptr;
    std::size_t n_ = 0;
  };
  View view() const { return View(vec_, 3 * n_local_); }

 private:
  Vec vec_ = nullptr;
  std::size_t n_local_ = 0;
};

}  // namespace ncfsim::fem
