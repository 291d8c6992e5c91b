#pragma once
// The solid material interface. A material is called once per batch of elements (never per
// element): it receives Green-Lagrange strain increments in the reference material axes (which
// convect with the deformation gradient, so fibre directions follow the fabric) and updates the
// 2nd Piola-Kirchhoff stress and its history in place. Voigt order 11, 22, 33, 12, 23, 13 with
// engineering shear strains.
#include <array>
#include <cstddef>
#include <memory>
#include <string>

namespace ncfsim::fem {

using Voigt6x6 = std::array<double, 36>;  // row-major

struct MaterialBatch {
  std::size_t n = 0;                         // elements in the batch
  std::size_t stride = 0;                    // distance between components of stress and history
  std::size_t strain_stride = 0;             // distance between components of strain_increment
  const double* strain_increment = nullptr;  // [6][strain_stride], material frame, borrowed
  double* stress = nullptr;                  // [6][stride], material frame, updated in place
  double* history = nullptr;                 // [n_history][stride], updated in place
  // [3][stride] reference element lengths along the material axes (m), borrowed; null where the
  // caller has none. Damage laws regularise their softening with them (crack band).
  const double* length = nullptr;
  double dt = 0.0;
};

class SolidMaterial {
 public:
  virtual ~SolidMaterial() = default;
  virtual const std::string& name() const = 0;
  virtual double density() const = 0;
  /// Initial elastic stiffness in the material frame.
  virtual Voigt6x6 elastic_stiffness() const = 0;
  /// Stiffness of the linearly varying strain fields, i.e. of bending (the physical hourglass
  /// stabilisation of one-point elements): the elastic one unless the law separates them (a
  /// dry tow bends as a bundle of fibres sliding on each other, far below its axial stiffness).
  virtual Voigt6x6 bending_stiffness() const { return elastic_stiffness(); }
  /// The stiffest tangent the law can reach (e.g. a compacted tow): bounds the stable step.
  virtual Voigt6x6 stable_step_stiffness() const { return elastic_stiffness(); }
  virtual int n_history() const { return 0; }
  /// History row that flags a failed element (a value >= 1: the engine erodes it at the end of
  /// the cycle); -1: the law never fails an element.
  virtual int failure_history_row() const { return -1; }
  virtual void update_stress(const MaterialBatch& batch) const = 0;
};

/// Hooke's law, isotropic.
class ElasticIsotropic final : public SolidMaterial {
 public:
  ElasticIsotropic(std::string name, double density, double youngs_modulus, double poisson_ratio);
  const std::string& name() const override { return name_; }
  double density() const override { return rho_; }
  Voigt6x6 elastic_stiffness() const override;
  void update_stress(const MaterialBatch& b) const override;

 private:
  std::string name_;
  double rho_, lambda_, mu_;
};

struct OrthotropicConstants {
  double E1, E2, E3, nu12, nu13, nu23, G12, G13, G23;
};

/// Orthotropic Hooke's law in the convected material frame.
class ElasticOrthotropic final : public SolidMaterial {
 public:
  ElasticOrthotropic(std::string name, double density, const OrthotropicConstants& c);
  const std::string& name() const override { return name_; }
  double density() const override { return rho_; }
  Voigt6x6 elastic_stiffness() const override { return C_; }
  void update_stress(const MaterialBatch& b) const override;

 private:
  std::string name_;
  double rho_;
  Voigt6x6 C_{};
};

/// One element of a batch whose law is a function of the total Green-Lagrange strain kept in the
/// first six history rows: adds the increment to it (E [6], out) and gives the orthotropic stress
/// C E (S [6]; C has no normal-shear coupling, as every law here in the material frame).
inline void accumulate_strain_orthotropic_stress(const Voigt6x6& C, const double* __restrict de,
                                                 std::size_t t, double* __restrict history,
                                                 std::size_t s, std::size_t e, double E[6],
                                                 double S[6]) {
  for (int k = 0; k < 6; ++k) {
    history[k * s + e] += de[k * t + e];
    E[k] = history[k * s + e];
  }
  for (int i = 0; i < 3; ++i) S[i] = C[6 * i] * E[0] + C[6 * i + 1] * E[1] + C[6 * i + 2] * E[2];
  S[3] = C[21] * E[3];
  S[4] = C[28] * E[4];
  S[5] = C[35] * E[5];
}

/// Stiffness from engineering constants; throws std::invalid_argument if not positive definite.
Voigt6x6 orthotropic_stiffness(const OrthotropicConstants& c);

/// Uniaxial moduli E1..E3 and shear moduli G12, G23, G13 seen along the axes of a frame whose
/// axes, expressed in the material frame, are the columns of `axes` (row-major 3x3).
std::array<double, 6> directional_moduli(const Voigt6x6& C, const std::array<double, 9>& axes);

}  // namespace ncfsim::fem
