#pragma once
// Central-difference explicit time integration with a variable stable step, on nodal state held
// in PETSc vectors. The model is checked and all element groups built before the first cycle;
// the cycle itself only computes.
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fem/bar_block.hpp"
#include "fem/energy.hpp"
#include "fem/hex8_block.hpp"
#include "fem/model.hpp"
#include "fem/petsc_vector.hpp"

namespace ncfsim::fem {

struct PartMassReport {
  std::string part;
  double mass = 0;        // physical mass, kg
  double added_mass = 0;  // mass added by mass scaling, kg
};

/// One hexahedron removed by erosion.
struct ErosionEvent {
  enum class Cause { StableStep, InvertedCorner };
  Cause cause = Cause::StableStep;
  double time = 0;
  std::int64_t cycle = 0;
  std::int64_t element = 0;  // user id
  int part = 0;
  double step = 0;  // its stable step when eroded (times the safety factor), s
  V3 centroid;      // m
};

struct PhaseTimers {
  double internal_force = 0, contact = 0, update = 0, output = 0;  // seconds
};

class ExplicitSolver {
 public:
  /// Builds element groups, masses and the initial state. Throws InputError / NumericalError.
  explicit ExplicitSolver(Model& model);

  /// One cycle. `at_tn` (may be empty) is called once state at t^n is complete (forces,
  /// energies, v^{n+1/2}), before the positions move on to t^{n+1}.
  void step(const std::function<void()>& at_tn = {});

  double time() const { return t_; }
  double time_step() const { return dt_; }
  std::int64_t cycle() const { return cycle_; }
  const EnergyBalance& energy() const { return energy_; }
  const StableStep& controlling_element() const { return step_; }
  const std::vector<PartMassReport>& part_masses() const { return part_mass_; }
  /// Hexahedra eroded so far (time.erosion_step_ratio), in order.
  const std::vector<ErosionEvent>& erosions() const { return erosions_; }
  const PhaseTimers& timers() const { return timers_; }
  std::size_t n_hexes() const;
  std::size_t n_bars() const;

  Model& model() { return model_; }
  const Model& model() const { return model_; }
  std::vector<Hex8Block>& hex_blocks() { return hex_; }
  std::vector<BarBlock>& bar_blocks() { return bar_; }
  const std::vector<Hex8Block>& hex_blocks() const { return hex_; }
  const std::vector<BarBlock>& bar_blocks() const { return bar_; }

  // Nodal state, [3*n_nodes] each.
  NodalVector x0, x, v, mass, f_int, f_ext, f_contact, f_damp, reaction;

  /// Sum over the nodes of a DOF-wise reaction of a named constraint (fixed or velocity set).
  V3 reaction_force(const std::vector<std::int32_t>& nodes) const;
  /// Power (W) the walls of picture frame k (its arms, PictureFrame::walls) put into the nodes
  /// at t^{n+1/2} of the last cycle; 0 without walls.
  double frame_wall_power(std::size_t k) const { return k < frame_wall_power_.size() ? frame_wall_power_[k] : 0.0; }
  /// Nodes in contact with the walls of picture frame k in the last cycle.
  std::int64_t frame_wall_contacts(std::size_t k) const { return k < frame_wall_active_.size() ? frame_wall_active_[k] : 0; }

 private:
  void build_blocks();
  void apply_mass_scaling();
  void assemble_mass();
  void check_finite(const double* vel) const;
  /// Erodes every hexahedron whose step at x (times the safety factor) is below dt_erode or
  /// one of whose corners has folded over (corner Jacobian <= 0); returns the stable step of
  /// those left.
  StableStep erode(const double* x, const double* v, double dt_erode);
  /// "(x, y, z) m": centroid at x of the element a StableStep names (for messages).
  std::string element_position(const StableStep& st, const double* x) const;

  Model& model_;
  std::vector<Hex8Block> hex_;
  std::vector<BarBlock> bar_;
  std::vector<PartMassReport> part_mass_;
  std::vector<ErosionEvent> erosions_;
  std::vector<double> step_scratch_, jacobian_scratch_;
  /// Elements eroded this cycle: their nodes and nodal internal forces at t^n. Their work over the
  /// first half of the next increment, which the trapezoidal external work counts, is booked
  /// as internal energy once the increment is known (the element no longer does it).
  struct ErodedForce {
    std::int32_t node[8];
    double f[24];
  };
  std::vector<ErodedForce> eroded_forces_;
  std::vector<std::uint8_t> fixed_mask_;  // [3*n] 1 where a DOF is fixed
  double t_ = 0, dt_ = 0, dt_prev_ = 0, dt_initial_ = 0;
  std::vector<V3> vpres_;
  struct FrameDof {
    std::int32_t frame = -1;
    double xi = 0, eta = 0;  // reference coordinates along the frame's arms
  };
  std::vector<FrameDof> frame_dof_;       // per constrained DOF (frame = -1: not a frame DOF)
  std::vector<V3> frame_c1_, frame_c2_;   // per frame: d(u1)/dt, d(u2)/dt this cycle
  struct WallContact {
    std::int32_t frame = -1;
    double xi = 0, eta = 0;  // frame coordinates of the contact point on the arm
    V3 force;                // on the node, at t^n
  };
  std::vector<WallContact> wall_contacts_;  // this cycle's
  std::vector<double> frame_wall_power_;
  std::vector<std::int64_t> frame_wall_active_;
  bool has_walls_ = false;
  void frame_wall_forces(const double* x, const double* mass, double dt, double* fc);
  std::vector<std::size_t> constrained_;  // DOFs with a fixed or prescribed velocity
  std::vector<double> constrained_vo_;    // their v^{n-1/2} during a cycle
  std::vector<double> zero_;              // [3*n] zeros for force arrays a model does not use
  bool f_damp_zero_ = false;              // f_damp holds zeros (no damping since it was cleared)
  std::vector<double> inv_mass_;      // [3*n] 1 / lumped mass
  std::vector<double> gravity_mass_;  // [3*n] physical nodal masses (no mass scaling)  // prescribed velocities at t^{n+1/2}, one per set
  std::int64_t cycle_ = 0;
  StableStep step_;
  EnergyBalance energy_;
  WorkAccumulator w_ext_, w_damp_, w_contact_nodes_, w_tools_, tool_work_on_nodes_;
  PhaseTimers timers_;
};

}  // namespace ncfsim::fem
