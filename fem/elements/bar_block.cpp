// GCC 12 reports false maybe-uninitialized warnings inside its own AVX-512 intrinsics (the
// undefined pass-through operand of the masked sqrt) when it inlines std::experimental::simd.
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#include "fem/elements/bar_block.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "fem/errors.hpp"
#include "fem/elements/simd_batch.hpp"

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

// Names the first bar whose force or strain is not finite, with its mid-point (the blow-up report).
[[noreturn]] void throw_non_finite_bar(const BarBlock& b, const double* x) {
  for (std::size_t e = 0; e < b.n; ++e) {
    if (std::isfinite(b.force[e]) && std::isfinite(b.strain[e])) continue;
    const auto i = 3 * static_cast<std::size_t>(b.conn[e]),
               j = 3 * static_cast<std::size_t>(b.conn[b.n + e]);
    std::ostringstream os;
    os << "bar " << b.user_id[e] << " (part " << b.part << ") has a non-finite force at ("
       << 0.5 * (x[i] + x[j]) << ", " << 0.5 * (x[i + 1] + x[j + 1]) << ", "
       << 0.5 * (x[i + 2] + x[j + 2]) << ") m";
    throw NumericalError(os.str());
  }
  throw NumericalError("bar part " + std::to_string(b.part) +
                       " produced a non-finite work increment");
}

void bar_internal_forces(BarBlock& b, const double* x, double* f, ElementEnergyIncrement& energy,
                         StableStep& step) {
  // Batched: W bars per SIMD register for the strain, law and force; the node gathers are per
  // lane and the force scatter runs per chunk as a plain loop (nodes shared by consecutive bars
  // then chain through the store buffer without stalling the vector work).
  using batch::load;
  using batch::store;
  using batch::VD;
  using batch::W;
  namespace stdx = batch::stdx;
  constexpr int BC = 256;  // bars per chunk
  static_assert(BC % W == 0, "chunk must hold whole SIMD batches");
  const std::size_t n = b.n;
  const BarForceLaw& law = *b.law;
  const double* ts = law.strains().data();
  const double* tf = law.forces().data();
  const double* tk = law.slopes().data();
  const int n_seg = static_cast<int>(law.slopes().size());
  const bool tension_only = law.tension_only();
  const std::int32_t* c0 = b.conn.data();
  const std::int32_t* c1 = b.conn.data() + n;
  const double* L0p = b.length0.data();
  const double* dtc = b.dt_crit.data();
  double* eps_p = b.strain.data();
  double* F_p = b.force.data();
  alignas(64) double sx[BC], sy[BC], sz[BC];  // axial force vector of each bar of the chunk
  VD w = 0.0;
  const std::size_t e_end = std::min(n, b.range_end);
  for (std::size_t e0 = b.range_begin; e0 < e_end; e0 += BC) {
    const int m = static_cast<int>(std::min<std::size_t>(BC, e_end - e0));
    for (int k = 0; k < m; k += W) {
      const int cnt = std::min(W, m - k);
      const std::size_t e = e0 + static_cast<std::size_t>(k);
      std::size_t ii[W], jj[W];
      for (int l = 0; l < W; ++l) {
        const std::size_t q = e + static_cast<std::size_t>(l < cnt ? l : cnt - 1);
        ii[l] = 3 * static_cast<std::size_t>(c0[q]), jj[l] = 3 * static_cast<std::size_t>(c1[q]);
      }
      const VD dx([&](auto l) { return x[jj[l]] - x[ii[l]]; });
      const VD dy([&](auto l) { return x[jj[l] + 1] - x[ii[l] + 1]; });
      const VD dz([&](auto l) { return x[jj[l] + 2] - x[ii[l] + 2]; });
      const VD L = stdx::sqrt(dx * dx + dy * dy + dz * dz);
      const VD L0 = load(L0p + e, cnt);
      const VD eps = L / L0 - 1.0;
      // Table segment: the last one starting below the strain, as BarForceLaw::force.
      VD Fs = tf[0], ks = tk[0], es = ts[0];
      for (int i = 1; i < n_seg; ++i) {
        const auto above = eps > ts[i];
        stdx::where(above, Fs) = tf[i];
        stdx::where(above, ks) = tk[i];
        stdx::where(above, es) = ts[i];
      }
      VD F = Fs + ks * (eps - es);
      if (tension_only) stdx::where(eps <= 0.0, F) = 0.0;
      w += batch::live(0.5 * (F + load(F_p + e, cnt)) * (eps - load(eps_p + e, cnt)) * L0, cnt);
      store(eps_p + e, eps, cnt);
      store(F_p + e, F, cnt);
      const VD s = F / L;
      batch::store_a(sx + k, s * dx), batch::store_a(sy + k, s * dy), batch::store_a(sz + k, s * dz);
      if (stdx::any_of(load(dtc + e, cnt) < step.dt))  // rare: scan in element order
        for (int l = 0; l < cnt; ++l)
          if (dtc[e + l] < step.dt) step = {dtc[e + l], b.user_id[e + l], ElementKind::Bar2};
    }
    for (int k = 0; k < m; ++k) {
      const std::size_t i = 3 * static_cast<std::size_t>(c0[e0 + k]), j = 3 * static_cast<std::size_t>(c1[e0 + k]);
      f[i] += sx[k], f[i + 1] += sy[k], f[i + 2] += sz[k];
      f[j] -= sx[k], f[j + 1] -= sy[k], f[j + 2] -= sz[k];
    }
  }
  const double wsum = stdx::reduce(w);
  if (!std::isfinite(wsum)) throw_non_finite_bar(b, x);
  energy.internal += wsum;
}

}  // namespace ncfsim::fem
