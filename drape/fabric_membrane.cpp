// The macro fabric membrane law (drape/fabric_membrane.hpp).
// GCC 12 reports false (maybe-)uninitialized warnings inside its AVX-512 intrinsics when it
// inlines std::experimental::simd (as in fem/elements/hex8_block.cpp).
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#pragma GCC diagnostic ignored "-Wuninitialized"
#include "drape/fabric_membrane.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fem/elements/simd_batch.hpp"

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
  // Elements in SIMD lanes; the shear angle and the table lookup per lane.
  using fem::batch::VD;
  using fem::batch::W;
  namespace stdx = std::experimental;
  const std::size_t st = b.stride;
  const double K = c_.fibre_tension_stiffness, Kc = K * c_.fibre_compression_ratio;
  double cf[2], sf[2];
  for (int k = 0; k < 2; ++k)
    cf[k] = std::cos(c_.fibre_angles[static_cast<std::size_t>(k)]),
    sf[k] = std::sin(c_.fibre_angles[static_cast<std::size_t>(k)]);
  for (std::size_t e0 = 0; e0 < b.n; e0 += W) {
    const int cnt = static_cast<int>(std::min<std::size_t>(W, b.n - e0));
    auto ld = [&](const double* p, std::size_t row) {
      return fem::batch::load(p + row * st + e0, cnt);
    };
    const VD F11 = ld(b.F, 0), F12 = ld(b.F, 1), F21 = ld(b.F, 2), F22 = ld(b.F, 3);
    const VD m1x = ld(b.axes, 0), m1y = ld(b.axes, 1), m2x = ld(b.axes, 2), m2y = ld(b.axes, 3);
    const VD J = F11 * F22 - F12 * F21;
    VD a[2][2], N0 = 0.0, N1 = 0.0, N2 = 0.0;
    for (int k = 0; k < 2; ++k) {
      const VD Ax = cf[k] * m1x + sf[k] * m2x, Ay = cf[k] * m1y + sf[k] * m2y;
      const VD x = F11 * Ax + F12 * Ay, y = F21 * Ax + F22 * Ay;
      const VD lam = stdx::sqrt(x * x + y * y);
      const VD il = 1.0 / lam;
      a[k][0] = x * il, a[k][1] = y * il;
      const VD eps = lam - 1.0;
      VD Kk = Kc;
      stdx::where(eps > 0.0, Kk) = K;
      const VD T = Kk * eps * lam;  // W'(lam) lam
      N0 += T * a[k][0] * a[k][0], N1 += T * a[k][1] * a[k][1], N2 += T * a[k][0] * a[k][1];
    }
    const VD s = stdx::clamp(a[0][0] * a[1][0] + a[0][1] * a[1][1], VD(-1.0), VD(1.0));
    const VD Fs([&](auto l) { return shear_force(std::asin(s[static_cast<int>(l)])); });
    N0 += Fs * (2.0 * a[0][0] * a[1][0] - s * (a[0][0] * a[0][0] + a[1][0] * a[1][0]));
    N1 += Fs * (2.0 * a[0][1] * a[1][1] - s * (a[0][1] * a[0][1] + a[1][1] * a[1][1]));
    N2 +=
        Fs * (a[0][0] * a[1][1] + a[1][0] * a[0][1] - s * (a[0][0] * a[0][1] + a[1][0] * a[1][1]));
    const VD iJ = 1.0 / J;
    fem::batch::store(b.resultant + e0, N0 * iJ, cnt);
    fem::batch::store(b.resultant + st + e0, N1 * iJ, cnt);
    fem::batch::store(b.resultant + 2 * st + e0, N2 * iJ, cnt);
  }
}

}  // namespace ncfsim::drape
