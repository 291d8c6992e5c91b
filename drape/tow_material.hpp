#pragma once
// Dry tow: the orthotropic bi-phase law of the paper's Eq. 1, C_tow = C_f + C_m, in the convected
// tow frame (axis 1 along the fibres), extended as the paper's conclusion asks: the transverse
// compaction stiffness rises nonlinearly as the tow is compacted and locks at a given width.
//
//   S = C_f E + C_m E + s_c(Ê2) m_2 (x) m_2 + s_c(Ê3) m_3 (x) m_3   (compaction_measure =
//   "fibre_sheet_spacing"; the default "transverse_strain" uses Ê2 = E22, m_2 = e_2, Ê3 = E33, m_3 = e_3)
//   C_f = E11f e_1 (x) e_1 (fibres carry only axial stress); optionally the uniform axial strain
//   (tow stretch) takes E11f_axial instead, E11f then setting only bending (bending_stiffness,
//   the physical hourglass stabilisation of the one-point hexahedra: docs/theory.md);
//   C_m = orthotropic matrix phase (E11m, E22m, E33m, nu12m, nu13m, nu23m, G12m, G13m, G23m);
//   Ê2 = (lambda_2^2 - 1)/2 with lambda_2 = 1/sqrt((C^-1)_22) the stretch of the SPACING of the
//   material planes X2 = const (fibre sheets stacked across the tow width), m_2 = C^-1 e_2 /
//   (C^-1)_22 = dÊ2/dE (hyperelastic); Ê3 likewise through the thickness. Without shear Ê2 = E22;
//   unlike E22 (the stretch of the transverse material LINE), Ê2 also sees the packing of fibres
//   that rotate against that line (intra-tow trellising): in the picture frame a tow compacted
//   by its neighbours otherwise escapes the locking through its soft G12m (docs/theory.md);
//   s_c(E) = 0 in tension; in compaction, with r = -E / E_lock (E_lock from the locking width),
//   s_c = -E_c E_lock (r / (1 - r) - r): zero slope at r = 0, the transverse tangent grows as
//   E_c / (1 - r)^2 and is capped at lock_stiffness_ratio * E_c past the cap (a stiff linear
//   continuation), so the explicit step stays bounded.
// The stress is a function of the total Green-Lagrange strain (elastic, path independent); the
// total strain is kept in the history (6 values per element).
#include <array>
#include <string>

#include "fem/material.hpp"

namespace ncfsim::drape {

struct TowConstants {
  double density = 0;           // kg/m^3 of the dry tow (fibre density x fibre volume fraction)
  double E11f = 0;              // Pa, fibre phase, axial (bending-calibrated, paper: 0.07 GPa)
  // Pa, fibre phase of the uniform axial strain (tow stretch) when it differs from the bending
  // one; 0: E11f in both (the paper's Eq. 1). E11f then sets only the bending stiffness.
  double E11f_axial = 0;
  double E11m = 0, E22m = 0, E33m = 0;   // Pa, matrix phase
  double nu12m = 0, nu13m = 0, nu23m = 0;
  double G12m = 0, G13m = 0, G23m = 0;   // Pa
  double compaction_modulus = 0;         // E_c, Pa: initial transverse compaction modulus
  double locking_width_ratio = 0.7;      // tow width at locking / initial width, (0, 1)
  double lock_stiffness_ratio = 50;      // cap of the compaction tangent / E_c, >= 1
  // Compaction strain: false (default, "transverse_strain"): E22 and E33, the stretch of the
  // transverse material lines; true ("fibre_sheet_spacing"): Ê2, Ê3, the spacing of the fibre
  // sheets, which also sees the packing by intra-tow trellising (see the header comment).
  bool compaction_of_fibre_sheets = false;
};

struct CompactionMeasure {
  double E2 = 0, E3 = 0;             // compaction strains across the width and the thickness
  std::array<double, 3> m2{}, m3{};  // their gradients: dE2/dE = m2 (x) m2
};

class TowMaterial final : public fem::SolidMaterial {
 public:
  /// Throws std::invalid_argument naming the constant and its allowed range.
  TowMaterial(std::string name, const TowConstants& c);
  const std::string& name() const override { return name_; }
  double density() const override { return c_.density; }
  fem::Voigt6x6 elastic_stiffness() const override { return C_; }
  fem::Voigt6x6 bending_stiffness() const override { return C_bend_; }
  fem::Voigt6x6 stable_step_stiffness() const override;
  int n_history() const override { return 6; }
  void update_stress(const fem::MaterialBatch& batch) const override;

  const TowConstants& constants() const { return c_; }
  /// Green-Lagrange compaction strain at locking (positive number).
  double locking_strain() const { return e_lock_; }
  /// Extra transverse stress of compaction at transverse Green-Lagrange strain E (<= 0 in compaction).
  double compaction_stress(double E) const;
  /// Its tangent dS/dE.
  double compaction_tangent(double E) const;
  /// Compaction strains of a total Green-Lagrange strain (Voigt, engineering shears).
  static CompactionMeasure compaction_measure(const double* E);
  /// Adds the compaction stress of the total strain Ev to the 2nd Piola-Kirchhoff stress S (Voigt).
  void add_compaction_stress(const double* Ev, double* S) const;

 private:
  std::string name_;
  TowConstants c_;
  fem::Voigt6x6 C_{};       // C_f + C_m, with the axial fibre modulus
  fem::Voigt6x6 C_bend_{};  // C_f + C_m, with the bending fibre modulus E11f
  double e_lock_ = 0, r_cap_ = 0;
};

}  // namespace ncfsim::drape
