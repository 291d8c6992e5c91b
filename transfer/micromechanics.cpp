#include "transfer/micromechanics.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ncfsim::transfer {

namespace {

void require_positive(double v, const char* what) {
  if (!(v > 0) || !std::isfinite(v))
    throw std::invalid_argument(std::string(what) + ": must be > 0 (got " + std::to_string(v) +
                                ")");
}

double chamis_modulus(double vf, double matrix, double fibre) {
  return matrix / (1.0 - std::sqrt(vf) * (1.0 - matrix / fibre));
}

double chamis_strength(double vf, double matrix_strength, double matrix_modulus,
                       double fibre_modulus) {
  return (1.0 - (std::sqrt(vf) - vf) * (1.0 - matrix_modulus / fibre_modulus)) * matrix_strength;
}

}  // namespace

void validate(const FibreData& f) {
  require_positive(f.E1, "fibre E1");
  require_positive(f.E2, "fibre E2");
  require_positive(f.G12, "fibre G12");
  require_positive(f.G23, "fibre G23");
  require_positive(f.tensile_strength, "fibre tensile_strength");
  require_positive(f.density, "fibre density");
  if (!(f.nu12 >= 0 && f.nu12 < 0.5))
    throw std::invalid_argument("fibre nu12: must be in [0, 0.5) (got " + std::to_string(f.nu12) +
                                ")");
}

void validate(const ResinData& r) {
  require_positive(r.E, "resin E");
  require_positive(r.tensile_strength, "resin tensile_strength");
  require_positive(r.shear_strength, "resin shear_strength");
  require_positive(r.density, "resin density");
  if (!(r.nu >= 0 && r.nu < 0.5))
    throw std::invalid_argument("resin nu: must be in [0, 0.5) (got " + std::to_string(r.nu) + ")");
}

ImpregnatedTow impregnated_tow(const FibreData& f, const ResinData& r, double vf,
                               double compressive_ratio) {
  validate(f);
  validate(r);
  if (!(vf > 0 && vf <= kMaxFibreVolumeFraction))
    throw std::invalid_argument(
        "fibre volume fraction: must be in (0, 0.9069] (hexagonal packing; got " +
        std::to_string(vf) + ")");
  if (!(compressive_ratio > 0 && compressive_ratio <= 1.5))
    throw std::invalid_argument("compressive_ratio: must be in (0, 1.5] (got " +
                                std::to_string(compressive_ratio) + ")");
  const double Gm = r.E / (2 * (1 + r.nu));
  ImpregnatedTow t;
  t.fibre_volume_fraction = vf;
  t.density = vf * f.density + (1 - vf) * r.density;
  auto& e = t.elastic;
  e.E1 = vf * f.E1 + (1 - vf) * r.E;
  e.nu12 = vf * f.nu12 + (1 - vf) * r.nu;
  e.E2 = chamis_modulus(vf, r.E, f.E2);
  e.E3 = e.E2;
  e.G12 = chamis_modulus(vf, Gm, f.G12);
  e.G13 = e.G12;
  e.G23 = chamis_modulus(vf, Gm, f.G23);
  e.nu13 = e.nu12;
  e.nu23 = e.E2 / (2 * e.G23) - 1;
  auto& s = t.strength;
  const double eps_fu = f.tensile_strength / f.E1;
  s.Xt = vf * f.tensile_strength + (1 - vf) * r.E * eps_fu;
  s.Yt = chamis_strength(vf, r.tensile_strength, r.E, f.E2);
  s.S12 = chamis_strength(vf, r.shear_strength, Gm, f.G12);
  s.S23 = chamis_strength(vf, r.shear_strength, Gm, f.G23);
  s.Xc = compressive_ratio * s.Xt;
  s.Yc = compressive_ratio * s.Yt;
  return t;
}

double compacted_fibre_volume_fraction(double vf0, double J, double fibre_stretch) {
  if (!(J > 0) || !(fibre_stretch > 0))
    throw std::invalid_argument(
        "compacted_fibre_volume_fraction: volume ratio and stretch must be > 0");
  return vf0 * fibre_stretch / J;
}

}  // namespace ncfsim::transfer
