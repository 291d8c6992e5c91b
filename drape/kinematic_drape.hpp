#pragma once
// Kinematic (pin-jointed net, "fishnet") drape: the fabric idealised as two families of
// inextensible fibres crossing at pin joints, mapped onto a tool surface (Mack & Taylor). Two
// generators leave a starting point (the pole) along the two fibre directions as discrete
// geodesics; every other joint is the point of the surface at one net spacing from its two
// neighbours nearer the generators (the chord lengths of the net are kept exactly). The shear
// angle at a joint is 90 deg minus the angle between the two fibre lines there.
//
// The surface is the outer boundary of a union of rigid bodies (fem::RigidSurface, the same
// description as the forming tools): a hemispherical punch standing on a flat plane is a sphere
// plus a plane. No friction, no material: the net is a geometric reference for the meso and
// macro drapes (the paper's "mapping methods").
#include <cstdint>
#include <string>
#include <vector>

#include "fem/rigid_tool.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::drape {

/// The outer boundary of a union of rigid bodies: the signed gap of a point is the smallest of
/// the bodies' gaps (exact outside the union, which is where a drape lives).
struct DrapeSurface {
  std::vector<fem::RigidSurface> bodies;

  /// Signed gap (> 0 outside) and the outward normal of the body that gives it; false when no
  /// body answers at p.
  bool gap_at(const fem::V3& p, double& gap, fem::V3& normal) const;
  /// The closest point of the surface to p (iterated along the normals). Throws
  /// std::runtime_error when no body answers.
  fem::V3 project(const fem::V3& p, fem::V3* normal = nullptr) const;
};

struct KinematicDrapeSpec {
  fem::V3 pole;             // where the generators start (projected onto the surface)
  fem::V3 fibre1{1, 0, 0};  // first fibre direction at the pole (projected onto the tangent plane)
  fem::V3 fibre2{0, 1, 0};  // second fibre direction at the pole
  double spacing = 2e-3;    // m, net edge length (the pin-to-pin chord)
  int half_nodes = 50;      // joints along each generator on each side of the pole
  /// Throws std::invalid_argument naming the field and its allowed range.
  void validate() const;
};

/// The net: joints (i, j), i along fibre 1 and j along fibre 2, both in [-n, n] (n = half_nodes);
/// joint index (i + n) + (2n + 1) (j + n). A joint the construction could not place (the two
/// circles do not meet on the surface: the net locks) is marked invalid, and so are the joints
/// that depend on it.
struct KinematicNet {
  int n = 0;
  double spacing = 0;
  std::vector<fem::V3> x;            // [(2n+1)^2] positions
  std::vector<std::uint8_t> placed;  // [(2n+1)^2] 1 where the joint was placed
  std::vector<double> shear_deg;     // [(2n+1)^2] shear angle at the joint (0 where unknown)
  std::size_t n_locked = 0;          // joints not placed

  int side() const { return 2 * n + 1; }
  std::size_t index(int i, int j) const {
    return static_cast<std::size_t>((i + n) + side() * (j + n));
  }
  bool has(int i, int j) const {
    return i >= -n && i <= n && j >= -n && j <= n && placed[index(i, j)];
  }
  /// Triangles of the placed cells (two per cell), node indices as above.
  std::vector<std::array<std::int32_t, 3>> triangles() const;
};

/// Drapes the net onto the surface. Throws std::invalid_argument for a bad spec and
/// std::runtime_error when the pole does not project onto the surface.
KinematicNet kinematic_drape(const DrapeSurface& surface, const KinematicDrapeSpec& spec);

/// Shear angle (deg, in [0, 90]) between two fibre lines (undirected): 90 - angle between them.
double shear_angle_deg(const fem::V3& fibre_a, const fem::V3& fibre_b);

}  // namespace ncfsim::drape
