#pragma once
// Central-difference explicit time integration with a variable stable step, on nodal state held
// in PETSc vectors. The model is checked and all element groups built before the first cycle;
// the cycle itself only computes.
#include <array>
#include <chrono>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "fem/boundary/boundary_motion.hpp"
#include "fem/elements/element_group.hpp"
#include "fem/energy.hpp"
#include "fem/huge_pages.hpp"
#include "fem/model.hpp"
#include "fem/petsc_vector.hpp"

namespace ncfsim::fem {

struct PartMassReport {
  std::string part;
  double mass = 0;        // physical mass, kg
  double added_mass = 0;  // mass added by mass scaling, kg
};

class PictureFrameMotion;
class Domain;
class CheckpointWriter;
class CheckpointReader;

/// The blocks of one kind among the solver's element groups, in group order (range-for, [], at).
template <class Block>
class BlockList {
 public:
  explicit BlockList(std::vector<Block*> b) : b_(std::move(b)) {}
  struct iterator {
    typename std::vector<Block*>::const_iterator it;
    Block& operator*() const { return **it; }
    iterator& operator++() { return ++it, *this; }
    bool operator==(const iterator& o) const { return it == o.it; }
  };
  iterator begin() const { return {b_.begin()}; }
  iterator end() const { return {b_.end()}; }
  std::size_t size() const { return b_.size(); }
  bool empty() const { return b_.empty(); }
  Block& operator[](std::size_t i) const { return *b_[i]; }
  Block& at(std::size_t i) const { return *b_.at(i); }

 private:
  std::vector<Block*> b_;
};

/// One element removed by erosion.
struct ErosionEvent {
  enum class Cause { StableStep, InvertedCorner, MaterialFailure, MassCap };
  Cause cause = Cause::StableStep;
  double time = 0;
  std::int64_t cycle = 0;
  std::int64_t element = 0;  // user id
  ElementKind kind = ElementKind::Hex8;
  int part = 0;
  double step = 0;  // its stable step when eroded (times the safety factor), s
  V3 centroid;      // m
};

struct PhaseTimers {
  double internal_force = 0, contact = 0, update = 0, output = 0;  // seconds
  double exchange = 0;  // MPI: ghost exchange and reductions (0 on one rank)
};

/// One MPI rank's share of a run (ExplicitSolver::rank_reports).
struct RankReport {
  std::size_t elements = 0;     // elements it integrates
  std::size_t owned_nodes = 0;  // nodes it updates
  std::size_t ghost_nodes = 0;  // nodes it reads from other ranks
  std::size_t ghost_bytes = 0;  // bytes it sends per cycle in the ghost exchange
  PhaseTimers timers;           // its phase times so far (output excluded)
};

class ExplicitSolver {
 public:
  /// Builds element groups, masses and the initial state. Throws InputError / NumericalError.
  explicit ExplicitSolver(Model& model);
  ~ExplicitSolver();

  /// One cycle. `at_tn` (may be empty) is called once state at t^n is complete (forces,
  /// energies, v^{n+1/2}), before the positions move on to t^{n+1}. With `at_tn_reads_x` false
  /// the callback promises not to read x: the positions then move in the velocity pass (one
  /// sweep over the nodal arrays, as without a callback), with the same results bit for bit.
  void step(const std::function<void()>& at_tn = {}, bool at_tn_reads_x = true);

