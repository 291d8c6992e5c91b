#include "drape/probes/shear_angle_probe.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "fem/elements/element_fields.hpp"
#include "fem/errors.hpp"

namespace ncfsim::drape {

using fem::V3;

ShearAngleProbe::ShearAngleProbe(const ShearProbe& sp, const fem::ExplicitSolver& s, const std::string& case_file)
    : name_(sp.name) {
  auto X0 = s.x0.view();
  for (std::size_t k = 0; k < s.blocks<fem::Hex8Block>().size(); ++k) {
    const auto& b = s.blocks<fem::Hex8Block>()[k];
    if (b.part != sp.part_a && b.part != sp.part_b) continue;
    for (std::size_t e = 0; e < b.n; ++e) {
      double c[3] = {0, 0, 0};
      for (int I = 0; I < 8; ++I)
        for (int r = 0; r < 3; ++r)
          c[r] += 0.125 * X0[3 * static_cast<std::size_t>(b.conn[static_cast<std::size_t>(I) * b.n + e]) +
                             static_cast<std::size_t>(r)];
      bool in = true;
      for (int r = 0; r < 3; ++r)
        in &= c[r] >= sp.box_min[static_cast<std::size_t>(r)] && c[r] <= sp.box_max[static_cast<std::size_t>(r)];
      if (in) (b.part == sp.part_a ? a_ : b_).emplace_back(k, e);
    }
  }
  if (a_.empty() || b_.empty())
    throw InputError(case_file, "output.shear_probe." + sp.name, "the box holds no element of one of the two parts");
}

std::vector<std::string> ShearAngleProbe::setup_lines() const {
  return {fmt::format("shear probe {}: {} + {} elements", name_, a_.size(), b_.size())};
}

void ShearAngleProbe::add_columns(std::vector<std::string>& columns) { columns.push_back(name_ + "_shear_angle_deg"); }

void ShearAngleProbe::add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const {
  row.push_back(shear_angle_deg(s));
}

double ShearAngleProbe::shear_angle_deg(const fem::ExplicitSolver& s) const {
  auto X = s.x.view();
  auto mean = [&](const Elements& set) {
    V3 sum, first;
    for (const auto& [k, e] : set) {
      const auto& b = s.blocks<fem::Hex8Block>()[k];
      if (b.n_eroded && b.eroded[e]) continue;  // no longer part of the fabric
      double d[3];
      fem::hex8_fibre_direction(b, X.data(), e, d);
      V3 v{d[0], d[1], d[2]};
      if (norm(first) == 0) first = v;
      sum += dot(v, first) < 0 ? -1.0 * v : v;  // a fibre direction has no sign
    }
    const double nan = std::numeric_limits<double>::quiet_NaN();
    return norm(sum) > 0 ? normalized(sum) : V3{nan, nan, nan};  // all eroded: nothing to measure
  };
  const double c = std::abs(dot(mean(a_), mean(b_)));
  if (std::isnan(c)) return c;
  return 90.0 - std::acos(std::min(1.0, c)) * 180.0 / M_PI;
}

}  // namespace ncfsim::drape
