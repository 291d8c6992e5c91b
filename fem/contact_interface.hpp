#pragma once
// The solver's view of a deformable contact (penalty, friction, tied): one object per contact
// definition, called once per cycle (one virtual call per cycle, never per node). Implementations
// live in fem/contact/.
#include <cstdint>
#include <string>
#include <vector>

#include "fem/vec3.hpp"

namespace ncfsim::fem {

struct Mesh;
class CheckpointWriter;
class CheckpointReader;

/// What a contact may read when it is set up (after masses are assembled, before cycle 0).
struct ContactSetup {
  const Mesh* mesh = nullptr;
  const double* x0 = nullptr;    // reference positions [3*n_nodes]
  const double* mass = nullptr;  // lumped nodal masses [3*n_nodes] (incl. mass scaling)
  double dt = 0;                 // the initial stable step (already times the safety factor)
  bool erosion = false;          // elements may be eroded: faces they uncover must become surface
};

/// Force resultant of one reported pair (of contact groups) for history.csv.
struct ContactResultant {
  std::string name;  // e.g. "tows_ply1__tows_ply2"
  V3 force;          // on the first group, N
};

class ContactAlgorithm {
 public:
  virtual ~ContactAlgorithm() = default;
  virtual const std::string& name() const = 0;
  /// Builds surfaces, search structures and penalties; throws InputError on bad definitions.
  virtual void initialise(const ContactSetup& setup) = 0;
  /// Bytes this contact will hold once initialised on `mesh` (one rank's), for the memory
  /// estimate made before the solver is built (fem/memory_estimate.hpp); `erosion`: elements may
  /// be eroded (a penalty contact then keeps every face of its hexahedra).
  virtual double estimated_bytes(const Mesh& mesh, bool erosion) const = 0;
  /// Adds contact forces at positions x (velocities v over the last half step, step dt) into
  /// f_contact [3*n_nodes]. Forces between deformable bodies must sum to zero.
  virtual void add_forces(const double* x, const double* v, const double* mass, double dt,
                          double* f_contact) = 0;
  /// Before add_forces: a running bound on how far any node this contact reads has moved since
  /// the solver started or resumed (m, non-decreasing; not called: none). A contact may skip
  /// work whose outcome the nodes cannot have changed by moving that much since it last did it.
  virtual void set_node_travel(double travel) { (void)travel; }
  /// Energy dissipated by friction (and failed ties) so far, J; part of the contact energy.
  virtual double friction_dissipation() const = 0;
  /// Resultants per reported pair, valid after add_forces.
  virtual std::vector<ContactResultant> resultants() const { return {}; }
  /// Largest step this contact allows (1e300 = no limit). Penalties should not need one.
  virtual double stable_step_limit() const { return 1e300; }
  /// Number of active contacts after the last add_forces (diagnostics).
  virtual std::int64_t active_contacts() const { return 0; }
  /// Deepest penetration past the contact thickness over the run so far, m (0: not tracked).
  virtual double max_penetration() const { return 0; }
  /// Cost counters for the run's log (0: not counted): the contact nodes this rank searches
  /// (its own on several ranks) and the broad-phase searches (bucket sorts) made so far.
  virtual std::size_t n_contact_nodes() const { return 0; }
  virtual std::int64_t n_broad_phase_searches() const { return 0; }
  /// Where the time went and what was searched, in words, for the run's log (empty: nothing).
  virtual std::string cost_details() const { return {}; }
  /// The elements `mesh_elements` (mesh-wide indices: Mesh::element_offset of the kind plus the
  /// index in its set) were eroded: their faces stop being contact segments from the next
  /// add_forces on, and the faces of their neighbours that they covered start being ones.
  virtual void erode(const std::vector<std::int32_t>& mesh_elements) { (void)mesh_elements; }
  // Domain decomposition (fem/parallel/domain.hpp, docs/parallel.md).
  /// Appends the nodes this rank must read, beyond the elements it integrates, to compute the
  /// contacts of the nodes it owns (owned[mesh node] = 1) at reference positions x0, remote
  /// surfaces within `halo` (m) of its own included. False: this contact cannot run on several
  /// ranks.
  virtual bool nodes_to_read(const std::uint8_t* owned, const double* x0, double halo,
                             std::vector<std::int32_t>& out) const {
    (void)owned, (void)x0, (void)halo, (void)out;
    return false;
  }
  /// From now on computes only the contacts of the nodes this rank owns, with the nodes it can
  /// read (readable[mesh node] = 1, kept current by the ghost exchange). Its resultants,
  /// dissipation and counters are then this rank's share.
  virtual void restrict_to_rank(const std::uint8_t* owned, const std::uint8_t* readable) {
    (void)owned, (void)readable;
  }
  /// The contact's state carried from cycle to cycle into a checkpoint, and back into a contact
  /// built and initialised from the same case (fem/checkpoint.hpp; CheckpointMismatch when it
  /// does not fit). Called at a cycle boundary only.
  virtual void save_state(CheckpointWriter& w) const = 0;
  virtual void load_state(CheckpointReader& r) = 0;
};

}  // namespace ncfsim::fem