  double time() const { return t_; }
  double time_step() const { return dt_; }
  /// What the set-up got of 2 MB pages for the model's arrays (fem/huge_pages.hpp), and from
  /// the 100th cycle of this process what it has after a second advice.
  const HugePageAdvice& huge_pages() const { return huge_pages_; }
  std::int64_t cycle() const { return cycle_; }
  const EnergyBalance& energy() const { return energy_; }
  const StableStep& controlling_element() const { return step_; }
  const std::vector<PartMassReport>& part_masses() const { return part_mass_; }
  /// Whether elements may be eroded: time.erosion_step_ratio or time.mass_scaling_erode_at_cap
  /// set, or a material that fails elements (a damage law).
  bool erosion_enabled() const {
    return model_.time.erosion_step_ratio > 0 || model_.time.mass_scaling_erode_at_cap ||
           material_failure_;
  }
  /// Elements eroded so far (time.erosion_step_ratio, material failure), in order.
  const std::vector<ErosionEvent>& erosions() const { return erosions_; }
  /// Nodes left with no element by erosion so far: they are held where they were, out of every
  /// contact, their kinetic energy booked as EnergyBalance::eroded_kinetic.
  std::size_t n_freed_nodes() const { return n_freed_nodes_; }
  const PhaseTimers& timers() const { return timers_; }
  /// The phase timers of this process's loop only (after a resume, less the saved ones), as
  /// tool_seconds, contact_seconds and group_seconds count.
  PhaseTimers loop_timers() const {
    return {timers_.internal_force - timers_loaded_.internal_force,
            timers_.contact - timers_loaded_.contact, timers_.update - timers_loaded_.update,
            timers_.output - timers_loaded_.output, timers_.exchange - timers_loaded_.exchange};
  }
  /// Seconds spent in contact k (model().contacts[k]) so far, part of timers().contact.
  double contact_seconds(std::size_t k) const {
    return k < contact_seconds_.size() ? contact_seconds_[k] : 0.0;
  }
  /// Seconds spent in rigid tool k (model().tools[k]) so far, part of timers().contact.
  double tool_seconds(std::size_t k) const {
    return k < tool_seconds_.size() ? tool_seconds_[k] : 0.0;
  }
  /// Seconds spent in element group k's internal forces (groups()[k]) so far, part of
  /// timers().internal_force (the rest: erosion checks and the choice of the step).
  double group_seconds(std::size_t k) const {
    return k < group_seconds_.size() ? group_seconds_[k] : 0.0;
  }
  /// Dynamic mass scaling (time.mass_scaling_dynamic): the cycles in which mass was added.
  std::int64_t mass_scaling_events() const { return mass_scaling_events_; }
  /// Hexahedra (all ranks) whose added mass has reached time.mass_scaling_max_ratio: their step
  /// is their own again.
  std::int64_t mass_scaling_capped() const { return mass_scaling_capped_; }
  /// Several ranks: how many times the contact halo was built again as the nodes moved
  /// (parallel.contact_halo_refresh; since the start or the resume).
  std::int64_t contact_halo_builds() const { return halo_builds_; }
  /// The split over MPI ranks (fem/parallel/domain.hpp); null on one rank.
  const Domain* domain() const { return domain_.get(); }
  /// Several ranks: flags (bits 0-3) the caller's loop raises on this rank (a stop, a
  /// checkpoint), OR-ed over the ranks in the next cycle's sums rather than in a collective of
  /// their own; requests_all_ranks() gives that OR after the cycle (0 before the first).
  void raise_requests(unsigned flags) { requests_ = flags & kRequestMask; }
  unsigned requests_all_ranks() const { return requests_all_ranks_; }
  static constexpr unsigned kRequestMask = 0xF;
  /// On several ranks: brings the whole state to the root (nodal arrays, element state, tool
  /// counters) so that output code reads it there as on one rank. Collective; nothing on one rank.
  void gather_for_output();
  /// Resultants and deepest penetration of contact k (ContactAlgorithm's); on several ranks the
  /// sums (maximum) over the ranks as of the last gather_for_output.
  std::vector<ContactResultant> contact_resultants(std::size_t k) const;
  double contact_max_penetration(std::size_t k) const;
  /// On the root of several ranks: each rank's share as of the last gather_for_output (empty
  /// on one rank).
  const std::vector<RankReport>& rank_reports() const { return rank_reports_; }
  std::size_t n_elements(ElementKind kind) const;
  std::size_t n_elements() const;

