#pragma once
// One element group: the elements of one kind and one part, with their state as structure of
// arrays and the kernels that advance it. The solver holds a list of groups and calls each once
// per cycle phase (a virtual call per group, never per element; the kernels behind it batch the
// elements in SIMD lanes). Groups are built by make_element_group (fem/elements/element_groups.cpp)
// before the first cycle.
#include <cstdint>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "fem/elements/element_kind.hpp"
#include "fem/elements/element_step.hpp"

namespace ncfsim::fem {

struct Model;
struct ElementSet;
class CheckpointWriter;
class CheckpointReader;

/// Nodal state an element kernel reads in a cycle, [3*n_nodes] each.
struct ElementCycleState {
  const double* x = nullptr;      // positions x^n
  const double* v = nullptr;      // velocities v^{n-1/2}
  const double* x_ref = nullptr;  // reference positions
  double dt = 0;                  // the step that moved the nodes to x^n
};

/// Name and size of one per-element output field (entity-major [n][components]).
struct CellFieldSpec {
  std::string name;
  int components = 1;
};

/// Dynamic mass scaling's target step, less this share, is what counts as below it: the elements
/// scaled to the target at the start sit on it, a rounding either side (the hexahedron kernel's
/// arithmetic and hex8_element_steps' differ in the last bits). Without it a step one rounding
/// under the target could start a scan every cycle that gave such elements 10 % more mass (the
/// headroom; test DynamicMassScaling.StepARoundingBelowTheTargetGetsNoMass).
inline constexpr double kMassScalingBelowShare = 1e-9;

/// What one pass of dynamic mass scaling did on a group: the mass added (kg), the elements
/// scaled, those below the target that the cap on added mass left as they were, and all those
/// at the cap after the pass.
struct DynamicScalingResult {
  double added_mass = 0;
  std::int64_t scaled = 0;
  std::int64_t held_at_cap = 0;
  std::int64_t at_cap = 0;
};

class ElementGroup {
 public:
  virtual ~ElementGroup() = default;
  virtual ElementKind kind() const = 0;
  int part() const { return part_; }
  std::size_t size() const { return n_; }
  int nodes_per_element() const { return fem::nodes_per_element(kind()); }
  /// Node I of element e is conn()[I * size() + e] ([nodes_per_element][n]).
  const std::int32_t* conn() const { return conn_; }
  std::int64_t user_id(std::size_t e) const { return user_id_[e]; }
  /// Index of element e in its mesh element set.
  std::int32_t set_index(std::size_t e) const { return set_index_[e]; }

  /// Element nodal masses added into mass [3*n_nodes].
  virtual void lumped_mass(double* mass) const = 0;
  /// Physical mass and mass added by mass scaling, added into the two sums (kg).
  virtual void add_part_mass(double& mass, double& added_mass) const = 0;
  /// Adds mass where an element's step (times safety) is below target_dt, so that it reaches it.
  virtual void scale_mass(const double* x, double target_dt, double safety) = 0;
  /// Dynamic mass scaling: each element of this rank's range whose step at x (times safety) is
  /// below target_dt gets the density that puts it at `headroom` times target_dt, but no more
  /// than (1 + max_added_ratio) times its material's density (then its step falls below the
  /// target); its added mass goes to its nodes in dm [3*n_nodes] (an eighth each for a
  /// hexahedron). Kinds that do not scale during a run add nothing.
  virtual DynamicScalingResult scale_mass_dynamic(const double* x, double target_dt, double safety,
                                                  double headroom, double max_added_ratio,
                                                  double* dm) {
    (void)x, (void)target_dt, (void)safety, (void)headroom, (void)max_added_ratio, (void)dm;
    return {};
  }
  /// Whether element e's density has reached (1 + max_added_ratio) times its material's (the cap
  /// of dynamic mass scaling). Kinds that do not scale during a run: never.
  virtual bool at_mass_cap(std::size_t e, double max_added_ratio) const {
    (void)e, (void)max_added_ratio;
    return false;
  }
  /// Stable step of the group's controlling element at positions x.
  virtual StableStep stable_step(const double* x) const = 0;
  /// Internal forces subtracted from f [3*n_nodes]; energy increments accumulated, step lowered to
  /// this group's controlling element.
  virtual void internal_forces(const ElementCycleState& s, double* f,
                               ElementEnergyIncrement& energy, StableStep& step) = 0;

