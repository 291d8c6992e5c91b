#pragma once
// Rigid tools: analytic surfaces (plane, sphere, cylinder, torus, plane with a circular hole) and
// triangulated surfaces from STL, moving in translation with a prescribed velocity or driven by a
// prescribed force along an axis (a blankholder), in node-to-rigid penalty contact with Coulomb
// friction (regularised stick: an elastic tangential spring capped at mu * normal force).
#include <array>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "fem/vec3.hpp"

namespace ncfsim::fem {

class CheckpointWriter;
class CheckpointReader;

enum class ToolShape { Plane, Sphere, Cylinder, Torus, PlaneWithHole, Triangles };

/// Closest-point queries on triangles, bucketed on a uniform grid.
class TriangleSurface {
 public:
  explicit TriangleSurface(std::vector<std::array<V3, 3>> triangles);
  static TriangleSurface read_stl(const std::string& path, double scale);
  /// Signed distance along the nearest triangle's normal; false when nothing within `radius`.
  bool closest(const V3& p, double radius, double& gap, V3& normal) const;
  std::size_t size() const { return tri_.size(); }
  const std::vector<std::array<V3, 3>>& triangles() const { return tri_; }

 private:
  std::vector<std::array<V3, 3>> tri_;
  std::vector<V3> normal_;
  V3 lo_, hi_;
  double cell_ = 1;
  std::array<int, 3> dims_{1, 1, 1};
  std::vector<std::int32_t> start_, items_;  // CSR buckets
};

struct RigidSurface {
  ToolShape shape = ToolShape::Plane;
  V3 point;                  // plane point, sphere/torus centre, axis point
  V3 axis{0, 0, 1};          // plane normal or axis (unit); the body lies on the side it points to
  double radius = 0;         // sphere, cylinder, torus major radius, hole radius
  double minor_radius = 0;   // torus tube radius
  bool body_inside = false;  // sphere/cylinder/torus: the body is inside the surface
  std::shared_ptr<const TriangleSurface> triangles;
  double search_radius = 0;  // triangles: how far to look for the nearest face

  /// Gap (positive = apart) and outward unit normal at a point in the tool's own frame.
  bool gap_at(const V3& p, double& gap, V3& normal) const;
  /// A lower bound on how far p (tool frame) must move before gap_at can report gap < offset:
  /// the proximity cull skips nodes that cannot reach the tool before the next rebuild.
  double reach_distance(const V3& p, double offset) const;
};

/// Which of a tool's contact nodes can touch it soon: the nodes within `margin` of the tool at
/// the last rebuild. Rebuilt (a full pass over the contact nodes) once the largest node
/// displacement plus the tool's own since then could close the margin, so no contact is missed.
struct ToolProximity {
  double margin = 0;               // m; 0 until the first rebuild sets it
  std::vector<std::int32_t> near;  // indices into RigidTool::contact_nodes
  std::vector<double> x_ref;       // [3*n_contact_nodes] positions at the last rebuild
  V3 tool_ref;                     // tool displacement at the last rebuild
  // The last displacement check: the caller's node travel bound then (< 0: none since the start
  // or the resume) and the largest node displacement from x_ref it found. While that plus the
  // travel since and the tool's own displacement stay below the margin, the check is skipped.
  double checked_travel = -1;
  double checked_d = 0;
  std::int64_t n_rebuilds = 0;
  std::int64_t n_checks = 0;  // displacement checks done (a pass over the contact nodes)
  bool valid = false;
};

struct ToolMotion {
  enum class Kind { Fixed, Velocity, Force } kind = Kind::Fixed;
  V3 velocity;              // Velocity: target velocity after the ramp
  double ramp_time = 0;     // smooth (C1) ramp from rest
  // Velocity: a scale of `velocity` over time, piecewise linear through (curve_time[k],
  // curve_scale[k]) and held past either end (empty: 1); it multiplies the ramp. A forming
  // process's speed profile: slow while the fabric stores little, full speed after.
  std::vector<double> curve_time, curve_scale;
  V3 axis{0, 0, 1};         // Force: direction of the applied force and of the free motion
  double force = 0;         // Force: magnitude (N), applied along `axis`
  double mass = 0;          // Force: tool mass (kg)
  double pressure = 0;      // Force given as a pressure (Pa; 0: given as a force) ...
  double pressed_area = 0;  // ... over this blank area (m^2): force = pressure x area
};

struct RigidTool {
  std::string name;
  RigidSurface surface;
  ToolMotion motion;
  std::vector<std::int32_t> contact_nodes;  // slave nodes
  double friction = 0;                      // Coulomb coefficient
  double penalty_scale = 0.1;  // k = scale * m_node / dt^2: never lowers the stable step
  /// Viscous damping of the normal penalty spring, share of critical 2 sqrt(k m), [0, 1]: damps
  /// contact chatter and friction-excited flutter of soft bodies sliding on the tool (a sled
  /// pulled at its top pitched into a growing normal-force oscillation without it); never pulls.
  /// Its work is reported with the friction dissipation.
  double damping = 0.1;
  double thickness = 0;  // contact offset (shell thickness / 2 or clearance)
  /// Proximity cull margin, m; 0: automatic (1 % of the contact nodes' bounding-box diagonal,
  /// at least 4 x thickness). Larger: fewer rebuilds, more nodes tested per cycle.
  double search_margin = 0;

