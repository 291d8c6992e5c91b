#include "drape/probes/picture_frame_force.hpp"

#include <cmath>

namespace ncfsim::drape {

PictureFrameForce::PictureFrameForce(std::size_t index, const fem::PictureFrame& frame, double fabric_length)
    : index_(index), frame_(frame), fabric_length_(fabric_length) {}

void PictureFrameForce::add_columns(std::vector<std::string>& columns) {
  for (const char* c : {"_shear_angle_deg", "_force_N", "_shear_force_N", "_normalised_shear_force_N_per_m"})
    columns.push_back(frame_.name + c);
}

void PictureFrameForce::add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const {
  // Crosshead force from the power the frame puts in: F = sum R.v / (dd/dt), d the crosshead
  // travel, d = 2 L cos(theta) - sqrt(2) L, theta = 45 deg - gamma/2; shear force F / (2 cos theta).
  const auto& pf = frame_;
  const double g = fem::picture_frame_angle(pf, s.time()), gd = fem::picture_frame_rate(pf, s.time());
  const double theta = 0.25 * M_PI - 0.5 * g, ddot = pf.arm_length * std::sin(theta) * gd;
  double power = s.frame_wall_power(index_);  // the arms as walls push the edge tows
  {
    auto R = s.reaction.view();
    auto Vn = s.v.view();
    for (auto node : pf.nodes)
      for (int c = 0; c < 3; ++c) {
        const auto d = 3 * static_cast<std::size_t>(node) + static_cast<std::size_t>(c);
        power += R[d] * Vn[d];
      }
  }
  const double F = ddot > 0 ? power / ddot : 0.0, Fs = F / (2 * std::cos(theta));
  const double Lf = fabric_length_;
  row.push_back(g * 180.0 / M_PI);
  row.push_back(F);
  row.push_back(Fs);
  row.push_back(Fs * pf.arm_length / (Lf * Lf));
}

}  // namespace ncfsim::drape
