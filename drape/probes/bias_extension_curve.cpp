#include "drape/probes/bias_extension_curve.hpp"

#include <algorithm>
#include <cmath>

#include "fem/errors.hpp"

namespace ncfsim::drape {

BiasExtensionCurve::BiasExtensionCurve(std::string x_column, BiasExtensionCoupon coupon, std::vector<Point> points,
                                       std::string case_file)
    : x_column_(std::move(x_column)), case_file_(std::move(case_file)), coupon_(coupon), points_(std::move(points)) {}

void BiasExtensionCurve::add_columns(std::vector<std::string>& columns) {
  const auto it = std::find(columns.begin(), columns.end(), x_column_);
  if (it == columns.end())
    throw InputError(case_file_, "output.sample.x",
                     "no history column '" + x_column_ + "' (probes: <name>_displacement_x_m)");
  x_ = static_cast<std::size_t>(it - columns.begin());
  columns.push_back("analytic_shear_angle_deg");
}

void BiasExtensionCurve::add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const {
  (void)s;
  row.push_back(central_shear_angle(coupon_, std::max(0.0, row[x_])) * 180.0 / M_PI);
}

void BiasExtensionCurve::add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const {
  (void)s;
  for (const auto& p : points_)
    summary["analytic_shear_angle_deg" + p.suffix] = central_shear_angle(p.coupon, p.extension) * 180.0 / M_PI;
}

}  // namespace ncfsim::drape