  Model& model() { return model_; }
  const Model& model() const { return model_; }
  /// Element groups (one per kind and part, kinds in ElementKind order, parts ascending).
  const std::vector<std::unique_ptr<ElementGroup>>& groups() const { return groups_; }
  /// The groups of one kind as their blocks (Hex8Block, BarBlock, ...).
  template <class Block>
  BlockList<Block> blocks() {
    std::vector<Block*> b;
    for (auto& g : groups_)
      if (Block* p = block_of<Block>(*g)) b.push_back(p);
    return BlockList<Block>(std::move(b));
  }
  template <class Block>
  BlockList<const Block> blocks() const {
    std::vector<const Block*> b;
    for (const auto& g : groups_)
      if (const Block* p = block_of<Block>(*g)) b.push_back(p);
    return BlockList<const Block>(std::move(b));
  }

  // Nodal state, [3*n_nodes] each.
  NodalVector x0, x, v, mass, f_int, f_ext, f_contact, f_damp, reaction;

  /// Sum over the nodes of a DOF-wise reaction of a named constraint (fixed or velocity set).
  V3 reaction_force(const std::vector<std::int32_t>& nodes) const;
  /// Power (W) the walls of picture frame k (its arms, PictureFrame::walls) put into the nodes
  /// at t^{n+1/2} of the last cycle; 0 without walls.
  double frame_wall_power(std::size_t k) const;
  /// Nodes in contact with the walls of picture frame k in the last cycle.
  std::int64_t frame_wall_contacts(std::size_t k) const;

  /// The mutable state at a cycle boundary (between two step() calls): x^n, v^{n-1/2}, time and
  /// steps, energies and pending works, erosion, then every group (/groups/NNN), tool
  /// (/tools/<name>) and contact (/contacts/NNN) into the current group of `w`.
  void save_state(CheckpointWriter& w) const;
  /// Overwrites the state of a solver just built from the same case (before its first step(),
  /// else std::logic_error) with a saved one; the next step() goes on as the saved run's would,
  /// bit for bit. CheckpointMismatch names what does not fit (another mesh size, another group).
  void load_state(CheckpointReader& r);

 private:
  /// What one cycle's phases hand on to the next (step() runs them in order).
  struct Cycle {
    bool move_x_in_pass = true;  // x^{n+1} in the velocity pass (the callback does not read x^n)
    bool has_ext = false, has_contact = false, has_damp = false;  // force kinds in use
    std::array<double, 3> booked0{};  // internal, eroded internal and kinetic energy before it
    ElementEnergyIncrement inc;       // the elements' energy increments (this rank's)
    StableStep st;                    // the element that controls the step
    double dt_new = 0, alpha = 0, t_half = 0, dt_mid = 0;
    // Works over the increments around t^n (F.du_old, F.du_new per force kind) and the kinetic
    // energy in product form: this rank's share until sum_over_ranks.
    double ext_old = 0, ext_new = 0, damp_old = 0, damp_new = 0, con_old = 0, con_new = 0, ke = 0;
    // Several ranks: this rank's report of a blow-up in its kernels or contacts, told to all at
    // the cycle's next collective (no collective of its own: one sync point less per cycle).
    std::string blow_up;
  };
  /// The nodal arrays of a cycle ([3*n_nodes]; step() holds the vectors' views).
  struct CycleArrays {
    double* x;
    double* v;
    const double* x0;
    const double* m;
    double *fi, *fe, *fc, *fd, *r;  // internal, external, contact, damping forces, reactions
  };
  // The phases of step(), in order.
  void internal_forces(const CycleArrays& a, Cycle& c);
  void erode_and_choose_step(const CycleArrays& a, Cycle& c);
  void contact_forces(const CycleArrays& a, Cycle& c);
  void exchange_forces(const CycleArrays& a, Cycle& c);  // several ranks
  void external_forces(const CycleArrays& a, Cycle& c);
  void update_velocities(const CycleArrays& a, Cycle& c);
  void sum_over_ranks(Cycle& c);  // several ranks
  void book_energies(const CycleArrays& a, Cycle& c);
  void finish_cycle(const Cycle& c);

