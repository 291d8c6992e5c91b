#pragma once
// Impregnated-tow properties from fibre and resin datasheet values at the tow's fibre volume
// fraction Vf (a transversely isotropic tow, axis 1 along the fibres):
//   E1   = Vf Ef1 + (1 - Vf) Em                               rule of mixtures
//   nu12 = Vf nuf12 + (1 - Vf) num                            rule of mixtures
//   E2   = Em / (1 - sqrt(Vf) (1 - Em / Ef2))                  Chamis (1989), E3 = E2
//   G12  = Gm / (1 - sqrt(Vf) (1 - Gm / Gf12))                 Chamis, G13 = G12
//   G23  = Gm / (1 - sqrt(Vf) (1 - Gm / Gf23))                 Chamis, nu23 = E2 / (2 G23) - 1
//   rho  = Vf rho_f + (1 - Vf) rho_m
// Chamis' square-root law is chosen over Halpin-Tsai because it needs no fitted reinforcing
// factor and is the form NASA's ICAN and most lamina datasheets use; at Vf 0.6 the two differ by
// a few per cent for carbon/epoxy (docs/theory.md).
// Strengths in the tow frame:
//   Xt = Vf sigma_fu + (1 - Vf) Em eps_fu                      fibre-dominated (matrix at the fibre
//   failure strain) Yt = [1 - (sqrt(Vf) - Vf) (1 - Em / Ef2)] sigma_mt          Chamis S12 = [1 -
//   (sqrt(Vf) - Vf) (1 - Gm / Gf12)] tau_m           Chamis, S23 likewise with Gf23 Xc =
//   compressive_ratio Xt, Yc = compressive_ratio Yt (the paper's ~60 %; a case key)
#include <string>

#include "fem/material.hpp"

namespace ncfsim::transfer {

/// Fibre datasheet values (e.g. Toray T700S). Pa, kg/m^3.
struct FibreData {
  double E1 = 230e9;   // axial modulus
  double E2 = 15e9;    // transverse modulus (carbon fibres are anisotropic)
  double G12 = 27e9;   // axial shear modulus
  double G23 = 5.5e9;  // transverse shear modulus
  double nu12 = 0.2;
  double tensile_strength = 4.9e9;
  double density = 1800;
};

/// Cured resin datasheet values (isotropic). Pa, kg/m^3.
struct ResinData {
  double E = 3.4e9;
  double nu = 0.36;
  double tensile_strength = 80e6;
  double shear_strength = 52e6;
  double density = 1170;
};

/// Strengths in the tow frame, Pa (all positive).
struct TowStrengths {
  double Xt = 0, Xc = 0;  // along the fibres
  double Yt = 0, Yc = 0;  // across (in-plane and through the thickness alike)
  double S12 = 0;         // axial (in-plane and transverse-axial) shear
  double S23 = 0;         // transverse shear
};

struct ImpregnatedTow {
  double fibre_volume_fraction = 0;
  double density = 0;
  fem::OrthotropicConstants elastic{};
  TowStrengths strength;
};

/// Largest fibre volume fraction of round fibres (hexagonal packing), pi / (2 sqrt 3).
constexpr double kMaxFibreVolumeFraction = 0.9069;

/// Throws std::invalid_argument naming the quantity and its allowed range.
void validate(const FibreData& f);
void validate(const ResinData& r);

/// The impregnated tow at fibre volume fraction vf in (0, 0.9069]; compressive strengths are
/// `compressive_ratio` (0, 1.5] of the tensile ones.
ImpregnatedTow impregnated_tow(const FibreData& f, const ResinData& r, double vf,
                               double compressive_ratio = 0.6);

/// Fibre volume fraction after a deformation at constant fibre content: the fibres keep their
/// length (inextensible at drape forces) and the tow's cross-section changes by J / lambda_1
/// (volume ratio over fibre stretch), so vf = vf0 lambda_1 / J.
double compacted_fibre_volume_fraction(double vf0, double volume_ratio_J,
                                       double fibre_stretch = 1.0);

}  // namespace ncfsim::transfer
