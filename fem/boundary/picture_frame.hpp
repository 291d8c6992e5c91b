#pragma once
// The pin-jointed picture frame of the fabric shear test as a boundary condition: the nodes it
// clamps follow the frame's rigid arms exactly.
#include <cstdint>
#include <string>
#include <vector>
#include <array>

#include "fem/vec3.hpp"

namespace ncfsim::fem {

/// Nodes clamped in a pin-jointed picture frame: a rhombus pinned at `corner` whose arms, along
/// arm1 and arm2 (orthogonal, unit) at t = 0, close symmetrically about their bisector. The frame
/// shear angle gamma (the arms stand at 90 deg - gamma) grows at `shear_rate` (rad/s) after a
/// smooth start over ramp_time. A node at corner + xi arm1 + eta arm2 (+ zeta normal) moves to
/// corner + xi u1 + eta u2 (+ zeta normal), u1 = cos(g/2) arm1 + sin(g/2) arm2,
/// u2 = sin(g/2) arm1 + cos(g/2) arm2: all three velocity components are prescribed.
struct PictureFrame {
  std::string name;
  std::vector<std::int32_t> nodes;
  V3 corner;
  V3 arm1{1, 0, 0}, arm2{0, 1, 0};
  double shear_rate = 0;   // rad/s
  double ramp_time = 0;    // s
  double arm_length = 0;   // m, frame side (pin to pin), for the frame force
  // Arms as walls (optional): the arms are rigid bars in the plane of the fabric; the nodes of
  // walls[0] bear on the two arms along arm1 (the lines eta = 0 and eta = arm_length), those of
  // walls[1] on the two along arm2 (xi = 0, xi = arm_length). The walls are strips through the
  // arms (pin to pin) normal to the frame plane, frictionless, node-to-wall penalty k = scale m / dt^2
  // (never lowers the stable step); they move with the frame (their work is the frame's).
  std::array<std::vector<std::int32_t>, 2> walls;
  double wall_penalty_scale = 0.1;
};

/// Frame shear angle (rad) and its rate at time t.
inline double picture_frame_angle(const PictureFrame& f, double t) {
  if (t <= 0) return 0;
  const double T = f.ramp_time;
  if (T <= 0 || t >= T) return f.shear_rate * (t - 0.5 * T);
  const double s = t / T;  // integral of the cubic ramp s^2 (3 - 2 s)
  return f.shear_rate * T * (s * s * s - 0.5 * s * s * s * s);
}
inline double picture_frame_rate(const PictureFrame& f, double t) {
  if (t <= 0) return 0;
  const double T = f.ramp_time;
  if (T <= 0 || t >= T) return f.shear_rate;
  const double s = t / T;
  return f.shear_rate * s * s * (3 - 2 * s);
}

}  // namespace ncfsim::fem
