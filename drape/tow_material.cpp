#include "drape/tow_material.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ncfsim::drape {

namespace {
void require(bool ok, const std::string& what) {
  if (!ok) throw std::invalid_argument(what);
}
}  // namespace

TowMaterial::TowMaterial(std::string name, const TowConstants& c) : name_(std::move(name)), c_(c) {
  require(c.density > 0, "density must be > 0");
  require(c.E11f >= 0, "E11f must be >= 0");
  for (double v : {c.E11m, c.E22m, c.E33m, c.G12m, c.G13m, c.G23m})
    require(v > 0, "matrix-phase moduli E11m E22m E33m G12m G13m G23m must be > 0");
  require(c.compaction_modulus >= 0, "compaction_modulus must be >= 0");
  require(c.locking_width_ratio > 0 && c.locking_width_ratio < 1, "locking_width_ratio must be in (0, 1)");
  require(c.lock_stiffness_ratio >= 1, "lock_stiffness_ratio must be >= 1");
  fem::OrthotropicConstants m{c.E11m, c.E22m, c.E33m, c.nu12m, c.nu13m, c.nu23m, c.G12m, c.G13m, c.G23m};
  C_ = fem::orthotropic_stiffness(m);  // throws if the matrix phase is not positive definite
  C_[0] += c.E11f;
  const double l = c.locking_width_ratio;
  e_lock_ = 0.5 * (1 - l * l);
  // Tangent E_c/(1-r)^2 reaches the cap at r_cap.
  r_cap_ = 1.0 - 1.0 / std::sqrt(c.lock_stiffness_ratio);
}

double TowMaterial::compaction_stress(double E) const {
  if (E >= 0 || c_.compaction_modulus == 0) return 0.0;
  const double r = -E / e_lock_;
  const double Ec = c_.compaction_modulus;
  if (r <= r_cap_) return -Ec * e_lock_ * (r / (1 - r) - r);
  const double s_cap = -Ec * e_lock_ * (r_cap_ / (1 - r_cap_) - r_cap_);
  const double k_cap = Ec * (1.0 / ((1 - r_cap_) * (1 - r_cap_)) - 1.0);  // extra tangent at the cap
  return s_cap - k_cap * e_lock_ * (r - r_cap_);
}

double TowMaterial::compaction_tangent(double E) const {
  if (E >= 0 || c_.compaction_modulus == 0) return 0.0;
  const double r = std::min(-E / e_lock_, r_cap_);
  return c_.compaction_modulus * (1.0 / ((1 - r) * (1 - r)) - 1.0);
}

fem::Voigt6x6 TowMaterial::stable_step_stiffness() const {
  fem::Voigt6x6 C = C_;
  const double extra = c_.compaction_modulus * (c_.lock_stiffness_ratio - 1.0);
  C[7] += extra;
  C[14] += extra;
  return C;
}

double TowMaterial::p_wave_modulus() const {
  const auto C = stable_step_stiffness();
  return std::max({C[0], C[7], C[14]});
}

void TowMaterial::update_stress(const fem::MaterialBatch& b) const {
  const std::size_t s = b.stride, t = b.strain_stride;
  const double* __restrict de = b.strain_increment;
  double* __restrict sig = b.stress;
  double* __restrict E = b.history;  // total Green-Lagrange strain [6][stride]
  const fem::Voigt6x6& C = C_;
  for (std::size_t e = 0; e < b.n; ++e) {
    double Ev[6];
    for (int k = 0; k < 6; ++k) {
      E[k * s + e] += de[k * t + e];
      Ev[k] = E[k * s + e];
    }
    for (int i = 0; i < 3; ++i)
      sig[i * s + e] = C[6 * i] * Ev[0] + C[6 * i + 1] * Ev[1] + C[6 * i + 2] * Ev[2];
    sig[s + e] += compaction_stress(Ev[1]);
    sig[2 * s + e] += compaction_stress(Ev[2]);
    sig[3 * s + e] = C[21] * Ev[3];
    sig[4 * s + e] = C[28] * Ev[4];
    sig[5 * s + e] = C[35] * Ev[5];
  }
}

}  // namespace ncfsim::drape
