#pragma once
// Tied contact: each node of the slave surface is tied at t = 0 to the nearest point of the master
// surface (a segment and local coordinates, plus the initial offset in the segment's own frame, so
// the tie follows rigid rotations), held there by a penalty spring k = penalty_scale * m_s m_m /
// (m_s + m_m) / dt0^2 in all directions. A tie fails on the quadratic criterion of
// TiedContactConfig; a failed tie's elastic energy is counted as dissipated
// (friction_dissipation()) and it carries no force afterwards.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fem/contact/cohesive_law.hpp"
#include "fem/contact/contact_config.hpp"
#include "fem/contact_interface.hpp"

namespace ncfsim::fem {

class TiedContact final : public ContactAlgorithm {
 public:
  /// Checks the configuration's ranges (InputError); the mesh is checked in initialise().
  explicit TiedContact(TiedContactConfig config);

  const std::string& name() const override { return cfg_.name; }
  void initialise(const ContactSetup& setup) override;
  double estimated_bytes(const Mesh& mesh, bool erosion) const override;
  void add_forces(const double* x, const double* v, const double* mass, double dt,
                  double* f_contact) override;
  /// Elastic energy released by failed ties, J.
  double friction_dissipation() const override { return dissipation_; }
  /// One resultant "slave__master": the force on the slave group.
  std::vector<ContactResultant> resultants() const override;
  /// Ties still holding.
  std::int64_t active_contacts() const override { return n_alive_; }
  /// Ties on faces of eroded hexahedra fail in the next add_forces (their energy released).
  void erode(const std::vector<std::int32_t>& mesh_elements) override;
  /// Several ranks: the master segments of the ties of owned slave nodes.
  bool nodes_to_read(const std::uint8_t* owned, const double* x0, double halo,
                     std::vector<std::int32_t>& out) const override;
  void restrict_to_rank(const std::uint8_t* owned, const std::uint8_t* readable) override;
  void save_state(CheckpointWriter& w) const override;
  void load_state(CheckpointReader& r) override;

  const TiedContactConfig& config() const { return cfg_; }
  std::size_t n_ties() const { return node_.size(); }
  std::size_t n_failed() const { return node_.size() - static_cast<std::size_t>(n_alive_); }
  /// Tributary area of the ties (m^2): all, and of the failed ones.
  double tied_area() const;
  double failed_area() const;
  /// Damage of each tie (0: intact, 1: separated; abrupt ties jump from 0 to 1).
  double damage(std::size_t t) const { return alive_[t] ? state_[t].damage : 1.0; }
  double search_distance() const { return search_distance_; }
  /// Several ranks: each rank updates only the ties of its own slave nodes. For output the
  /// solver takes every tie's state at its minimum over the ranks (0 failed, 1 holds, 2 holds
  /// until the next cycle) and gives it to the root, which keeps its own ties' states and takes
  /// the others' (so failed_area() counts the whole interface's failures).
  const std::vector<std::uint8_t>& tie_states() const { return alive_; }
  void take_other_ranks_tie_states(const std::vector<std::uint8_t>& merged) {
    for (std::size_t t = 0; t < alive_.size() && t < merged.size(); ++t)
      if (!mine_.empty() && !mine_[t]) alive_[t] = merged[t];
  }
  /// Slave nodes beside no master segment (within the search distance): not tied.
  std::size_t untied_nodes() const { return untied_; }

  /// One tie as initialise() made it, for a deck that ties the same points (transfer's export).
  struct TieRecord {
    std::int32_t node = 0;                 // slave node
    std::array<std::int32_t, 4> corner{};  // master segment's corners
    double xi = 0, eta = 0;                // the tied point on the segment
    double stiffness = 0;                  // k, N/m
    double area = 0;                       // tributary area, m^2
  };
  TieRecord tie(std::size_t t) const {
    TieRecord r{node_[t], {}, xi_[t], eta_[t], stiffness_[t], area_[t]};
    for (std::size_t a = 0; a < 4; ++a) r.corner[a] = corner_[4 * t + a];
    return r;
  }

 private:
  /// Every tie intact, no work done yet (after the ties are found).
  void reset_tie_state();
  /// Ties each node of the configured slave faces to the nearest of its paired master faces.
  void initialise_face_pairs(const ContactSetup& setup);
  void add_tie(std::int32_t node, const std::int32_t* corners, double xi, double eta,
               std::int32_t seg_hex, double area, const double* x0, const double* mass,
               double inv_dt0_sq);

  TiedContactConfig cfg_;
  bool cohesive_ = false;
  double search_distance_ = 0;
  std::size_t untied_ = 0;
  // One entry per tie (structure of arrays).
  std::vector<std::int32_t> node_;     // [n_tie] slave node
  std::vector<std::int32_t> corner_;   // [n_tie][4] master segment corners
  std::vector<double> xi_, eta_;       // [n_tie] local coordinates on the segment
  std::vector<double> offset_;         // [n_tie][3] initial offset along (t1, t2, n) of the segment
  std::vector<double> offset_global_;  // [n_tie][3] initial offset, global (cohesive ties)
  std::vector<double> stiffness_;      // [n_tie] k, N/m
  std::vector<double> normal_cap_;     // [n_tie] tensile strength * area, N (0: none)
  std::vector<double> shear_cap_;      // [n_tie] shear strength * area, N (0: none)
  std::vector<std::int32_t> seg_hex_;  // [n_tie] hexahedron owning the master segment
  std::vector<std::int32_t> slave_hex_;  // [n_tie] a hexahedron of the slave face (-1: unknown)
  std::vector<double> area_;             // [n_tie] tributary area, m^2
  std::vector<CohesiveState> state_;     // [n_tie] cohesive state (cohesive ties)
  // Cohesive ties: the work done on each tie (trapezoidal in its separation) and the separation
  // and force of the last cycle; what a tie dissipated is its work less the energy it holds.
  std::vector<double> tie_work_, last_sep_, last_force_;
  double failed_work_ = 0;           // work done on the ties that have failed (all dissipated)
  std::vector<std::uint8_t> mine_;   // several ranks: [n_tie] 1: its slave node is owned here
  std::vector<std::uint8_t> alive_;  // [n_tie] 1: holds, 2: holds until the next cycle (eroded)
  std::int64_t n_alive_ = 0;
  double dissipation_ = 0;
  V3 force_;  // on the slave group, N
};

}  // namespace ncfsim::fem
