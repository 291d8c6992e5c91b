#pragma once
// The macro (homogenised) membrane law of a biaxial dry fabric for shells: two fibre families
// convected with the deformation and free to turn against each other (their angle change is the
// shear angle), stiff in fibre tension, nearly free in fibre compression, and an in-plane shear
// resistance tabulated as the normalised shear force of a picture frame against the shear angle
// (its rise is the shear locking). The curve may differ with the sign of the shear: positive
// shear closes the angle between the families around material axis 1 (the wale, the stitch
// direction of an NCF: the tricot stitch is stretched), negative shear opens it. One curve for
// both signs is the classic symmetric macro law; two curves give a macro law that shows the
// shear bias of a stitched fabric. docs/theory.md, "Macro fabric membrane law".
//
// Hyperelastic: per unit reference area W = sum_k K(e_k) e_k^2 / 2 + int_0^g F_sh(g') cos g' dg',
// with e_k the stretch of family k minus one, g = asin(a1.a2) the shear angle of the unit
// convected directions a_k = F A_k / |F A_k|. The power of the picture frame is F_sh cos(g) g' per
// unit area (Harrison's normalisation), so the frame force of a macro frame reproduces F_sh.
// Membrane force (per unit current length):
//   N = (1/J) [ sum_k K e_k (1 + e_k) a_k a_k + F_sh(g) (a1 a2 + a2 a1 - sin g (a1 a1 + a2 a2)) ].
#include <array>
#include <string>
#include <vector>

#include "fem/membrane_law.hpp"

namespace ncfsim::drape {

/// Normalised shear force (N/m) against shear angle (rad), piecewise linear through the origin,
/// extrapolated with the last slope.
class ShearCurve {
 public:
  ShearCurve() = default;
  /// Angles (rad) strictly increasing from 0 (prepended when absent with force 0); forces at
  /// the angles. Throws std::invalid_argument on a bad table.
  ShearCurve(std::vector<double> angle, std::vector<double> force);
  double force(double angle) const;
  double max_slope() const { return max_slope_; }
  const std::vector<double>& angles() const { return angle_; }
  const std::vector<double>& forces() const { return force_; }
  bool empty() const { return angle_.empty(); }

 private:
  std::vector<double> angle_, force_, slope_;
  double max_slope_ = 0;
};

struct FabricMembraneConstants {
  double areal_density = 0;               // kg/m^2
  std::array<double, 2> fibre_angles{};   // rad, from material axis 1
  double fibre_tension_stiffness = 0;     // N/m per family (force per width per strain)
  double fibre_compression_ratio = 1e-3;  // compression stiffness / tension stiffness
  double bending_stiffness = 0;           // N m (moment per width per curvature)
  ShearCurve positive;                    // g > 0
  ShearCurve negative;                    // g < 0 (force magnitude at |g|); empty: positive's
};

class FabricMembraneLaw final : public fem::MembraneLaw {
 public:
  /// Throws std::invalid_argument naming the bad constant.
  FabricMembraneLaw(std::string name, FabricMembraneConstants c);
  const std::string& name() const override { return name_; }
  double areal_density() const override { return c_.areal_density; }
  double membrane_stiffness() const override { return c_.fibre_tension_stiffness; }
  double bending_stiffness() const override { return c_.bending_stiffness; }
  std::array<double, 2> fibre_angles() const override { return c_.fibre_angles; }
  void update(const fem::MembraneBatch& b) const override;
  /// Normalised shear force at signed shear angle g (rad).
  double shear_force(double g) const;
  const FabricMembraneConstants& constants() const { return c_; }

 private:
  std::string name_;
  FabricMembraneConstants c_;
};

}  // namespace ncfsim::drape
