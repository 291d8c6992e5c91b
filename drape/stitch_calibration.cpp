#include "drape/stitch_calibration.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ncfsim::drape {

namespace {
constexpr double kQuarterPi = M_PI / 4;

// Components of the segment (along load, across load) in the undeformed coupon.
void segment_components(const BiasExtensionCoupon& c, StitchSegment seg, ShearSign sign, double& a, double& b) {
  if (seg == StitchSegment::I) {
    a = sign == ShearSign::Positive ? c.stitch_length : 0.0;
    b = sign == ShearSign::Positive ? 0.0 : c.stitch_length;
  } else {
    a = sign == ShearSign::Positive ? c.stitch_length : c.gauge;
    b = sign == ShearSign::Positive ? c.gauge : c.stitch_length;
  }
}

double interp(const std::vector<double>& x, const std::vector<double>& y, double v) {
  if (v <= x.front()) return y.front() + (v - x.front()) * (y[1] - y[0]) / (x[1] - x[0]);
  const auto it = std::upper_bound(x.begin(), x.end(), v);
  const std::size_t i = std::min<std::size_t>(static_cast<std::size_t>(it - x.begin()), x.size() - 1);
  const std::size_t i0 = i - 1;
  return y[i0] + (v - x[i0]) * (y[i] - y[i0]) / (x[i] - x[i0]);
}
}  // namespace

double central_shear_angle(const BiasExtensionCoupon& c, double D) {
  const double L0 = c.length - c.width;
  const double arg = std::min(1.0, (L0 + D) / (std::sqrt(2.0) * L0));
  return M_PI / 2 - 2 * std::acos(arg);
}

double stitch_strain(const BiasExtensionCoupon& c, StitchSegment seg, ShearSign sign, double gamma) {
  double a, b;
  segment_components(c, seg, sign, a, b);
  const double ll = std::sqrt(2.0) * std::cos(kQuarterPi - gamma / 2), lt = std::sqrt(2.0) * std::sin(kQuarterPi - gamma / 2);
  const double L0 = std::hypot(a, b), L = std::hypot(ll * a, lt * b);
  return (L - L0) / L0;
}

double stitch_angle_to_load(const BiasExtensionCoupon& c, StitchSegment seg, ShearSign sign, double gamma) {
  double a, b;
  segment_components(c, seg, sign, a, b);
  const double ll = std::sqrt(2.0) * std::cos(kQuarterPi - gamma / 2), lt = std::sqrt(2.0) * std::sin(kQuarterPi - gamma / 2);
  return std::atan2(lt * b, ll * a);
}

std::vector<double> coupon_force(const BiasExtensionCoupon& c, ShearSign sign, const StitchLaw& law,
                                 const std::vector<double>& extensions) {
  const StitchSegment seg = sign == ShearSign::Positive ? StitchSegment::I : StitchSegment::Lambda;
  const double n_seg = c.width / c.gauge;
  std::vector<double> F;
  for (double D : extensions) {
    const double g = central_shear_angle(c, D);
    const double e = stitch_strain(c, seg, sign, g);
    const double f = e > 0 ? interp(law.strain, law.force, e) : 0.0;
    F.push_back(f * n_seg * std::cos(stitch_angle_to_load(c, seg, sign, g)));
  }
  return F;
}

StitchLaw calibrate_stitch_law(const BiasExtensionCoupon& c, ShearSign sign, const std::vector<double>& ext,
                               const std::vector<double>& force, double max_shear_deg, int n_points) {
  if (!(c.length > c.width && c.width > 0)) throw std::invalid_argument("coupon length must exceed its width > 0");
  if (!(c.stitch_length > 0 && c.gauge > 0)) throw std::invalid_argument("stitch length and gauge must be > 0");
  if (ext.size() != force.size()) throw std::invalid_argument("extension and force columns differ in length");
  if (n_points < 2) throw std::invalid_argument("the law needs at least 2 points");
  const StitchSegment seg = sign == ShearSign::Positive ? StitchSegment::I : StitchSegment::Lambda;
  const double n_seg = c.width / c.gauge;
  std::vector<double> e, f;  // stitch strain, force per segment
  for (std::size_t i = 0; i < ext.size(); ++i) {
    if (i > 0 && !(ext[i] > ext[i - 1])) throw std::invalid_argument("extensions must strictly increase");
    const double g = central_shear_angle(c, ext[i]);
    if (g * 180 / M_PI > max_shear_deg) break;
    const double es = stitch_strain(c, seg, sign, g);
    if (es <= 0) continue;
    e.push_back(es);
    f.push_back(force[i] / (n_seg * std::cos(stitch_angle_to_load(c, seg, sign, g))));
  }
  if (e.size() < 3)
    throw std::invalid_argument("fewer than 3 samples with a stretched stitch below " + std::to_string(max_shear_deg) +
                                " deg shear: extend the data or check the shear sign");
  // Monotone (running maximum): a tension-only stitch law must not soften in this calibration.
  for (std::size_t i = 1; i < f.size(); ++i) f[i] = std::max(f[i], f[i - 1]);
  StitchLaw law;
  const double emax = e.back();
  for (int k = 0; k < n_points; ++k) {
    const double es = emax * k / (n_points - 1);
    law.strain.push_back(es);
    // Below the first sample, interpolate linearly towards (0, 0).
    double fv;
    if (es <= e.front()) fv = f.front() * es / e.front();
    else fv = interp(e, f, es);
    law.force.push_back(std::max(0.0, fv));
  }
  law.force.front() = 0.0;
  return law;
}

}  // namespace ncfsim::drape
