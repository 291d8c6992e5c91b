#pragma once
// Stitch-to-tow connection elements: each joins a stitch node to a tow node with an elastic spring.
// Along the tow the spring holds up to a sliding force, beyond which the tow slides past the stitch
// (a frictional slider: the force stays at the sliding force, the slip and the energy it dissipates
// are tracked; the sliding force comes from the tow pull-out test). Across the tow the spring stays
// elastic up to a transverse force: the yarn lies in the gap between two tows and bears on their
// sides, so a tow does not slip sideways past it at the pull-out force. The spring's rest offset
// turns with the tow's axis (the smallest rotation from its set-up direction), so a turning tow
// loads no joint; the forces are the gradient of the spring energy, including those on the nodes
// of the tow hexahedron that gives the axis (docs/theory.md, "Stitch-to-tow connection").
// Implemented as a contact of the engine: its forces go to the contact forces, the spring energy
// and the slip work into the contact energy, the slip work also into friction_dissipation.
#include <cstdint>
#include <string>
#include <vector>

#include "drape/fabric_generator.hpp"
#include "fem/contact_interface.hpp"

namespace ncfsim::drape {

struct StitchConnectionSettings {
  double sliding_force = 0.05;     // N per connection (> 0) along the tow, docs/fabric-data.md
  double transverse_force = 0.15;  // N, across the tow (in and out of the ply); 0: no limit
  double stiffness = 0;           // N/m; 0: the stability limit below
  double stiffness_scale = 0.1;   // k <= scale * min(m_a, m_b) / dt^2: never lowers the stable step
};

class StitchToTowConnection final : public fem::ContactAlgorithm {
 public:
  StitchToTowConnection(std::string name, std::vector<StitchConnection> pairs, StitchConnectionSettings s);
  const std::string& name() const override { return name_; }
  void initialise(const fem::ContactSetup& setup) override;
  double estimated_bytes(const fem::Mesh& mesh, bool erosion) const override;
  void add_forces(const double* x, const double* v, const double* mass, double dt, double* f_contact) override;
  double friction_dissipation() const override { return dissipated_; }
  std::int64_t active_contacts() const override { return n_sliding_; }
  std::vector<fem::ContactResultant> resultants() const override;
  /// A joint whose axis hexahedron (one holding its tow node and axis node) is eroded is
  /// released: that piece of tow is gone and gives no axis.
  void erode(const std::vector<std::int32_t>& mesh_elements) override;
  /// Several ranks: a joint is computed where its stitch node is owned; it reads the tow node
  /// and the hexahedron that gives the tow's axis.
  bool nodes_to_read(const std::uint8_t* owned, const double* x0, double halo,
                     std::vector<std::int32_t>& out) const override;
  void restrict_to_rank(const std::uint8_t* owned, const std::uint8_t* readable) override;
  void save_state(fem::CheckpointWriter& w) const override;
  void load_state(fem::CheckpointReader& r) override;
  /// Joints released by erosion so far.
  std::size_t released() const { return n_released_; }

  /// Slip of each connection so far (m, the slider's path length), for output and tests.
  double slip_length(std::size_t i) const { return slip_len_[i]; }
  double force_magnitude(std::size_t i) const { return force_[i]; }
  /// Spring stiffness in use (N/m): the requested one, capped by the stability limit.
  double stiffness(std::size_t i) const { return k_[i]; }
  std::size_t size() const { return a_.size(); }
  /// Tow hexahedra that give the joints' axes (each counted once).
  std::size_t axis_hexahedra() const { return slot_hex_.size(); }

 private:
  std::string name_;
  StitchConnectionSettings s_;
  std::vector<std::int32_t> a_, b_;     // stitch node, tow node
  std::vector<std::int32_t> ax_;  // the tow's next node from b along it (finds the hexahedron)
  std::vector<double> rest_;      // [3*n] rest offset b - a with the slip, set-up frame
  std::vector<double> k_;         // [n]
  std::vector<double> force_, slip_len_;
  // The tow hexahedra that give the joints' axes, each once (about 8 joints share one on the bias
  // cases' CI mesh): its axis is gathered and its forces scattered once per cycle. Per joint: its
  // hexahedron's slot (-1: released by erosion).
  // Several ranks (empty on one): [n] 1: the joint is computed here; [n_slots] 1: a joint of
  // this rank uses the slot.
  std::vector<std::uint8_t> joint_mine_, slot_mine_;
  std::vector<std::int32_t> joint_slot_;
  std::vector<std::int32_t> slot_hex_;    // [n_slots] mesh hexahedron (-1: eroded)
  std::vector<std::int32_t> slot_nodes_;  // [8*n_slots]
  std::vector<double> slot_w_;            // [8*n_slots] +-1/8 at its ends along the tow
  std::vector<double> slot_t0_;           // [3*n_slots] tow axis at set-up (unit)
  // Per cycle, per slot: the turn of the axis (t, a = t0 x t, c = t0.t, |u|) and the sum of
  // k d (x) rho over its joints, from which the forces on its nodes follow.
  std::vector<double> slot_turn_, slot_m_;
  std::size_t n_released_ = 0;
  double dissipated_ = 0;
  std::int64_t n_sliding_ = 0;
  fem::V3 total_{};
};

}  // namespace ncfsim::drape
