#include "drape/probes/bending_length_probe.hpp"

#include <algorithm>
#include <cmath>

#include "fem/elements/hex8_block.hpp"

namespace ncfsim::drape {

using fem::V3;

BendingLengthMeasure::BendingLengthMeasure(const BendingLengthProbe& bp, const fem::ExplicitSolver& s) : spec_(bp) {
  const fem::Model& model = s.model();
  auto X0 = s.x0.view();
  double lo[3] = {1e300, 1e300, 1e300}, hi[3] = {-1e300, -1e300, -1e300};
  for (const auto& b : s.blocks<fem::Hex8Block>()) {
    if (b.part != bp.part) continue;
    for (std::size_t j = 0; j < b.conn.size(); ++j)
      for (int r = 0; r < 3; ++r) {
        const double v = X0[3 * static_cast<std::size_t>(b.conn[j]) + static_cast<std::size_t>(r)];
        lo[r] = std::min(lo[r], v);
        hi[r] = std::max(hi[r], v);
      }
  }
  overhang_ = hi[0] - lo[0], width_ = hi[1] - lo[1], thickness_ = hi[2] - lo[2];
  areal_mass_ = s.part_masses()[static_cast<std::size_t>(bp.part)].mass / (overhang_ * width_);
  const auto& pp = model.parts[static_cast<std::size_t>(bp.part)];
  const auto moduli = fem::directional_moduli(
      model.materials[static_cast<std::size_t>(pp.material)]->bending_stiffness(), {1, 0, 0, 0, 1, 0, 0, 0, 1});
  E1_ = moduli[0];  // bending modulus along material axis 1 (beam theory)
}

void BendingLengthMeasure::add_columns(std::vector<std::string>& columns) {
  columns.push_back(spec_.name + "_tip_angle_deg");
}

void BendingLengthMeasure::add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const {
  row.push_back(tip_angle(s) * 180.0 / M_PI);
}

double BendingLengthMeasure::tip_angle(const fem::ExplicitSolver& s) const {
  const V3 r = fem::mean_displacement(s, spec_.root), t = fem::mean_displacement(s, spec_.tip);
  auto X0 = s.x0.view();
  V3 r0, t0;
  for (auto i : spec_.root) r0 += V3::at(X0.data() + 3 * static_cast<std::size_t>(i));
  for (auto i : spec_.tip) t0 += V3::at(X0.data() + 3 * static_cast<std::size_t>(i));
  r0 = (1.0 / static_cast<double>(spec_.root.size())) * r0 + r;
  t0 = (1.0 / static_cast<double>(spec_.tip.size())) * t0 + t;
  return std::atan2(-(t0.z - r0.z), t0.x - r0.x);  // rad below the horizontal
}

void BendingLengthMeasure::add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const {
  // c = O (cos(theta/2) / (8 tan theta))^(1/3), G = w c^3, beam theory c = (E1 t^3 / 12 / w)^(1/3)
  const std::string& n = spec_.name;
  const double theta = tip_angle(s), g = norm(s.model().gravity);
  const double c = theta > 0 ? overhang_ * std::cbrt(std::cos(theta / 2) / (8 * std::tan(theta))) : std::nan("");
  summary[n + "_overhang_m"] = overhang_;
  summary[n + "_tip_angle_deg"] = theta * 180.0 / M_PI;
  summary[n + "_bending_length_m"] = fem::json_number(c);
  summary[n + "_flexural_rigidity_Nm"] =
      std::isfinite(c) ? nlohmann::json(areal_mass_ * g * c * c * c) : nlohmann::json(nullptr);
  summary[n + "_beam_theory_bending_length_m"] =
      std::cbrt(E1_ * thickness_ * thickness_ * thickness_ / 12.0 / (areal_mass_ * g));
  summary[n + "_axial_modulus_Pa"] = E1_;
}

}  // namespace ncfsim::drape
