#pragma once
// The membrane law interface of shell elements whose in-plane response is not a plane-stress
// continuum (a dry fabric: two fibre families that shear freely until they lock). Called once
// per batch of shells (never per element) with each shell's in-plane deformation gradient; the
// law returns the membrane stress resultant. Bending and transverse shear of such shells are
// linear elastic with the law's bending modulus (a fabric bends as fibres sliding on each other,
// far below its membrane stiffness: fem/elements/shell4_block.hpp).
#include <array>
#include <cstddef>
#include <string>

namespace ncfsim::fem {

struct MembraneBatch {
  std::size_t n = 0;       // shells in the batch
  std::size_t stride = 0;  // distance between components of every array
  // [4][stride] in-plane deformation gradient F = dx/dX at the shell centre, from the shell's
  // reference in-plane frame to its current one, row-major (F11, F12, F21, F22). Rigid motions
  // give a rotation: a law must be objective in it (a function of F^T F and the convected
  // directions F A).
  const double* F = nullptr;
  // [4][stride] reference material directions A1 (x, y), A2 (x, y) in the reference in-plane
  // frame, unit vectors (a fabric's two fibre families).
  const double* axes = nullptr;
  // [3][stride] out: membrane force per unit current length N11, N22, N12 in the current
  // in-plane frame (N/m; the Cauchy stress times the thickness).
  double* resultant = nullptr;
  double* history = nullptr;  // [n_history][stride], updated in place
};

class MembraneLaw {
 public:
  virtual ~MembraneLaw() = default;
  virtual const std::string& name() const = 0;
  /// Mass per unit area (kg/m^2).
  virtual double areal_density() const = 0;
  /// The stiffest membrane tangent the law can reach, force per unit length (N/m): with the
  /// areal density it sets the stable step.
  virtual double membrane_stiffness() const = 0;
  /// Bending stiffness per unit width (N m): moment per unit curvature.
  virtual double bending_stiffness() const = 0;
  /// Angles (rad) of the two fibre families from material axis 1 in the reference plane: the
  /// shear angle is 90 deg minus the angle between them once convected.
  virtual std::array<double, 2> fibre_angles() const = 0;
  virtual int n_history() const { return 0; }
  virtual void update(const MembraneBatch& batch) const = 0;
};

}  // namespace ncfsim::fem
