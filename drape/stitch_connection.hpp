#pragma once
// Stitch-to-tow connection elements: each joins a stitch node to a tow node with an elastic spring
// up to a sliding force, beyond which the stitch slides on the tow (a frictional slider, the force
// stays at the sliding force; the slip and the energy it dissipates are tracked). The sliding force
// comes from the tow pull-out test. Implemented as a contact of the engine: its forces go to the
// contact forces, the spring energy and the slip work into the contact energy, the slip work also
// into friction_dissipation.
#include <string>
#include <vector>

#include "drape/fabric_generator.hpp"
#include "fem/contact_interface.hpp"

namespace ncfsim::drape {

struct StitchConnectionSettings {
  double sliding_force = 0.05;    // N per connection (> 0), docs/fabric-data.md
  double stiffness = 0;           // N/m; 0: the stability limit below
  double stiffness_scale = 0.1;   // k <= scale * min(m_a, m_b) / dt^2: never lowers the stable step
};

class StitchToTowConnection final : public fem::ContactAlgorithm {
 public:
  StitchToTowConnection(std::string name, std::vector<StitchConnection> pairs, StitchConnectionSettings s);
  const std::string& name() const override { return name_; }
  void initialise(const fem::ContactSetup& setup) override;
  void add_forces(const double* x, const double* v, const double* mass, double dt, double* f_contact) override;
  double friction_dissipation() const override { return dissipated_; }
  std::int64_t active_contacts() const override { return n_sliding_; }
  std::vector<fem::ContactResultant> resultants() const override;

  /// Slip of each connection so far (m), for output and tests.
  double slip_length(std::size_t i) const { return slip_len_[i]; }
  double force_magnitude(std::size_t i) const { return force_[i]; }
  /// Spring stiffness in use (N/m): the requested one, capped by the stability limit.
  double stiffness(std::size_t i) const { return k_[i]; }
  std::size_t size() const { return a_.size(); }

 private:
  std::string name_;
  StitchConnectionSettings s_;
  std::vector<std::int32_t> a_, b_;     // stitch node, tow node
  std::vector<double> d0_;              // [3*n] reference offset b - a
  std::vector<double> slip_;            // [3*n] slider position
  std::vector<double> k_;               // [n]
  std::vector<double> force_, slip_len_;
  double dissipated_ = 0;
  std::int64_t n_sliding_ = 0;
  fem::V3 total_{};
};

}  // namespace ncfsim::drape