  // State
  V3 displacement;                  // tool translation at the current time
  V3 velocity;                      // tool velocity over the current half step
  V3 force;                         // resultant contact force exerted BY the nodes ON the tool
  std::vector<double> tangential;   // [3*n_contact_nodes] elastic friction forces
  double friction_dissipation = 0;  // J, friction and normal damping
  std::int64_t n_active = 0;
  double max_penetration = 0;  // deepest node past the contact offset over the run, m
  ToolProximity proximity;
};

/// Smooth ramp from 0 to 1 over [0, t_ramp] (cubic, zero slope at both ends).
inline double smooth_ramp(double t, double t_ramp) {
  if (t_ramp <= 0 || t >= t_ramp) return t < 0 ? 0.0 : 1.0;
  if (t <= 0) return 0.0;
  const double s = t / t_ramp;
  return s * s * (3 - 2 * s);
}

/// The velocity curve's scale at time t: piecewise linear, held past either end; 1 without one.
double tool_velocity_scale(const ToolMotion& m, double t);

/// Prescribed tool velocity at time t (Velocity kind).
V3 tool_prescribed_velocity(const RigidTool& tool, double t);

/// Distance a Velocity tool travels from 0 to t (its speed's integral: ramp and curve).
double tool_prescribed_travel(const RigidTool& tool, double t);

/// Axis a tool reports its scalar force and displacement along (a punch's stroke): its motion
/// direction, the force's axis of a force-driven tool, else its surface's axis.
V3 tool_axis(const RigidTool& tool);

/// Contact forces of one tool at positions x, velocities v (last half step) and step dt;
/// adds the forces on the nodes into f_contact [3*n_nodes] and updates the tool's state.
/// node_travel: a running bound on how far any contact node has moved since the start (the
/// solver's sum over cycles of its largest node displacement), or < 0 when the caller has none;
/// with it the proximity cull's displacement check is skipped in the cycles where it cannot fail.
void tool_contact_forces(RigidTool& tool, const double* x, const double* v, const double* mass,
                         double dt, double* f_contact, double node_travel = -1);

/// Takes the nodes flagged in `gone` ([n_nodes], 1: gone) out of the tool's contact nodes (nodes
/// left with no element by erosion); their friction state goes with them, the near list is
/// rebuilt in the next contact pass.
void remove_tool_contact_nodes(RigidTool& tool, const std::vector<std::uint8_t>& gone);

/// The tool's state (motion, force, friction, contact nodes left after erosion, the proximity
/// list, whose order fixes the order of the friction sums) into a checkpoint and back into a tool
/// of the same case (CheckpointMismatch when it does not fit).
void save_tool_state(const RigidTool& tool, CheckpointWriter& w);
void load_tool_state(RigidTool& tool, CheckpointReader& r);

}  // namespace ncfsim::fem
