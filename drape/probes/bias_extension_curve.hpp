#pragma once
// The bias-extension test's analytic central shear angle (Eq. 2, drape/stitch_calibration.hpp)
// beside the simulated one: history.csv analytic_shear_angle_deg at the row's extension (a
// history column, e.g. a probe's <name>_displacement_x_m), and summary.json
// analytic_shear_angle_deg<suffix> at the extensions a summary sample asks for.
#include <string>
#include <vector>

#include "drape/stitch_calibration.hpp"
#include "fem/run_measure.hpp"

namespace ncfsim::drape {

class BiasExtensionCurve final : public fem::RunMeasure {
 public:
  /// A summary sample point: key suffix (e.g. "_at_10mm"), extension (m) and its coupon.
  struct Point {
    std::string suffix;
    double extension = 0;
    BiasExtensionCoupon coupon;
  };
  /// `x_column`: the history column that holds the extension (m), looked up at add_columns
  /// (InputError(case_file, output.sample.x) when absent); `coupon` for the history column.
  BiasExtensionCurve(std::string x_column, BiasExtensionCoupon coupon, std::vector<Point> points,
                     std::string case_file);
  void add_columns(std::vector<std::string>& columns) override;
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override;
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override;

 private:
  std::string x_column_, case_file_;
  BiasExtensionCoupon coupon_;
  std::vector<Point> points_;
  std::size_t x_ = 0;  // index of x_column in a history row
};

}  // namespace ncfsim::drape
