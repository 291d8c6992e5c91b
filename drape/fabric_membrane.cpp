// The macro fabric membrane law (drape/fabric_membrane.hpp).
#include "drape/fabric_membrane.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ncfsim::drape {

ShearCurve::ShearCurve(std::vector<double> angle, std::vector<double> force) {
  if (angle.size() != force.size() || angle.empty())
    throw std::invalid_argument("the shear curve needs as many forces as angles, at least one");
  if (angle.front() != 0) {
    if (!(angle.front() > 0)) throw std::invalid_argument("shear angles must be >= 0");
    angle.insert(angle.begin(), 0.0);
    force.insert(force.begin(), 0.0);
  } else if (force.front() != 0) {
    throw std::invalid_argument("the shear force at zero shear must be 0");
  }
  for (std::size_t i = 0; i < angle.size(); ++i) {
    if (!std::isfinite(angle[i]) || !std::isfinite(force[i]))
      throw std::invalid_argument("shear curve values must be finite");
    if (i > 0 && !(angle[i] > angle[i - 1]))
      throw std::invalid_argument("shear angles must increase strictly");
  }
  angle_ = std::move(angle), force_ = std::move(force);
  slope_.assign(angle_.size(), 0.0);
  for (std::size_t i = 0; i + 1 < angle_.size(); ++i) {
    slope_[i] = (force_[i + 1] - force_[i]) / (angle_[i + 1] - angle_[i]);
    max_slope_ = std::max(max_slope_, std::abs(slope_[i]));
  }
  if (angle_.size() >= 2) slope_.back() = slope_[angle_.size() - 2];
}

double ShearCurve::force(double g) const {
  const std::size_t n = angle_.size();
  if (n < 2) return 0.0;
  std::size_t i = 0;
  while (i + 2 < n && g > angle_[i + 1]) ++i;
  return force_[i] + slope_[i] * (g - angle_[i]);
}

FabricMembraneLaw::FabricMembraneLaw(std::string name, FabricMembraneConstants c)
    : name_(std::move(name)), c_(std::move(c)) {
  if (!(c_.areal_density > 0)) throw std::invalid_argument("areal_density must be > 0");
  if (!(c_.fibre_tension_stiffness > 0))
    throw std::invalid_argument("fibre_tension_stiffness must be > 0");
  if (!(c_.fibre_compression_ratio >= 0 && c_.fibre_compression_ratio <= 1))
    throw std::invalid_argument("fibre_compression_ratio must lie in [0, 1]");
  if (!(c_.bending_stiffness > 0)) throw std::invalid_argument("bending_stiffness must be > 0");
  if (c_.positive.empty()) throw std::invalid_argument("the shear curve is missing");
  const double d = std::remainder(c_.fibre_angles[0] - c_.fibre_angles[1], M_PI);
  if (std::abs(d) < 5 * M_PI / 180)
    throw std::invalid_argument("the two fibre families must not be (nearly) parallel");
}

double FabricMembraneLaw::shear_force(double g) const {
  if (g >= 0) return c_.positive.force(g);
  return -(c_.negative.empty() ? c_.positive : c_.negative).force(-g);
}

void FabricMembraneLaw::update(const fem::MembraneBatch& b) const {
  const std::size_t st = b.stride;
  const double K = c_.fibre_tension_stiffness, Kc = K * c_.fibre_compression_ratio;
  double cf[2], sf[2];
  for (int k = 0; k < 2; ++k)
    cf[k] = std::cos(c_.fibre_angles[static_cast<std::size_t>(k)]),
    sf[k] = std::sin(c_.fibre_angles[static_cast<std::size_t>(k)]);
  for (std::size_t e = 0; e < b.n; ++e) {
    const double F11 = b.F[e], F12 = b.F[st + e], F21 = b.F[2 * st + e], F22 = b.F[3 * st + e];
    const double m1x = b.axes[e], m1y = b.axes[st + e], m2x = b.axes[2 * st + e],
                 m2y = b.axes[3 * st + e];
    const double J = F11 * F22 - F12 * F21;
    double a[2][2], N[3] = {0, 0, 0};
    for (int k = 0; k < 2; ++k) {
      const double Ax = cf[k] * m1x + sf[k] * m2x, Ay = cf[k] * m1y + sf[k] * m2y;
      const double x = F11 * Ax + F12 * Ay, y = F21 * Ax + F22 * Ay;
      const double lam = std::sqrt(x * x + y * y);
      a[k][0] = x / lam, a[k][1] = y / lam;
      const double eps = lam - 1;
      const double T = (eps > 0 ? K : Kc) * eps * lam;  // W'(lam) lam
      N[0] += T * a[k][0] * a[k][0], N[1] += T * a[k][1] * a[k][1], N[2] += T * a[k][0] * a[k][1];
    }
    const double s = std::clamp(a[0][0] * a[1][0] + a[0][1] * a[1][1], -1.0, 1.0);
    const double Fs = shear_force(std::asin(s));
    N[0] += Fs * (2 * a[0][0] * a[1][0] - s * (a[0][0] * a[0][0] + a[1][0] * a[1][0]));
    N[1] += Fs * (2 * a[0][1] * a[1][1] - s * (a[0][1] * a[0][1] + a[1][1] * a[1][1]));
    N[2] +=
        Fs * (a[0][0] * a[1][1] + a[1][0] * a[0][1] - s * (a[0][0] * a[0][1] + a[1][0] * a[1][1]));
    const double iJ = 1.0 / J;
    b.resultant[e] = N[0] * iJ, b.resultant[st + e] = N[1] * iJ,
    b.resultant[2 * st + e] = N[2] * iJ;
  }
}

}  // namespace ncfsim::drape
