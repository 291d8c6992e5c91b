#pragma once
// The solver's view of a boundary condition that drives nodes by a prescribed motion (a test
// rig's clamps and arms): it prescribes all three velocity components of its nodes and may push
// other nodes with walls. The solver calls each object a few times per cycle, never per node.
#include <cstddef>
#include <cstdint>
#include <vector>

namespace ncfsim::fem {

class BoundaryMotion {
 public:
  virtual ~BoundaryMotion() = default;
  /// Checks the definition against a mesh of n_nodes nodes; throws InputError.
  virtual void check(std::size_t n_nodes) const = 0;
  /// Nodes whose velocity it prescribes (all three components; a later object wins a shared node).
  virtual const std::vector<std::int32_t>& driven_nodes(std::size_t i) const = 0;
  virtual std::size_t n_driven_sets() const = 0;
  /// Set-up: DOF d (3 node + component) of set `set`, at reference positions x0, is the solver's
  /// constrained DOF k; velocities() fills v[k] for it.
  virtual void bind_dof(std::size_t set, std::size_t k, std::size_t d, const double* x0) = 0;
  /// Prescribed velocities of the bound DOFs at time t into v (indexed by constrained DOF).
  virtual void velocities(double t, double* v) = 0;

  /// Whether it adds nodal forces (walls); they go with the contact forces.
  virtual bool has_forces() const { return false; }
  /// Forces at positions x and time t (penalty from nodal masses and step dt) added into f.
  virtual void add_forces(double t, const double* x, const double* mass, double dt, double* f) {
    (void)t, (void)x, (void)mass, (void)dt, (void)f;
  }
  /// Work of those forces over the increments around t^n: dt_old at t_old = t^{n-1/2}, dt_new at
  /// t_new = t^{n+1/2}, added into the driving (external) work and the work on the nodes.
  virtual void add_force_work(double t_old, double t_new, double dt_old, double dt_new,
                              double& source_old, double& source_new, double& on_nodes_old,
                              double& on_nodes_new) {
    (void)t_old, (void)t_new, (void)dt_old, (void)dt_new, (void)source_old, (void)source_new,
        (void)on_nodes_old, (void)on_nodes_new;
  }
};

}  // namespace ncfsim::fem
