#pragma once
// ASTM D1388 cantilever bending of a strip under gravity (drape/probe_specs.hpp
// BendingLengthProbe): history.csv <name>_tip_angle_deg; summary.json <name>_overhang_m,
// _tip_angle_deg, _bending_length_m, _flexural_rigidity_Nm, _beam_theory_bending_length_m,
// _axial_modulus_Pa (docs/output.md).
#include <string>
#include <vector>

#include "drape/probe_specs.hpp"
#include "fem/run_measure.hpp"

namespace ncfsim::drape {

class BendingLengthMeasure final : public fem::RunMeasure {
 public:
  /// Measures the strip (the part's reference bounding box: overhang along x, width along y,
  /// thickness along z), its weight per area and its bending modulus along material axis 1.
  BendingLengthMeasure(const BendingLengthProbe& spec, const fem::ExplicitSolver& s);
  void add_columns(std::vector<std::string>& columns) override;
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override;
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override;

  /// Tip angle below the horizontal (rad): the line from the root's to the tip's centroid.
  double tip_angle(const fem::ExplicitSolver& s) const;

 private:
  BendingLengthProbe spec_;
  double overhang_ = 0, thickness_ = 0, width_ = 0, areal_mass_ = 0, E1_ = 0;
};

}  // namespace ncfsim::drape
