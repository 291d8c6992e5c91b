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
  require(c.E11f_axial >= 0, "E11f_axial must be >= 0");
  C_ = fem::orthotropic_stiffness(m);  // throws if the matrix phase is not positive definite
  C_bend_ = C_;
  C_bend_[0] += c.E11f;
  C_[0] += c.E11f_axial > 0 ? c.E11f_axial : c.E11f;
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

void TowMaterial::update_stress(const fem::MaterialBatch& b) const {
  const std::size_t s = b.stride, t = b.strain_stride;
  const double* __restrict de = b.strain_increment;
  double* __restrict sig = b.stress;
  double* __restrict E = b.history;  // total Green-Lagrange strain [6][stride]
  const fem::Voigt6x6& C = C_;
  for (std::size_t e = 0; e < b.n; ++e) {
    double Ev[6], S[6];
    fem::accumulate_strain_orthotropic_stress(C, de, t, E, s, e, Ev, S);
    add_compaction_stress(Ev, S);
    for (int k = 0; k < 6; ++k) sig[k * s + e] = S[k];
  }
}

CompactionMeasure TowMaterial::compaction_measure(const double* Ev) {
  // C = I + 2E (Voigt 11 22 33 12 23 13, engineering shears): C12 = gamma12 etc.
  const double C11 = 1 + 2 * Ev[0], C22 = 1 + 2 * Ev[1], C33 = 1 + 2 * Ev[2];
  const double C12 = Ev[3], C23 = Ev[4], C13 = Ev[5];
  // Adjugate of C (symmetric); C^-1 = adj / det.
  const double A11 = C22 * C33 - C23 * C23, A22 = C11 * C33 - C13 * C13, A33 = C11 * C22 - C12 * C12;
  const double A12 = C13 * C23 - C12 * C33, A13 = C12 * C23 - C13 * C22, A23 = C12 * C13 - C11 * C23;
  const double det = C11 * A11 + C12 * A12 + C13 * A13;
  CompactionMeasure m;
  // The spacing of the material planes X2 = const (they hold the fibres and the thickness
  // direction) is lambda_2 = 1 / sqrt((C^-1)_22): E2 = (lambda_2^2 - 1) / 2; dE2/dE = m2 (x) m2
  // with m2 = C^-1 e2 / (C^-1)_22. Likewise for the planes X3 = const.
  m.E2 = 0.5 * (det / A22 - 1);
  m.E3 = 0.5 * (det / A33 - 1);
  m.m2 = {A12 / A22, 1.0, A23 / A22};
  m.m3 = {A13 / A33, A23 / A33, 1.0};
  return m;
}

void TowMaterial::add_compaction_stress(const double* Ev, double* S) const {
  if (c_.compaction_modulus == 0) return;
  if (Ev[1] >= 0 && Ev[2] >= 0 && (!c_.compaction_of_fibre_sheets || (Ev[3] == 0 && Ev[4] == 0 && Ev[5] == 0))) return;
  const CompactionMeasure cm =
      c_.compaction_of_fibre_sheets ? compaction_measure(Ev) : CompactionMeasure{Ev[1], Ev[2], {0, 1, 0}, {0, 0, 1}};
  for (int d = 0; d < 2; ++d) {
    const double sc = compaction_stress(d == 0 ? cm.E2 : cm.E3);
    if (sc == 0) continue;
    const auto& m = d == 0 ? cm.m2 : cm.m3;
    S[0] += sc * m[0] * m[0];
    S[1] += sc * m[1] * m[1];
    S[2] += sc * m[2] * m[2];
    S[3] += sc * m[0] * m[1];
    S[4] += sc * m[1] * m[2];
    S[5] += sc * m[0] * m[2];
  }
}

}  // namespace ncfsim::drape