  void build_blocks();
  void apply_mass_scaling();
  void assemble_mass();
  void check_finite(const double* vel) const;
  /// Several ranks (collective): throws on every rank the NumericalError `what` of the lowest
  /// rank whose `what` is a report (not empty, not "-"); returns when no rank has one.
  void share_blow_up(const std::string& what) const;
  /// Several ranks (collective): throws on every rank the report `what` of rank `from`, which the
  /// ranks found together in a reduction (`from` = size: none, returns).
  void throw_blow_up_of(int from, const std::string& what) const;
  void build_motions();
  /// Whether an element of this rank at the cap of dynamic mass scaling has its step below
  /// cap_dt (only those are measured; none while no element has reached the cap).
  bool capped_below(const double* x, double cap_dt);
  /// With time.mass_scaling_erode_at_cap, the step below which an element at the mass cap is
  /// eroded: the target, less the rounding a scaled element's step sits below it; 0 without.
  double mass_cap_erosion_step() const;
  /// Erodes every element of the groups that can lose elements whose step at x (times the
  /// safety factor) is below dt_erode or one of whose corners has folded over (corner Jacobian
  /// <= 0); those groups' steps (group_step_) become the stable step of the elements left.
  /// Without `check_steps` only the elements the material has failed are eroded.
  /// Nodes of eroded elements left with no element are taken out (see n_freed_nodes).
  void erode(const double* x, const double* v, double dt_erode, bool check_steps,
             const std::string& blow_up = {});
  /// Several ranks: shares this cycle's erosions (see solver.cpp); `gone` becomes every rank's.
  void share_erosions(std::vector<std::int32_t>& gone, std::vector<std::int32_t>& orphans,
                      const std::string& blow_up);
  /// Takes out the nodes of `candidates` that no element holds any more and no constraint drives.
  void free_orphan_nodes(const std::vector<std::int32_t>& candidates);
  /// "(x, y, z) m": centroid at x of the element a StableStep names (for messages).
  std::string element_position(const StableStep& st, const double* x) const;

  /// Splits the model over the ranks of PETSC_COMM_WORLD (more than one): InputError for what
  /// cannot be split yet.
  void decompose();

