#include "impact/cfc_filter.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

namespace ncfsim::impact {

namespace {

constexpr double kPi = 3.14159265358979323846;

struct Coefficients {
  double a0, a1, a2, b1, b2;
};

Coefficients j211(double T, double cfc) {
  const double wd = 2 * kPi * cfc * 2.0775;
  const double wa = std::tan(wd * T / 2);
  const double s2 = std::sqrt(2.0);
  const double k = 1 + s2 * wa + wa * wa;
  const double a0 = wa * wa / k;
  return {a0, 2 * a0, a0, -2 * (wa * wa - 1) / k, (-1 + s2 * wa - wa * wa) / k};
}

void pass(const Coefficients& c, std::vector<double>& v) {
  if (v.size() < 3) return;
  double x1 = v[0], x2 = v[0], y1 = v[0], y2 = v[0];  // at rest at the first value
  for (double& s : v) {
    const double y = c.a0 * s + c.a1 * x1 + c.a2 * x2 + c.b1 * y1 + c.b2 * y2;
    x2 = x1;
    x1 = s;
    y2 = y1;
    y1 = y;
    s = y;
  }
}

}  // namespace

std::vector<double> cfc_filter(const std::vector<double>& x, double T, double cfc) {
  if (!(cfc > 0) || !std::isfinite(cfc))
    throw std::invalid_argument("CFC filter class: must be > 0 Hz (got " + std::to_string(cfc) +
                                ")");
  if (!(T > 0) || 1.0 / T < 10.0 * cfc)
    throw std::invalid_argument("CFC filter: the sampling frequency (" + std::to_string(1.0 / T) +
                                " Hz) must be at least 10 x CFC (" + std::to_string(10 * cfc) +
                                " Hz): lower the history interval or the class");
  if (x.empty()) return {};
  const Coefficients c = j211(T, cfc);
  // Pad both ends with the end values (the filter's start-up transient falls in the padding).
  const std::size_t pad = std::min<std::size_t>(x.size(), 200);
  std::vector<double> v;
  v.reserve(x.size() + 2 * pad);
  v.insert(v.end(), pad, x.front());
  v.insert(v.end(), x.begin(), x.end());
  v.insert(v.end(), pad, x.back());
  pass(c, v);
  std::vector<double> r(v.rbegin(), v.rend());
  pass(c, r);
  return std::vector<double>(r.rbegin() + static_cast<std::ptrdiff_t>(pad),
                             r.rbegin() + static_cast<std::ptrdiff_t>(pad + x.size()));
}

}  // namespace ncfsim::impact
