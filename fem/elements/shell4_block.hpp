#pragma once
// Four-node shells of the Belytschko-Tsay class for explicit dynamics (LS-DYNA ELFORM 2): a
// co-rotational frame per element (normal from the diagonals, in-plane axes on their bisector, so
// the frame does not depend on which node comes first), one-point in-plane integration with
// stiffness hourglass control of the membrane, out-of-plane and rotation modes, Mindlin plate
// kinematics with nodal rotations (the translational velocities come from the solver; the
// rotational ones are held by the shell group, fem/elements/shell4_group.cpp).
//
// Kinematics (theory: docs/theory.md, "Shells"): in the current frame, with B_aI = dN_I/dx_a at
// the centre and the rotation velocities w_I,
//   d_11 = B_1I v_1I, d_22 = B_2I v_2I, 2 d_12 = B_2I v_1I + B_1I v_2I        (membrane)
//   k_11 = B_1I w_2I, k_22 = -B_2I w_1I, 2 k_12 = B_2I w_2I - B_1I w_1I       (curvature)
//   g_13 = B_1I v_3I + w_2I / 4, g_23 = B_2I v_3I - w_1I / 4                   (transverse shear)
// and the nodal forces and moments are the derivatives of the element's power
// A (N:d + M:k + Q.g) with respect to the nodal velocities (so the work booked is the work done).
//
// Measures: the in-plane deformation gradient F from the reference in-plane frame to the current
// one (one point, at the centre), its polar rotation R (in 2D exactly atan2(F21 - F12, F11 +
// F22)). Membrane strains are total (Green-Lagrange E = (F^T F - I) / 2, objective by
// construction); curvature, transverse shear and the hourglass modes are integrated in rate form
// with their increments rotated back to the reference frame by R, so rigid rotations leave them
// unchanged.
//
// Sections: a plane-stress elastic material (E, nu) integrated through the thickness at Gauss
// points (S(z) = Q (E + z kappa)), or a membrane law (fem/membrane_law.hpp: a dry fabric) with
// linear bending and transverse shear from the law's bending stiffness.
#include <cstdint>
#include <vector>

#include "fem/elements/block_of.hpp"
#include "fem/elements/element_step.hpp"
#include "fem/membrane_law.hpp"

namespace ncfsim::fem {

/// Shells per kernel chunk (a membrane law sees a chunk's deformation gradients at once).
inline constexpr std::size_t kShell4Chunk = 64;

struct Shell4Section {
  double thickness = 0;              // m
  int integration_points = 2;        // Gauss points through the thickness (elastic section)
  const MembraneLaw* law = nullptr;  // borrowed; null: elastic plane stress
  double youngs_modulus = 0, poisson_ratio = 0, density = 0;  // elastic section
  double hourglass_stiffness = 0.1;  // LS-DYNA's QM: share of the physical stiffness
};

struct Shell4Block {
  int part = 0;
  int material_index = -1;  // index into Model::materials (elastic) or Model::membrane_laws
  Shell4Section section;
  std::size_t n = 0;
  std::vector<std::int32_t> conn;        // [4][n] node indices, counter-clockwise about the normal
  std::vector<std::int64_t> user_id;     // [n]
  std::vector<std::int32_t> mesh_index;  // [n] index into the mesh's shell set
  // The elements the per-cycle kernel integrates (a rank's share; all on one rank). The
  // begin is a multiple of kShell4Chunk.
  std::size_t range_begin = 0, range_end = static_cast<std::size_t>(-1);

  // Reference geometry.
  std::vector<double> area0;  // [n]
  std::vector<double> b0;     // [8][n] dN_I/dX_a at the centre, reference in-plane frame [2a+..]:
                              // rows 0..3 = dN_I/dX_1, rows 4..7 = dN_I/dX_2
  std::vector<double> axes0;  // [4][n] material axes 1 and 2 in the reference in-plane frame
  std::vector<double> mass_scale;  // [n] >= 1 where mass scaling raised the element's step

  // State (reference frame, see the header comment).
  std::vector<double> strain;        // [3][n] membrane Green-Lagrange strain E11, E22, E12
  std::vector<double> curvature;     // [3][n] k11, k22, k12 (tensor components), 1/m
  std::vector<double> shear;         // [2][n] transverse shear strains g13, g23
  std::vector<double> resultant;     // [3][n] membrane force N (2nd Piola-Kirchhoff, N/m)
  std::vector<double> moment;        // [3][n] bending moment M (N m / m)
  std::vector<double> shear_force;   // [2][n] transverse shear force Q (N/m)
  std::vector<double> hg_force;      // [5][n] hourglass generalised forces (x, y, w, wx, wy)
  std::vector<double> drill_moment;  // [4][n] drilling spring moment at each corner (N m)
  std::vector<double> polar_angle;   // [2][n] cos, sin of the polar rotation of F last cycle
  std::vector<double> history;       // [n_history][n] of the membrane law

  // Stiffnesses of the section per unit width.
  double membrane_stiffness = 0;  // N/m: E t / (1 - nu^2) or the law's
  double bending_stiffness = 0;   // N m
  double shear_stiffness = 0;     // N/m (transverse)
  double areal_density = 0;       // kg/m^2 (before mass scaling)
  double poisson = 0;             // of the bending and membrane of the elastic section
};

/// Builds the reference geometry at x_ref with material axis 1 `axis` (global; projected on each
/// element's plane). Throws NumericalError naming a degenerate element.
void shell4_initialise(Shell4Block& b, const double* x_ref, const double axis[3]);
/// Translational lumped mass (A0 rho_A / 4 per node, with mass scaling) added into mass [3*n].
void shell4_lumped_mass(const Shell4Block& b, double* mass);
/// Rotational inertia per node, added into inertia [n_nodes]: m_I (t^2 / 12 + A0 / 8) (the
/// scaling of LS-DYNA's rotary inertia, so the rotations never control the stable step).
void shell4_rotary_inertia(const Shell4Block& b, double* inertia);
/// Step of each element at positions x: L / c with L the smaller of the shortest side and the
/// area over the longest side, c = sqrt(membrane stiffness / areal density).
void shell4_element_steps(const Shell4Block& b, const double* x, std::vector<double>& dt);
/// Forces subtracted from f [3*n_nodes] and moments from m [3*n_nodes] at x^n, with the
/// velocities v^{n-1/2} and the rotation velocities w^{n-1/2} ([3*n_nodes] each, global) over
/// the step dt that led to x^n.
void shell4_internal_forces(Shell4Block& b, const double* x, const double* v, const double* w,
                            double dt, double* f, double* m, ElementEnergyIncrement& energy,
                            StableStep& step);
/// Output at positions x, per element: the shear angle (deg; 90 minus the angle between the
/// convected fibre families of the law, or the material axes 1 and 2 of an elastic section),
/// the membrane force N as a symmetric tensor in global axes [6] (xx, yy, zz, xy, yz, xz; N/m),
/// the bending moment likewise [6] (N m/m) and the first fibre direction (global, unit) [3].
/// Any pointer may be null.
void shell4_output_fields(const Shell4Block& b, const double* x, double* shear_angle_deg,
                          double* membrane_force, double* bending_moment, double* fibre_direction);

template <>
Shell4Block* block_of<Shell4Block>(ElementGroup& g);
template <>
const Shell4Block* block_of<Shell4Block>(const ElementGroup& g);

}  // namespace ncfsim::fem
