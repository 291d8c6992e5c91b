#include "fem/boundary/picture_frame_motion.hpp"

#include <algorithm>
#include <cmath>

#include "fem/errors.hpp"

namespace ncfsim::fem {

namespace {
// Velocity of the frame's material point (xi, eta) at time t (d/dt of corner + xi u1 + eta u2).
V3 frame_point_velocity(const PictureFrame& pf, double t, double xi, double eta) {
  const double g = picture_frame_angle(pf, t), gd = 0.5 * picture_frame_rate(pf, t);
  const double cs = std::cos(0.5 * g), sn = std::sin(0.5 * g);
  return gd * (xi * (-sn * pf.arm1 + cs * pf.arm2) + eta * (cs * pf.arm1 - sn * pf.arm2));
}
}  // namespace

PictureFrameMotion::PictureFrameMotion(const std::vector<PictureFrame>& frames) : frames_(frames) {
  c1_.resize(frames_.size());
  c2_.resize(frames_.size());
  wall_power_.assign(frames_.size(), 0.0);
  wall_active_.assign(frames_.size(), 0);
  for (const auto& pf : frames_)
    for (const auto& w : pf.walls) has_walls_ = has_walls_ || !w.empty();
}

void PictureFrameMotion::check(std::size_t n) const {
  for (const auto& pf : frames_)
    if (!(std::abs(dot(pf.arm1, pf.arm1) - 1) < 1e-9 &&
          std::abs(dot(pf.arm2, pf.arm2) - 1) < 1e-9 && std::abs(dot(pf.arm1, pf.arm2)) < 1e-9))
      throw InputError("", "boundary.picture_frame." + pf.name,
                       "the arms must be orthogonal unit vectors");
  for (const auto& pf : frames_) {
    if (!(pf.wall_penalty_scale > 0 && pf.wall_penalty_scale <= 1))
      throw InputError("", "boundary.picture_frame." + pf.name + ".wall_penalty_scale",
                       "must be in (0, 1]");
    for (const auto& w : pf.walls)
      for (auto node : w)
        if (node < 0 || static_cast<std::size_t>(node) >= n)
          throw InputError("", "boundary.picture_frame." + pf.name, "wall node outside the mesh");
  }
}

void PictureFrameMotion::bind_dof(std::size_t set, std::size_t k, std::size_t d, const double* x0) {
  const auto& pf = frames_[set];
  const V3 r = V3::at(x0 + 3 * (d / 3)) - pf.corner;
  dofs_.push_back({k, static_cast<std::int32_t>(set), static_cast<std::uint8_t>(d % 3),
                   dot(r, pf.arm1), dot(r, pf.arm2)});
}

void PictureFrameMotion::velocities(double t, double* v) {
  for (std::size_t k = 0; k < frames_.size(); ++k) {  // d(u1)/dt, d(u2)/dt at t
    const auto& pf = frames_[k];
    const double g = picture_frame_angle(pf, t), gd = 0.5 * picture_frame_rate(pf, t);
    const double cs = std::cos(0.5 * g), sn = std::sin(0.5 * g);
    c1_[k] = gd * (-sn * pf.arm1 + cs * pf.arm2);
    c2_[k] = gd * (cs * pf.arm1 - sn * pf.arm2);
  }
  for (const FrameDof& fd : dofs_) {
    const auto f = static_cast<std::size_t>(fd.frame);
    v[fd.k] = (fd.xi * c1_[f] + fd.eta * c2_[f]).arr()[fd.component];
  }
}

void PictureFrameMotion::add_forces(double t, const double* x, const double* mass, double dt,
                                    double* fc) {
  wall_contacts_.clear();
  const double inv_dt2 = 1.0 / (dt * dt);
  for (std::size_t k = 0; k < frames_.size(); ++k) {
    const auto& pf = frames_[k];
    wall_active_[k] = 0;
    if (pf.walls[0].empty() && pf.walls[1].empty()) continue;
    const double g = picture_frame_angle(pf, t);
    const double cs = std::cos(0.5 * g), sn = std::sin(0.5 * g);
    const V3 u1 = cs * pf.arm1 + sn * pf.arm2, u2 = sn * pf.arm1 + cs * pf.arm2;
    const double s = std::sin(g), c = std::cos(g), L = pf.arm_length;
    // In-plane unit normals: n1 to the arms along u1 (pointing towards +eta), n2 to those along u2.
    const V3 n1 = (1.0 / c) * (u2 - s * u1), n2 = (1.0 / c) * (u1 - s * u2);
    for (int w = 0; w < 2; ++w)
      for (auto node : pf.walls[static_cast<std::size_t>(w)]) {
        const auto i = static_cast<std::size_t>(node);
        const V3 r = V3::at(x + 3 * i) - pf.corner;
        const double b1 = dot(r, u1), b2 = dot(r, u2);
        const double xi = (b1 - s * b2) / (c * c), eta = (b2 - s * b1) / (c * c);
        // Signed distances to the two arms of this pair (positive inside the frame).
        const double q = w == 0 ? eta : xi, along = w == 0 ? xi : eta;
        if (along < 0 || along > L) continue;  // the arms are bars from pin to pin
        const double d_lo = q * c, d_hi = (L - q) * c;
        double depth = 0, sign = 0;
        if (d_lo < 0)
          depth = -d_lo, sign = 1;
        else if (d_hi < 0)
          depth = -d_hi, sign = -1;
        else
          continue;
        const double k_pen = pf.wall_penalty_scale * mass[3 * i] * inv_dt2;
        const V3 F = (sign * k_pen * depth) * (w == 0 ? n1 : n2);
        fc[3 * i] += F.x, fc[3 * i + 1] += F.y, fc[3 * i + 2] += F.z;
        WallContact wc;
        wc.frame = static_cast<std::int32_t>(k);
        wc.xi = w == 0 ? xi : (sign > 0 ? 0.0 : L);
        wc.eta = w == 0 ? (sign > 0 ? 0.0 : L) : eta;
        wc.force = F;
        wall_contacts_.push_back(wc);
        ++wall_active_[k];
      }
  }
}

// The walls are kinematically driven like velocity tools, so their work on the nodes is the
// frame's (external) work; the contact energy keeps the penalty energy stored.
void PictureFrameMotion::add_force_work(double t_old, double t_new, double dt_old, double dt_new,
                                        double& source_old, double& source_new,
                                        double& on_nodes_old, double& on_nodes_new) {
  std::fill(wall_power_.begin(), wall_power_.end(), 0.0);
  for (const auto& wc : wall_contacts_) {
    const auto& pf = frames_[static_cast<std::size_t>(wc.frame)];
    const double p_old = dot(wc.force, frame_point_velocity(pf, t_old, wc.xi, wc.eta));
    const double p_new = dot(wc.force, frame_point_velocity(pf, t_new, wc.xi, wc.eta));
    wall_power_[static_cast<std::size_t>(wc.frame)] += p_new;
    source_old += dt_old * p_old, source_new += dt_new * p_new;
    on_nodes_old += dt_old * p_old, on_nodes_new += dt_new * p_new;
  }
}

}  // namespace ncfsim::fem
