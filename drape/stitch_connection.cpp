#include "drape/stitch_connection.hpp"

#include <cmath>
#include <stdexcept>

#include "fem/errors.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::drape {

StitchToTowConnection::StitchToTowConnection(std::string name, std::vector<StitchConnection> pairs,
                                             StitchConnectionSettings s)
    : name_(std::move(name)), s_(s) {
  if (!(s.sliding_force > 0)) throw std::invalid_argument("sliding_force must be > 0");
  if (!(s.stiffness >= 0)) throw std::invalid_argument("stiffness must be >= 0");
  if (!(s.stiffness_scale > 0 && s.stiffness_scale <= 1)) throw std::invalid_argument("stiffness_scale must be in (0, 1]");
  for (const auto& p : pairs) a_.push_back(p.stitch_node), b_.push_back(p.tow_node);
}

void StitchToTowConnection::initialise(const fem::ContactSetup& setup) {
  const std::size_t n = a_.size(), nn = setup.mesh->n_nodes();
  d0_.assign(3 * n, 0.0);
  slip_.assign(3 * n, 0.0);
  k_.assign(n, 0.0);
  force_.assign(n, 0.0);
  slip_len_.assign(n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    const auto a = static_cast<std::size_t>(a_[i]), b = static_cast<std::size_t>(b_[i]);
    if (a >= nn || b >= nn || a == b) throw InputError("", name_, "connection joins an invalid node pair");
    for (int c = 0; c < 3; ++c) d0_[3 * i + static_cast<std::size_t>(c)] = setup.x0[3 * b + static_cast<std::size_t>(c)] - setup.x0[3 * a + static_cast<std::size_t>(c)];
    const double m = std::min(setup.mass[3 * a], setup.mass[3 * b]);
    const double k_stable = s_.stiffness_scale * m / (setup.dt * setup.dt);
    k_[i] = s_.stiffness > 0 ? std::min(s_.stiffness, k_stable) : k_stable;
  }
}

void StitchToTowConnection::add_forces(const double* x, const double*, const double*, double, double* fc) {
  const std::size_t n = a_.size();
  const double Fs = s_.sliding_force;
  double diss = 0;
  std::int64_t sliding = 0;
  fem::V3 total{};
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t a = static_cast<std::size_t>(a_[i]), b = static_cast<std::size_t>(b_[i]);
    double d[3];
    for (int c = 0; c < 3; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      d[c] = x[3 * b + cc] - x[3 * a + cc] - d0_[3 * i + cc] - slip_[3 * i + cc];
    }
    const double k = k_[i];
    double f = k * std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (f > Fs) {  // return mapping: the slider moves until the spring carries Fs
      const double ds = (f - Fs) / k, inv = 1.0 / (f / k);
      for (int c = 0; c < 3; ++c) {
        const auto cc = static_cast<std::size_t>(c);
        slip_[3 * i + cc] += ds * d[c] * inv;
        d[c] *= Fs / f;
      }
      diss += Fs * ds;
      slip_len_[i] += ds;
      f = Fs;
      ++sliding;
    }
    force_[i] = f;
    for (int c = 0; c < 3; ++c) {
      const auto cc = static_cast<std::size_t>(c);
      const double fk = k * d[c];  // pulls a towards b and b towards a
      fc[3 * a + cc] += fk;
      fc[3 * b + cc] -= fk;
    }
    total += fem::V3{k * d[0], k * d[1], k * d[2]};
  }
  dissipated_ += diss;
  n_sliding_ = sliding;
  total_ = total;
}

std::vector<fem::ContactResultant> StitchToTowConnection::resultants() const { return {{name_, total_}}; }

}  // namespace ncfsim::drape
