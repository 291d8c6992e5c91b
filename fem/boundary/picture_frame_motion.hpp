#pragma once
// The picture frames of a model (fem/boundary/picture_frame.hpp) as a boundary motion: the
// clamped nodes follow the rigid arms, the arms as walls push the edge nodes.
#include <cstdint>
#include <vector>

#include "fem/boundary/boundary_motion.hpp"
#include "fem/boundary/picture_frame.hpp"

namespace ncfsim::fem {

class PictureFrameMotion final : public BoundaryMotion {
 public:
  /// Borrows the frames (Model::picture_frames), which outlive it.
  explicit PictureFrameMotion(const std::vector<PictureFrame>& frames);
  void check(std::size_t n_nodes) const override;
  std::size_t n_driven_sets() const override { return frames_.size(); }
  const std::vector<std::int32_t>& driven_nodes(std::size_t i) const override {
    return frames_[i].nodes;
  }
  void bind_dof(std::size_t set, std::size_t k, std::size_t d, const double* x0) override;
  void velocities(double t, double* v) override;
  bool has_forces() const override { return has_walls_; }
  void add_forces(double t, const double* x, const double* mass, double dt, double* f) override;
  void add_force_work(double t_old, double t_new, double dt_old, double dt_new, double& source_old,
                      double& source_new, double& on_nodes_old, double& on_nodes_new) override;

  /// Power (W) the walls of frame k put into the nodes at t^{n+1/2} of the last cycle.
  double wall_power(std::size_t k) const { return k < wall_power_.size() ? wall_power_[k] : 0.0; }
  /// Nodes in contact with the walls of frame k in the last cycle.
  std::int64_t wall_contacts(std::size_t k) const {
    return k < wall_active_.size() ? wall_active_[k] : 0;
  }

 private:
  const std::vector<PictureFrame>& frames_;
  struct FrameDof {
    std::size_t k = 0;  // the solver's constrained DOF
    std::int32_t frame = -1;
    std::uint8_t component = 0;
    double xi = 0, eta = 0;  // reference coordinates along the frame's arms
  };
  std::vector<FrameDof> dofs_;
  std::vector<V3> c1_, c2_;  // per frame: d(u1)/dt, d(u2)/dt this cycle
  struct WallContact {
    std::int32_t frame = -1;
    double xi = 0, eta = 0;  // frame coordinates of the contact point on the arm
    V3 force;                // on the node, at t^n
  };
  std::vector<WallContact> wall_contacts_;  // this cycle's
  std::vector<double> wall_power_;
  std::vector<std::int64_t> wall_active_;
  bool has_walls_ = false;
};

}  // namespace ncfsim::fem
