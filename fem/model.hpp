#pragma once
// Everything the explicit solver needs, checked before the time loop starts: mesh, materials,
// part properties, constraints, loads, tools and time controls. Node lists refer to the mesh's
// (renumbered) node indices.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "fem/bar_block.hpp"
#include "fem/contact_interface.hpp"
#include "fem/material.hpp"
#include "fem/mesh.hpp"
#include "fem/rigid_tool.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::fem {

constexpr std::array<double, 9> kIdentityAxes{1, 0, 0, 0, 1, 0, 0, 0, 1};

struct PartProperties {
  enum class Kind { Solid, Bar } kind = Kind::Solid;
  int material = -1;  // index into Model::materials (solids)
  int bar_law = -1;   // index into Model::bar_laws (bars)
  std::array<double, 9> material_axes = kIdentityAxes;  // row-major, axes as columns, global
  double hourglass_stiffness = 1.0;
  double hourglass_viscosity = 0.05;
};

struct FixedDofs {
  std::string name;
  std::vector<std::int32_t> nodes;
  std::array<bool, 3> dofs{true, true, true};
};

struct PrescribedVelocity {
  std::string name;
  std::vector<std::int32_t> nodes;
  std::array<bool, 3> dofs{false, false, false};  // which components are prescribed
  V3 velocity;                                     // value after the ramp
  double ramp_time = 0;                            // smooth ramp from 0
  double start_time = 0;                           // zero before this time
};

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

struct NodalLoad {
  std::string name;
  std::vector<std::int32_t> nodes;
  V3 force_per_node;   // N on each node after the ramp
  double ramp_time = 0;
};

struct InitialVelocity {
  std::vector<std::int32_t> nodes;
  V3 velocity;
};

struct TimeControl {
  double end_time = 0;
  double safety_factor = 0.9;
  double mass_scaling_dt = 0;       // 0: off; else elements below this step get added mass
  double history_interval = 0;      // 0: 200 rows over the run
  double frame_interval = 0;        // 0: 20 frames over the run
  std::int64_t max_cycles = 0;      // 0: unlimited
  double energy_balance_limit = 0.05;
  double min_step_ratio = 1e-4;     // stop when the step falls below this share of the initial one
  double erosion_step_ratio = 0;    // 0: off; else erode a hexahedron whose step falls below this
                                    // share of the initial one (LS-DYNA's ERODE with DTMIN)
};

struct Model {
  Mesh mesh;
  std::vector<std::unique_ptr<SolidMaterial>> materials;
  std::vector<BarForceLaw> bar_laws;
  std::vector<PartProperties> parts;  // indexed like mesh.part_names
  std::vector<FixedDofs> fixed;
  std::vector<PrescribedVelocity> velocities;
  std::vector<PictureFrame> picture_frames;
  std::vector<NodalLoad> loads;
  std::vector<InitialVelocity> initial_velocities;
  V3 gravity;
  double gravity_ramp_time = 0;  // smooth ramp of gravity from 0 (settling without a jolt)
  double mass_damping = 0;  // mass-proportional damping coefficient alpha (1/s)
  double mass_damping_end_time = 0;  // > 0: damping acts only before this time (settling)
  std::vector<RigidTool> tools;
  std::vector<std::unique_ptr<ContactAlgorithm>> contacts;  // deformable / tied contacts
  TimeControl time;
};

}  // namespace ncfsim::fem
