#include "impact/tow_damage_material.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ncfsim::impact {

namespace {

void require_positive(double v, const std::string& what) {
  if (!(v > 0) || !std::isfinite(v))
    throw std::invalid_argument(what + ": must be > 0 (got " + std::to_string(v) + ")");
}

}  // namespace

TowDamageMaterial::TowDamageMaterial(std::string name, const TowDamageConstants& c)
    : name_(std::move(name)), c_(c) {
  require_positive(c.density, "density");
  require_positive(c.default_length, "default_length");
  if (!(c.residual_compression >= 0 && c.residual_compression < 1))
    throw std::invalid_argument("residual_compression: must be in [0, 1) (got " +
                                std::to_string(c.residual_compression) + ")");
  const auto& s = c.strength;
  strength_ = {s.Xt, s.Xc, s.Yt, s.Yc, s.S12, s.S23};
  static constexpr std::array<const char*, kModes> kStrengthNames{"Xt", "Xc",  "Yt",
                                                                  "Yc", "S12", "S23"};
  for (int m = 0; m < kModes; ++m) {
    require_positive(strength_[static_cast<std::size_t>(m)],
                     kStrengthNames[static_cast<std::size_t>(m)]);
    require_positive(c.fracture_energy[static_cast<std::size_t>(m)],
                     std::string("fracture_energy_") + kModeNames[static_cast<std::size_t>(m)]);
  }
  for (int m = 0; m < kModes; ++m)
    erode_[static_cast<std::size_t>(m)] = c.erode_on[static_cast<std::size_t>(m)] ? 1.0 : 0.0;
  C_ = fem::orthotropic_stiffness(c.elastic);  // throws unless positive definite
  const auto& e = c.elastic;
  modulus_ = {e.E1, e.E1, e.E2, e.E2, e.G12, e.G23};
  for (int m = 0; m < kModes; ++m) {
    const auto k = static_cast<std::size_t>(m);
    rf_length_[k] = 2 * c.fracture_energy[k] * modulus_[k] / (strength_[k] * strength_[k]);
  }
  if (c.raise_to_crack_band) rf_floor_ = kRaisedFailureRatio;
}

double TowDamageMaterial::raised_energy_factor(FailureMode m, double L) const {
  if (!c_.raise_to_crack_band) return 1.0;
  return std::max(1.0, rf_floor_ * L / rf_length_[static_cast<std::size_t>(m)]);
}

double TowDamageMaterial::max_element_length(FailureMode m) const {
  return rf_length_[static_cast<std::size_t>(m)];
}

void TowDamageMaterial::update_stress(const fem::MaterialBatch& b) const {
  const std::size_t s = b.stride, t = b.strain_stride;
  const double* __restrict de = b.strain_increment;
  double* __restrict sig = b.stress;
  double* __restrict h = b.history;  // [18][stride]: E (6), r (6), d (6)
  const double* len = b.length;      // [3][stride] or null
  const fem::Voigt6x6& C = C_;
  const double L0 = c_.default_length;
  for (std::size_t e = 0; e < b.n; ++e) {
    double E[6], S[6];  // total strain, effective (undamaged) stress
    fem::accumulate_strain_orthotropic_stress(C, de, t, h, s, e, E, S);
    const double L1 = len ? len[e] : L0, L2 = len ? len[s + e] : L0, L3 = len ? len[2 * s + e] : L0;
    // Failure indices and the length across each mode's crack.
    // Fibre compression: kinking (Argon, the linearised LaRC03 criterion with sigma_22 = 0): the
    // fibres misaligned by phi0 = S12 / Xc kink when the shear in their frame, |s11| phi0 + |tau|,
    // reaches S12; pure compression fails at Xc, axial shear brings it on earlier.
    const double tau = std::sqrt(S[3] * S[3] + S[5] * S[5]);
    const double kink = S[0] < 0 ? -S[0] / strength_[1] + tau / strength_[4] : 0.0;
    const double f[kModes] = {std::max(S[0], 0.0) / strength_[0],
                              kink,
                              std::max({S[1], S[2], 0.0}) / strength_[2],
                              std::max({-S[1], -S[2], 0.0}) / strength_[3],
                              std::sqrt(S[3] * S[3] + S[5] * S[5]) / strength_[4],
                              std::abs(S[4]) / strength_[5]};
    // Normal-stress matrix modes crack across the axis whose stress governs.
    const double Lm_t = S[1] >= S[2] ? L2 : L3, Lm_c = S[1] <= S[2] ? L2 : L3;
    const double L[kModes] = {L1, L1, Lm_t, Lm_c, L2, L2};
    double d[kModes];
    for (int m = 0; m < kModes; ++m) {
      double& r = h[(6 + m) * s + e];
      r = std::max({r, f[m], 1.0});
      const double rf = std::max(rf_length_[static_cast<std::size_t>(m)] / L[m], rf_floor_);
      const double dm = std::min(1.0, (1.0 - 1.0 / r) / (1.0 - 1.0 / rf));
      // damage never heals (the length of a crushed element may change its r_f)
      d[m] = h[(12 + m) * s + e] = std::max(h[(12 + m) * s + e], dm);
    }
    double failed = 0;
    for (int m = 0; m < kModes; ++m)
      failed = std::max(failed, erode_[static_cast<std::size_t>(m)] * d[m]);
    h[kFailedRow * s + e] = failed >= 1.0 ? 1.0 : 0.0;
    const double d1 = S[0] >= 0 ? d[0] : d[1];
    const double d2 = S[1] >= 0 ? d[2] : d[3];
    const double d3 = S[2] >= 0 ? d[2] : d[3];
    const double keep_axial_shear = (1 - d[4]) * (1 - d[2]) * (1 - d[0]);
    const double keep_transverse_shear = (1 - d[5]) * (1 - d[2]);
    // Crushed in compression: at least the residual plateau (0 unless given).
    const double R1 = c_.residual_compression * strength_[1],
                 R2 = c_.residual_compression * strength_[3];
    sig[e] = S[0] < 0 ? std::min((1 - d1) * S[0], -std::min(-S[0], R1)) : (1 - d1) * S[0];
    sig[s + e] = S[1] < 0 ? std::min((1 - d2) * S[1], -std::min(-S[1], R2)) : (1 - d2) * S[1];
    sig[2 * s + e] = S[2] < 0 ? std::min((1 - d3) * S[2], -std::min(-S[2], R2)) : (1 - d3) * S[2];
    sig[3 * s + e] = keep_axial_shear * S[3];
    sig[4 * s + e] = keep_transverse_shear * S[4];
    sig[5 * s + e] = keep_axial_shear * S[5];
  }
}

}  // namespace ncfsim::impact
