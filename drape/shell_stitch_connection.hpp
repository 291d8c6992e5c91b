#pragma once
// The slider that sews a macro stitch line to its shells (drape/shell_stitch.hpp): a spring
// between each stitch node and its point on the host shell (bilinear weights of the host's
// nodes). Along the stitch (the line's reference tangent convected by the host shell) the spring
// holds up to the sliding force, beyond which the yarn slides through the fabric: the slip is kept
// as a reference length along the line and moves the spring's anchor to the material point it
// reaches (weights linear in the slip, so the forces on the host's nodes are those of a spring
// between two points, with no follower terms). Across the line and out of the plane it stays
// elastic: the stitch stays sewn to its row of the fabric. A clamp or a frame holds a line's end
// nodes directly (node selector shell_stitch_ends), not through their sliders.
// Implemented as a contact of the engine: forces into the contact forces (they sum to zero),
// the slip work into friction_dissipation.
#include <cstdint>
#include <string>
#include <vector>

#include "drape/shell_stitch.hpp"
#include "fem/contact_interface.hpp"

namespace ncfsim::drape {

struct ShellStitchSliderSettings {
  double sliding_force = 0.1;  // N per stitch node (> 0; the reader scales it by the node's share)
  double stiffness_scale = 0.1;  // k = scale * min(m_stitch, m_point) / dt^2: never lowers the step
};

class StitchToShellConnection final : public fem::ContactAlgorithm {
 public:
  StitchToShellConnection(std::string name, std::vector<ShellStitchLink> links,
                          ShellStitchSliderSettings s);
  const std::string& name() const override { return name_; }
  void initialise(const fem::ContactSetup& setup) override;
  double estimated_bytes(const fem::Mesh& mesh, bool erosion) const override;
  void add_forces(const double* x, const double* v, const double* mass, double dt,
                  double* f_contact) override;
  double friction_dissipation() const override { return dissipated_; }
  std::int64_t active_contacts() const override { return n_sliding_; }
  /// For the run's log: the links this rank computes, and in words the lines, the links sliding
  /// in the last cycle and the slip work so far.
  std::size_t n_contact_nodes() const override;
  std::string cost_details() const override;
  /// Several ranks: a link is computed where its stitch node is owned; it reads its host's nodes.
  bool nodes_to_read(const std::uint8_t* owned, const double* x0, double halo,
                     std::vector<std::int32_t>& out) const override;
  void restrict_to_rank(const std::uint8_t* owned, const std::uint8_t* readable) override;
  void save_state(fem::CheckpointWriter& w) const override;
  void load_state(fem::CheckpointReader& r) override;

  std::size_t size() const { return links_.size(); }
  /// Slip of link i along its line so far (m of the line's reference length, signed: along
  /// the direction given to the stitch positive).
  double slip(std::size_t i) const { return slip_[i]; }
  double stiffness(std::size_t i) const { return k_[i]; }

 private:
  std::string name_;
  ShellStitchSliderSettings s_;
  std::vector<ShellStitchLink> links_;
  std::vector<double> k_, slip_;
  std::vector<std::uint8_t> mine_;  // several ranks: [n] 1 where this rank computes the link
  double dissipated_ = 0;
  std::int64_t n_sliding_ = 0;
};

}  // namespace ncfsim::drape
