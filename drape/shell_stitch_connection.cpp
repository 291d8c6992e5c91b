#include "drape/shell_stitch_connection.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fem/checkpoint.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::drape {

StitchToShellConnection::StitchToShellConnection(std::string name,
                                                 std::vector<ShellStitchLink> links,
                                                 ShellStitchSliderSettings s)
    : name_(std::move(name)), s_(s), links_(std::move(links)) {
  if (!(s_.sliding_force > 0)) throw std::invalid_argument("sliding_force must be > 0");
  if (!(s_.stiffness_scale > 0 && s_.stiffness_scale <= 1))
    throw std::invalid_argument("stiffness_scale must be in (0, 1]");
}

// Per link its record (104 bytes), stiffness, slip and rank flag.
double StitchToShellConnection::estimated_bytes(const fem::Mesh& mesh, bool erosion) const {
  (void)mesh, (void)erosion;
  return 121.0 * static_cast<double>(links_.size());
}

void StitchToShellConnection::initialise(const fem::ContactSetup& setup) {
  const std::size_t n = links_.size(), nn = setup.mesh->n_nodes();
  k_.assign(n, 0.0);
  slip_.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto& l = links_[i];
    for (auto nd : l.host)
      if (nd < 0 || static_cast<std::size_t>(nd) >= nn)
        throw InputError("", name_, "a stitch link's host shell has an invalid node");
    if (l.stitch_node < 0 || static_cast<std::size_t>(l.stitch_node) >= nn)
      throw InputError("", name_, "a stitch link has an invalid stitch node");
    // The mass the spring sees at the shell point: 1 / sum(w^2 / m) over the host's nodes.
    double inv = 0;
    for (int k = 0; k < 4; ++k)
      inv += l.weight[k] * l.weight[k] / setup.mass[3 * static_cast<std::size_t>(l.host[k])];
    const double m = std::min(setup.mass[3 * static_cast<std::size_t>(l.stitch_node)], 1 / inv);
    k_[i] = s_.stiffness_scale * m / (setup.dt * setup.dt);
  }
}

void StitchToShellConnection::add_forces(const double* x, const double*, const double*, double,
                                         double* f) {
  n_sliding_ = 0;
  for (std::size_t i = 0; i < links_.size(); ++i) {
    if (!mine_.empty() && !mine_[i]) continue;  // another rank's
    const auto& l = links_[i];
    const auto a = 3 * static_cast<std::size_t>(l.stitch_node);
    // The anchor: the material point of the host a slip s along the line from the sewn point;
    // t: the line's reference tangent convected by the host (|t| = stretch along the line).
    double w[4], p[3] = {0, 0, 0}, t[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k) {
      w[k] = l.weight[k] + slip_[i] * l.slide[k];
      const auto h = 3 * static_cast<std::size_t>(l.host[k]);
      for (int d = 0; d < 3; ++d) p[d] += w[k] * x[h + d], t[d] += l.slide[k] * x[h + d];
    }
    double u[3];
    for (int d = 0; d < 3; ++d) u[d] = x[a + d] - p[d];
    const double tl = std::sqrt(t[0] * t[0] + t[1] * t[1] + t[2] * t[2]);
    if (tl > 0) {
      const double ut = (u[0] * t[0] + u[1] * t[1] + u[2] * t[2]) / tl;
      const double fs = s_.sliding_force * l.penetrations;
      const double limit = fs / k_[i];
      if (std::abs(ut) > limit) {
        const double ds = ut - std::copysign(limit, ut);  // m, in the current configuration
        slip_[i] += ds / tl;
        dissipated_ += fs * std::abs(ds);
        for (int k = 0; k < 4; ++k) w[k] = l.weight[k] + slip_[i] * l.slide[k];
        for (int d = 0; d < 3; ++d) u[d] -= ds * t[d] / tl;
        ++n_sliding_;
      }
    }
    const double fk[3] = {-k_[i] * u[0], -k_[i] * u[1], -k_[i] * u[2]};
    for (int d = 0; d < 3; ++d) f[a + d] += fk[d];
    for (int k = 0; k < 4; ++k) {
      const auto h = 3 * static_cast<std::size_t>(l.host[k]);
      for (int d = 0; d < 3; ++d) f[h + d] -= w[k] * fk[d];
    }
  }
}

std::size_t StitchToShellConnection::n_contact_nodes() const {
  if (mine_.empty()) return links_.size();
  return static_cast<std::size_t>(std::count(mine_.begin(), mine_.end(), std::uint8_t{1}));
}

std::string StitchToShellConnection::cost_details() const {
  std::size_t lines = 0;
  for (const auto& l : links_) lines += l.prev < 0 ? 1 : 0;
  return std::to_string(links_.size()) + " stitch links on " + std::to_string(lines) + " lines, " +
         std::to_string(n_sliding_) + " sliding in the last cycle, slip work " +
         fmt::format("{:.4g}", dissipated_) + " J";
}

bool StitchToShellConnection::nodes_to_read(const std::uint8_t* owned, const double*, double,
                                            std::vector<std::int32_t>& out) const {
  for (const auto& l : links_)
    if (owned[static_cast<std::size_t>(l.stitch_node)]) out.insert(out.end(), l.host.begin(), l.host.end());
  return true;
}

void StitchToShellConnection::restrict_to_rank(const std::uint8_t* owned, const std::uint8_t*) {
  mine_.assign(links_.size(), 0);
  for (std::size_t i = 0; i < links_.size(); ++i)
    mine_[i] = owned[static_cast<std::size_t>(links_[i].stitch_node)];
}

void StitchToShellConnection::save_state(fem::CheckpointWriter& w) const {
  w.write_int("n_links", static_cast<std::int64_t>(links_.size()));
  fem::save_array(w, "slip", slip_);
  w.write_double("dissipated", dissipated_);
  w.write_int("n_sliding", n_sliding_);
}

void StitchToShellConnection::load_state(fem::CheckpointReader& r) {
  r.check_int("n_links", static_cast<std::int64_t>(links_.size()));
  fem::load_array(r, "slip", slip_);
  dissipated_ = r.read_double("dissipated");
  n_sliding_ = r.read_int("n_sliding");
}

}  // namespace ncfsim::drape
