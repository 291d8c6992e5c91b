#pragma once
// In-plane shear angle between the fibres of two plies over a material region (drape/
// probe_specs.hpp ShearProbe): history.csv <name>_shear_angle_deg.
#include <string>
#include <utility>
#include <vector>

#include "drape/probe_specs.hpp"
#include "fem/run_measure.hpp"

namespace ncfsim::drape {

class ShearAngleProbe final : public fem::RunMeasure {
 public:
  /// Finds the hexahedra of each ply whose reference centroid lies in the box; throws InputError
  /// (case_file, output.shear_probe.<name>) when one ply has none there.
  ShearAngleProbe(const ShearProbe& spec, const fem::ExplicitSolver& s, const std::string& case_file);
  std::vector<std::string> setup_lines() const override;
  void add_columns(std::vector<std::string>& columns) override;
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override;

  /// 90 deg minus the angle between the two plies' mean fibre directions (deg); NaN when every
  /// element of a ply has eroded.
  double shear_angle_deg(const fem::ExplicitSolver& s) const;

 private:
  using Elements = std::vector<std::pair<std::size_t, std::size_t>>;  // (hex block, element)
  std::string name_;
  Elements a_, b_;
};

}  // namespace ncfsim::drape
