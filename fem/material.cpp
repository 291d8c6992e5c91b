#include "fem/material.hpp"

#include <Eigen/Dense>
#include <stdexcept>

namespace ncfsim::fem {

ElasticIsotropic::ElasticIsotropic(std::string name, double density, double E, double nu)
    : name_(std::move(name)), rho_(density) {
  if (!(density > 0)) throw std::invalid_argument("density must be > 0");
  if (!(E > 0)) throw std::invalid_argument("Young's modulus must be > 0");
  if (!(nu > -1.0 && nu < 0.5)) throw std::invalid_argument("Poisson's ratio must be in (-1, 0.5)");
  mu_ = E / (2 * (1 + nu));
  lambda_ = E * nu / ((1 + nu) * (1 - 2 * nu));
}

Voigt6x6 ElasticIsotropic::elastic_stiffness() const {
  Voigt6x6 C{};
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) C[6 * i + j] = lambda_;
    C[6 * i + i] += 2 * mu_;
    C[6 * (i + 3) + i + 3] = mu_;
  }
  return C;
}

void ElasticIsotropic::update_stress(const MaterialBatch& b) const {
  const std::size_t s = b.stride, t = b.strain_stride;
  const double* __restrict de = b.strain_increment;
  double* __restrict sig = b.stress;
  const double lam = lambda_, mu2 = 2 * mu_, mu = mu_;
  for (std::size_t e = 0; e < b.n; ++e) {
    const double tr = de[e] + de[t + e] + de[2 * t + e];
    sig[e] += lam * tr + mu2 * de[e];
    sig[s + e] += lam * tr + mu2 * de[t + e];
    sig[2 * s + e] += lam * tr + mu2 * de[2 * t + e];
    sig[3 * s + e] += mu * de[3 * t + e];
    sig[4 * s + e] += mu * de[4 * t + e];
    sig[5 * s + e] += mu * de[5 * t + e];
  }
}

Voigt6x6 orthotropic_stiffness(const OrthotropicConstants& c) {
  for (double v : {c.E1, c.E2, c.E3, c.G12, c.G13, c.G23})
    if (!(v > 0)) throw std::invalid_argument("orthotropic moduli must all be > 0");
  Eigen::Matrix<double, 6, 6> S = Eigen::Matrix<double, 6, 6>::Zero();
  S(0, 0) = 1 / c.E1;
  S(1, 1) = 1 / c.E2;
  S(2, 2) = 1 / c.E3;
  S(0, 1) = S(1, 0) = -c.nu12 / c.E1;
  S(0, 2) = S(2, 0) = -c.nu13 / c.E1;
  S(1, 2) = S(2, 1) = -c.nu23 / c.E2;
  S(3, 3) = 1 / c.G12;
  S(4, 4) = 1 / c.G23;
  S(5, 5) = 1 / c.G13;
  Eigen::LLT<Eigen::Matrix<double, 6, 6>> llt(S);
  if (llt.info() != Eigen::Success)
    throw std::invalid_argument(
        "orthotropic constants are not positive definite (check nu12^2 < E1/E2 etc.)");
  Eigen::Matrix<double, 6, 6> C = S.inverse();
  Voigt6x6 out{};
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) out[6 * i + j] = C(i, j);
  return out;
}

ElasticOrthotropic::ElasticOrthotropic(std::string name, double density,
                                       const OrthotropicConstants& c)
    : name_(std::move(name)), rho_(density), C_(orthotropic_stiffness(c)) {
  if (!(density > 0)) throw std::invalid_argument("density must be > 0");
}

void ElasticOrthotropic::update_stress(const MaterialBatch& b) const {
  const std::size_t s = b.stride, t = b.strain_stride;
  const double* __restrict de = b.strain_increment;
  double* __restrict sig = b.stress;
  const double c11 = C_[0], c12 = C_[1], c13 = C_[2], c22 = C_[7], c23 = C_[8], c33 = C_[14];
  const double g12 = C_[21], g23 = C_[28], g13 = C_[35];
  for (std::size_t e = 0; e < b.n; ++e) {
    const double d1 = de[e], d2 = de[t + e], d3 = de[2 * t + e];
    sig[e] += c11 * d1 + c12 * d2 + c13 * d3;
    sig[s + e] += c12 * d1 + c22 * d2 + c23 * d3;
    sig[2 * s + e] += c13 * d1 + c23 * d2 + c33 * d3;
    sig[3 * s + e] += g12 * de[3 * t + e];
    sig[4 * s + e] += g23 * de[4 * t + e];
    sig[5 * s + e] += g13 * de[5 * t + e];
  }
}

std::array<double, 6> directional_moduli(const Voigt6x6& Cv, const std::array<double, 9>& axes) {
  Eigen::Matrix<double, 6, 6> C;
  for (int i = 0; i < 6; ++i)
    for (int j = 0; j < 6; ++j) C(i, j) = Cv[6 * i + j];
  const Eigen::Matrix<double, 6, 6> S = C.inverse();
  auto axis = [&](int k) { return Eigen::Vector3d(axes[k], axes[3 + k], axes[6 + k]); };
  // Voigt stress of the tensor sym(a b^T + b a^T)/2 scaled: tensor T -> [T11 T22 T33 T12 T23 T13]
  auto to_voigt = [](const Eigen::Matrix3d& T) {
    Eigen::Matrix<double, 6, 1> v;
    v << T(0, 0), T(1, 1), T(2, 2), T(0, 1), T(1, 2), T(0, 2);
    return v;
  };
  auto strain_tensor = [](const Eigen::Matrix<double, 6, 1>& e) {  // engineering -> tensor
    Eigen::Matrix3d T;
    T << e(0), e(3) / 2, e(5) / 2, e(3) / 2, e(1), e(4) / 2, e(5) / 2, e(4) / 2, e(2);
    return T;
  };
  std::array<double, 6> out{};
  for (int i = 0; i < 3; ++i) {  // uniaxial stress along axis i
    const Eigen::Vector3d a = axis(i);
    const Eigen::Matrix3d sig = a * a.transpose();
    const Eigen::Matrix3d eps = strain_tensor(S * to_voigt(sig));
    out[i] = 1.0 / a.dot(eps * a);
  }
  const int pairs[3][2] = {{0, 1}, {1, 2}, {0, 2}};
  for (int p = 0; p < 3; ++p) {  // pure shear stress on the plane of the pair
    const Eigen::Vector3d a = axis(pairs[p][0]), c = axis(pairs[p][1]);
    const Eigen::Matrix3d sig = a * c.transpose() + c * a.transpose();
    const Eigen::Matrix3d eps = strain_tensor(S * to_voigt(sig));
    out[3 + p] = 1.0 / (2.0 * a.dot(eps * c));
  }
  return out;
}

}  // namespace ncfsim::fem
