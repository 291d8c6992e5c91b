#include "fem/bar_block.hpp"

#include <cmath>
#include <stdexcept>

#include "fem/errors.hpp"

namespace ncfsim::fem {

BarForceLaw::BarForceLaw(std::string name, std::vector<double> strain, std::vector<double> force,
                         bool tension_only, double linear_density)
    : name_(std::move(name)), strain_(std::move(strain)), force_(std::move(force)),
      tension_only_(tension_only), rho_l_(linear_density) {
  if (strain_.size() < 2 || strain_.size() != force_.size())
    throw std::invalid_argument("a force-strain table needs at least 2 points of equal length");
  if (!(linear_density > 0)) throw std::invalid_argument("linear density must be > 0");
  bool has_zero = false;
  for (std::size_t i = 0; i < strain_.size(); ++i) {
    if (!std::isfinite(strain_[i]) || !std::isfinite(force_[i]))
      throw std::invalid_argument("force-strain table holds a non-finite value");
    if (i > 0 && !(strain_[i] > strain_[i - 1]))
      throw std::invalid_argument("strains of a force-strain table must strictly increase");
    if (strain_[i] == 0.0) has_zero = (force_[i] == 0.0) || has_zero;
  }
  slope_.resize(strain_.size() - 1);
  for (std::size_t i = 0; i + 1 < strain_.size(); ++i) {
    slope_[i] = (force_[i + 1] - force_[i]) / (strain_[i + 1] - strain_[i]);
    if (slope_[i] < 0) throw std::invalid_argument("force-strain table must not soften (slope < 0)");
    max_slope_ = std::max(max_slope_, slope_[i]);
  }
  if (!(max_slope_ > 0)) throw std::invalid_argument("force-strain table has no stiffness");
  if (!has_zero && !(strain_.front() > 0 && tension_only_))
    throw std::invalid_argument("force-strain table must pass through (0, 0)");
  if (strain_.front() > 0) {  // tension-only table starting above zero: prepend the origin
    strain_.insert(strain_.begin(), 0.0);
    force_.insert(force_.begin(), 0.0);
    slope_.insert(slope_.begin(), force_[1] / strain_[1]);
    max_slope_ = std::max(max_slope_, slope_.front());
  }
}

BarForceLaw BarForceLaw::linear(std::string name, double EA, bool tension_only, double rho_l) {
  if (!(EA > 0)) throw std::invalid_argument("axial stiffness must be > 0");
  return BarForceLaw(std::move(name), {-1.0, 0.0, 1.0}, {-EA, 0.0, EA}, tension_only, rho_l);
}

void bar_initialise(BarBlock& b, const double* x) {
  b.length0.resize(b.n);
  b.strain.assign(b.n, 0.0);
  b.force.assign(b.n, 0.0);
  b.dt_crit.resize(b.n);
  if (b.mass_scale.size() != b.n) b.mass_scale.assign(b.n, 1.0);
  const double rho_l = b.law->linear_density(), kmax = b.law->max_slope();
  for (std::size_t e = 0; e < b.n; ++e) {
    const auto i = static_cast<std::size_t>(b.conn[e]), j = static_cast<std::size_t>(b.conn[b.n + e]);
    const double dx = x[3 * j] - x[3 * i], dy = x[3 * j + 1] - x[3 * i + 1], dz = x[3 * j + 2] - x[3 * i + 2];
    const double L = std::sqrt(dx * dx + dy * dy + dz * dz);
    if (!(L > 0))
      throw NumericalError("bar " + std::to_string(b.user_id[e]) + " has zero length");
    b.length0[e] = L;
    // Two lumped masses m/2 on a spring k = slope/L: dt = sqrt(m/k) = L sqrt(rho_l/slope).
    b.dt_crit[e] = L * std::sqrt(b.mass_scale[e] * rho_l / kmax);
  }
}

void bar_lumped_mass(const BarBlock& b, double* mass) {
  const double rho_l = b.law->linear_density();
  for (std::size_t e = 0; e < b.n; ++e) {
    const double m = 0.5 * rho_l * b.mass_scale[e] * b.length0[e];
    for (int k = 0; k < 2; ++k) {
      const auto node = static_cast<std::size_t>(b.conn[k * b.n + e]);
      for (int c = 0; c < 3; ++c) mass[3 * node + c] += m;
    }
  }
}

void bar_internal_forces(BarBlock& b, const double* x, double* f, ElementEnergyIncrement& energy,
                         StableStep& step) {
  const std::size_t n = b.n;
  const BarForceLaw& law = *b.law;
  const std::int32_t* __restrict c0 = b.conn.data();
  const std::int32_t* __restrict c1 = b.conn.data() + n;
  double w = 0;
  for (std::size_t e = 0; e < n; ++e) {
    const auto i = static_cast<std::size_t>(c0[e]), j = static_cast<std::size_t>(c1[e]);
    const double dx = x[3 * j] - x[3 * i], dy = x[3 * j + 1] - x[3 * i + 1], dz = x[3 * j + 2] - x[3 * i + 2];
    const double L = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double L0 = b.length0[e];
    const double eps = L / L0 - 1.0;
    const double F = law.force(eps);
    w += 0.5 * (F + b.force[e]) * (eps - b.strain[e]) * L0;
    b.strain[e] = eps;
    b.force[e] = F;
    const double s = F / L;
    f[3 * i] += s * dx, f[3 * i + 1] += s * dy, f[3 * i + 2] += s * dz;
    f[3 * j] -= s * dx, f[3 * j + 1] -= s * dy, f[3 * j + 2] -= s * dz;
    if (b.dt_crit[e] < step.dt) step = {b.dt_crit[e], b.user_id[e], true};
  }
  if (!std::isfinite(w))
    throw NumericalError("bar part " + std::to_string(b.part) + " produced a non-finite force");
  energy.internal += w;
}

}  // namespace ncfsim::fem