  Model& model_;
  std::vector<std::unique_ptr<ElementGroup>> groups_;
  std::unique_ptr<Domain> domain_;
  std::vector<StableStep> group_step_;                    // per group, this cycle
  std::vector<std::unique_ptr<BoundaryMotion>> motions_;  // rigs that drive nodes (picture frames)
  PictureFrameMotion* frames_ = nullptr;                  // among motions_
  std::vector<PartMassReport> part_mass_;
  std::vector<ErosionEvent> erosions_;
  std::vector<std::int32_t> node_elements_;  // [n_nodes] elements (any kind) still holding it
  std::vector<std::uint8_t> node_freed_;     // [n_nodes] 1: left with no element, taken out
  std::size_t n_freed_nodes_ = 0;
  std::vector<std::size_t> freeing_;  // DOFs of nodes freed this cycle (stopped in its update)
  std::vector<double> freeing_vo_;    // their v^{n-1/2}
  std::vector<double> freeing_xo_;    // their x^n (positions moved in the velocity pass)
  bool material_failure_ = false;     // a group's material can fail elements
  std::vector<double> step_scratch_, jacobian_scratch_;
  std::vector<double> reduce_buffer_;  // per-cycle sums over the ranks
  std::vector<std::pair<std::size_t, std::size_t>> local_erosions_;  // (group, element) this cycle
  bool eroded_any_ = false;        // several ranks: some rank eroded an element this cycle
  double friction_all_ranks_ = 0;  // several ranks: friction dissipated, summed this cycle
  unsigned requests_ = 0, requests_all_ranks_ = 0;  // several ranks: see raise_requests
  std::vector<double> contact_seconds_;             // per contact, see contact_seconds
  std::vector<double> tool_seconds_;                // per rigid tool, see tool_seconds
  std::vector<double> group_seconds_;               // per element group, see group_seconds
  std::vector<std::vector<ContactResultant>> contact_resultants_;  // several ranks: summed
  std::vector<double> contact_max_penetration_;
  std::array<double, 4> motion_work_all_ranks_{};  // several ranks: the rigs' wall works, summed
  std::vector<double> frame_wall_power_;           // several ranks: summed at gather_for_output
  std::vector<std::int64_t> frame_wall_contacts_;
  std::vector<RankReport> rank_reports_;
  /// Elements eroded this cycle: their nodes and nodal internal forces at t^n. Their work over the
  /// first half of the next increment, which the trapezoidal external work counts, is booked
  /// as internal energy once the increment is known (the element no longer does it).
  struct ErodedForce {
    int n_nodes = 0;
    std::int32_t node[kMaxNodesPerElement];
    double f[3 * kMaxNodesPerElement];
  };
  std::vector<ErodedForce> eroded_forces_;
  std::vector<std::uint8_t> fixed_mask_;  // [3*n] 1 where a DOF is fixed
  double t_ = 0, dt_ = 0, dt_prev_ = 0, dt_initial_ = 0;
  HugePageAdvice huge_pages_;
  static constexpr std::int64_t kHugePageSecondLook = 100;  // cycles of this process before the
  std::int64_t cycles_here_ = 0;                            // second advice (a resume too)
  // Sum over the cycles of a bound on this rank's largest node displacement in each (m): the
  // rigid tools' proximity cull compares its growth with their margin (not checkpointed: after a
  // resume the tools check once and start from there).
  double node_travel_ = 0;
  PhaseTimers timers_loaded_;  // the timers a checkpoint brought (loop_timers)
  // Several ranks, the contact halo built again as the nodes move (refresh_contact_halo): the
  // positions at the last build, a bound on the largest node displacement since (summed over
  // the ranks each cycle, the same on all), the last exact check of it, and the builds so far.
  std::vector<double> halo_x_;
  double halo_travel_ = 0, halo_checked_d_ = 0, halo_travel_checked_ = 0, node_travel_sent_ = 0;
  // The same bound summed over the ranks since this process started, never reset (the contacts'
  // displacement checks read it: every node they read moved at most that far).
  double travel_all_ranks_ = 0;
  bool halo_due_ = false;  // after a resume: rebuild the last build's halo at the next cycle
  std::int64_t halo_builds_ = 0;
  void refresh_contact_halo(double* x, double* v);
  void build_contact_halo(double* x, double* v);
  // Dynamic mass scaling (time.mass_scaling_dynamic): events so far and the work array.
  std::int64_t mass_scaling_events_ = 0;
  // No scan before this cycle: the last found every hexahedron below the target at the cap.
  std::int64_t mass_scaling_pause_until_ = 0;
  std::int64_t mass_scaling_capped_ = 0;  // hexahedra at the cap (all ranks), as of the last scan
  double mass_scaling_work_ = 0;  // this cycle's, on held nodes (booked as external work)
  std::vector<double> added_mass_scratch_;
  void scale_mass_dynamic(double* x, double* v, double* m);
  std::vector<V3> vpres_;         // prescribed velocities at t^{n+1/2}, one per set
  std::vector<double> motion_v_;  // per constrained DOF: velocity from its boundary motion
  bool has_motion_forces_ = false;
  std::vector<std::size_t> constrained_;  // DOFs with a fixed or prescribed velocity
  std::vector<double> constrained_vo_;    // their v^{n-1/2} during a cycle
  std::vector<double> constrained_xo_;    // their x^n during a cycle (positions moved in the pass)
  std::vector<double> zero_;              // [3*n] zeros for force arrays a model does not use
  bool f_damp_zero_ = false;              // f_damp holds zeros (no damping since it was cleared)
  std::vector<double> inv_mass_;          // [3*n] 1 / lumped mass
  std::vector<double> gravity_mass_;      // [3*n] physical nodal masses (no mass scaling)
  std::int64_t cycle_ = 0;
  StableStep step_;
  EnergyBalance energy_;
  WorkAccumulator w_ext_, w_damp_, w_contact_nodes_, w_tools_, tool_work_on_nodes_;
  PhaseTimers timers_;
};

}  // namespace ncfsim::fem
