#pragma once
// Impregnated tow with progressive damage, in the convected tow frame (axis 1 along the fibres;
// Voigt 11 22 33 12 23 13, engineering shears). Orthotropic elastic (the transfer's constants),
// then per failure mode m:
//   initiation on the effective stress s = C0 E (maximum stress, modes kept apart):
//     fibre_tension       f = <s11>+ / Xt
//     fibre_compression   f = <s11>- / Xc + sqrt(s12^2 + s13^2) / S12 where s11 < 0 (kinking:
//                         fibres misaligned by S12 / Xc fail when the shear in their frame
//                         reaches S12; the linearised LaRC03 criterion; pure compression: Xc)
//     matrix_tension      f = max(<s22>+, <s33>+) / Yt
//     matrix_compression  f = max(<s22>-, <s33>-) / Yc
//     in_plane_shear      f = sqrt(s12^2 + s13^2) / S12      transverse_shear  f = |s23| / S23
//   softening: r_m = max over the history of f_m; past r_m = 1 the damage grows linearly in the
//   equivalent strain to full damage at r_f = 2 G_m E_m / (X_m^2 L_m) (crack band: G_m the
//   fracture energy per area, L_m the element's length across the crack, E_m the modulus of the
//   mode), d_m = (1 - 1/r_m) / (1 - 1/r_f), so that a uniaxial (or pure-shear) path peaks at the
//   strength and dissipates G_m / L_m per volume whatever the mesh. r_f must exceed 1: the element
//   must be short enough not to snap back, L_m < 2 G_m E_m / X_m^2 (checked: the case refuses a
//   longer one, or with `raise_to_crack_band` gives it the smallest energy free of snap-back,
//   r_f = kRaisedFailureRatio, G = kRaisedFailureRatio X_m^2 L_m / (2 E_m), reported).
//   degradation: s11 (1 - d_ft or d_fc by its sign), s22 and s33 (1 - d_mt or d_mc by their signs),
//   a compressive one held at least at min(|C E|, residual_compression x Xc or Yc) (crush plateau),
//   s12 and s13 (1 - d_s12)(1 - d_mt)(1 - d_ft): a cracked matrix and broken fibres carry no axial
//   shear; s23 (1 - d_s23)(1 - d_mt).
// History per element [kHistory][stride]: total strain (6), r per mode (6), d per mode (6), failed
// (1 once a mode in `erode_on` is fully damaged: the engine erodes the element).
// The element lengths along the material axes come with the batch (MaterialBatch::length); a
// batch without them uses `default_length`.
#include <array>
#include <string>

#include "fem/material.hpp"

namespace ncfsim::impact {

enum class FailureMode {
  FibreTension,
  FibreCompression,
  MatrixTension,
  MatrixCompression,
  InPlaneShear,
  TransverseShear
};
constexpr int kModes = 6;
/// r_f of an element longer than its crack band when the law raises its energy (the failure
/// strain 0.1 % past the initiation strain: the steepest softening that does not snap back).
constexpr double kRaisedFailureRatio = 1.001;
/// Result-field names, in FailureMode order (damage_<name>, failed_fraction_<name>).
constexpr std::array<const char*, kModes> kModeNames{"fibre_tension",  "fibre_compression",
                                                     "matrix_tension", "matrix_compression",
                                                     "in_plane_shear", "transverse_shear"};

struct TowStrength {
  double Xt = 0, Xc = 0, Yt = 0, Yc = 0, S12 = 0, S23 = 0;  // Pa, all > 0
};

/// Fracture energies per unit crack area (J/m^2), per mode in FailureMode order.
using FractureEnergies = std::array<double, kModes>;

struct TowDamageConstants {
  double density = 0;
  fem::OrthotropicConstants elastic{};
  TowStrength strength;
  FractureEnergies fracture_energy{};
  double default_length = 1e-3;  // m, used when a batch brings no element lengths
  /// Modes whose full damage fails the element (eroded by the engine): by default the fibre
  /// modes (a tow whose matrix has cracked still carries its fibres).
  std::array<bool, kModes> erode_on{true, true, false, false, false, false};
  std::string fracture_energy_key;  // case-file key of the fracture energies, for messages
  /// Share of the compressive strength (Xc along the fibres, Yc across) a fully crushed tow still
  /// carries, [0, 1): its compressive stress never falls below min(|C E|, share x strength). A
  /// crushed composite keeps bearing (the crush plateau); with 0 a tow failed in compression
  /// carries nothing and collapses under a punch. Elastic on the way back (no energy created).
  double residual_compression = 0;
  /// An element longer across a crack than 2 G E / X^2: false, the case refuses it
  /// (check_crack_band); true (`crack_band = "raise"`), its energy in that mode is raised to
  /// kRaisedFailureRatio X^2 L / (2 E), from its current length, element by element.
  bool raise_to_crack_band = false;
};

class TowDamageMaterial final : public fem::SolidMaterial {
 public:
  static constexpr int kHistory = 19;
  static constexpr int kDamageRow = 12;  // d of mode m in row kDamageRow + m
  static constexpr int kFailedRow = 18;
  /// Throws std::invalid_argument naming the constant and its allowed range.
  TowDamageMaterial(std::string name, const TowDamageConstants& c);
  const std::string& name() const override { return name_; }
  double density() const override { return c_.density; }
  fem::Voigt6x6 elastic_stiffness() const override { return C_; }
  int n_history() const override { return kHistory; }
  int failure_history_row() const override { return kFailedRow; }
  void update_stress(const fem::MaterialBatch& b) const override;

  /// The longest element (m) across a crack of mode m that does not snap back: 2 G E / X^2.
  double max_element_length(FailureMode m) const;
  /// The factor on the fracture energy of mode m the law applies to an element L long across
  /// its crack: 1 where L is within the crack band, above it when the law raises (else 1).
  double raised_energy_factor(FailureMode m, double L) const;
  const TowDamageConstants& constants() const { return c_; }

 private:
  std::string name_;
  TowDamageConstants c_;
  fem::Voigt6x6 C_{};
  std::array<double, kModes> strength_{}, modulus_{}, rf_length_{};
  double rf_floor_ = 1.0 + 1e-9;  // the smallest r_f (kRaisedFailureRatio when raising)
  std::array<double, kModes>
      erode_{};  // 1: the mode's full damage fails the element  // per mode; rf = rf_length / L
};

}  // namespace ncfsim::impact
