#pragma once
// The picture-frame shear test's measures (fem/boundary/picture_frame.hpp): history.csv
// <frame>_shear_angle_deg, <frame>_force_N (crosshead), <frame>_shear_force_N and
// <frame>_normalised_shear_force_N_per_m (normalised by the fabric length, Harrison et al.).
#include <cstddef>
#include <string>
#include <vector>

#include "fem/boundary/picture_frame.hpp"
#include "fem/run_measure.hpp"

namespace ncfsim::drape {

class PictureFrameForce final : public fem::RunMeasure {
 public:
  /// Frame `index` of the model (its arms' wall power is the solver's frame_wall_power(index));
  /// `fabric_length` (m): side of the sheared fabric, for the normalised force.
  PictureFrameForce(std::size_t index, const fem::PictureFrame& frame, double fabric_length);
  void add_columns(std::vector<std::string>& columns) override;
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override;

 private:
  std::size_t index_;
  const fem::PictureFrame& frame_;  // borrowed from the model
  double fabric_length_;
};

}  // namespace ncfsim::drape