  // Domain decomposition (fem/parallel/domain.hpp).
  /// Elements per kernel chunk: a rank's run of this group starts on a multiple of it.
  virtual std::size_t chunk() const { return 1; }
  /// Restricts the per-cycle kernels (forces, steps) to elements [begin, end) on this rank;
  /// false for a kind that cannot be split over ranks.
  virtual bool set_range(std::size_t begin, std::size_t end) {
    (void)begin, (void)end;
    return false;
  }
  /// The per-element state arrays, [components][size()] doubles each, that an output on the
  /// root gathers from the ranks that integrate them.
  virtual std::vector<std::pair<double*, int>> state_arrays() { return {}; }
  /// For a group that holds nodal degrees of freedom of its own (the shells' rotations): the
  /// nodes this rank owns (owned[mesh node] = 1), whose kinetic energy it books, and the nodal
  /// array [3 n_nodes] of moments its internal forces accumulate, which the solver sums over the
  /// ranks (ghosts into owners, then back) before the next cycle (null: none).
  virtual void set_owned_nodes(const std::uint8_t* owned) { (void)owned; }
  virtual double* nodal_moments() { return nullptr; }

  // Erosion (kinds that can lose elements; the defaults are for those that cannot).
  virtual bool can_erode() const { return false; }
  /// Step of every element of this rank's range at x (1e300 for an eroded one and, on several
  /// ranks, for another rank's) and, where asked, the smallest corner Jacobian ratio of each
  /// (<= 0: folded over at a corner).
  virtual void element_steps(const double* x, std::vector<double>& dt,
                             std::vector<double>* corner_jacobian) const {
    (void)x, (void)dt, (void)corner_jacobian;
  }
  /// As element_steps, for the elements at the cap of dynamic mass scaling only (at_mass_cap);
  /// the others get 1e300.
  virtual void capped_element_steps(const double* x, double max_added_ratio,
                                    std::vector<double>& dt) const {
    (void)x, (void)max_added_ratio, (void)dt;
  }
  /// Nodal forces f[nodes_per_element][3] element e exerts at x, v as it stands (not changed).
  virtual void element_force(std::size_t e, const double* x, const double* v, double* f) const {
    (void)e, (void)x, (void)v, (void)f;
  }
  /// Removes element e; returns the elastic energy it held, which leaves the model with it.
  virtual double erode(std::size_t e) {
    (void)e;
    return 0;
  }
  virtual std::size_t n_eroded() const { return 0; }
  /// Whether the group's material can fail an element (SolidMaterial::failure_history_row).
  virtual bool material_can_fail() const { return false; }
  /// Appends the elements (group indices) the material has failed and that are not eroded yet.
  virtual void failed_elements(std::vector<std::size_t>& out) const { (void)out; }

  /// Per-element output fields of this kind and their values for the group's elements:
  /// out[k] points to [size()][components of field k] of cell_fields()[k].
  virtual std::vector<CellFieldSpec> cell_fields() const = 0;
  virtual void cell_values(const double* x, double* const* out) const = 0;

  /// The group's mutable state (its block's state arrays, and what the group itself carries from
  /// cycle to cycle) into a checkpoint, and back into a group built from the same case
  /// (fem/checkpoint.hpp: "rebuild, then overwrite"; CheckpointMismatch on another size).
  virtual void save_state(CheckpointWriter& w) const = 0;
  virtual void load_state(CheckpointReader& r) = 0;

 protected:
  // Set by the group from its block's arrays (the block owns them).
  int part_ = 0;
  std::size_t n_ = 0;
  const std::int32_t* conn_ = nullptr;
  const std::int64_t* user_id_ = nullptr;
  std::vector<std::int32_t> set_index_;
};

/// The elements `elements` (indices into `set`) of part `part`, as a group of the set's kind, set
/// up at reference positions x_ref. Throws InputError naming the part when its properties do not
/// fit the kind (no material, no bar law), NumericalError for a degenerate element.
std::unique_ptr<ElementGroup> make_element_group(const Model& model, const ElementSet& set,
                                                 int part, const std::vector<std::size_t>& elements,
                                                 const double* x_ref);

/// The block of kind Block behind a group, null when the group is of another kind.
template <class Block>
Block* block_of(ElementGroup& g);
template <class Block>
const Block* block_of(const ElementGroup& g);

}  // namespace ncfsim::fem
