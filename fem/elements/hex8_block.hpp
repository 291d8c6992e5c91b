#pragma once
// One-point hexahedra of one part and one material, state held as structure of arrays.
//
// Formulation (see docs/theory.md):
//  * uniform-gradient (Flanagan-Belytschko) B operator, b_I = dV/dx_I / V, exact volume, so the
//    patch test holds on distorted meshes;
//  * objective Lagrangian stress at the centre: Green-Lagrange strain in the reference material
//    axes advanced by the uniform gradient's rate of deformation pulled back with the mid-step F
//    (so the booked energy is the nodal forces' work, distorted elements too), 2nd
//    Piola-Kirchhoff stress from the material, pushed forward to Cauchy stress; fibre axes
//    convect with F, rigid rotations add no strain;
//  * physically based, assumed-strain hourglass stabilisation in the element frame: each
//    hourglass mode is resisted by the energy of its linear (bending) or bilinear strain field,
//    with the parasitic shear of bending removed (Belytschko-Bindeman type). One element through
//    a thin layer then bends with the right stiffness. A small viscous part damps hourglass
//    noise; only that part is non-physical and is reported as hourglass energy.
#include <array>
#include <cstdint>
#include <vector>

#include "fem/elements/block_of.hpp"
#include "fem/elements/element_step.hpp"
#include "fem/material.hpp"

namespace ncfsim::fem {

/// Elements per chunk of the hexahedron kernel.
inline constexpr std::size_t kHex8Chunk = 32;

struct Hex8Block {
  int part = 0;
  const SolidMaterial* material = nullptr;  // borrowed, outlives the block
  int material_index = -1;                  // index into Model::materials
  std::size_t n = 0;
  std::vector<std::int32_t> conn;     // [8][n] node indices
  std::vector<std::int64_t> user_id;  // [n]
  std::vector<double> stress;         // [6][n] 2nd Piola-Kirchhoff stress, reference material axes
  std::vector<double>
      strain;  // [6][n] Green-Lagrange strain, reference material axes (engineering shear)
  std::vector<double> history;  // [n_history][n]
  std::vector<double>
      hg_force;  // [12][n] hourglass generalised forces, element frame, [3*mode+axis]
  std::vector<double> hg_viscous;  // [12][n] viscous hourglass forces of the last cycle (their
                                   // work is booked over both increments around it)
  std::vector<double>
      mat_axes;  // [9][n] reference material axes, global (row-major, axes = columns)
  std::vector<double> jac_inv0;        // [9][n] inverse of the reference centre Jacobian
  std::vector<double> jac_inv0_axes;   // [9][n] jac_inv0 * mat_axes: F M = J jac_inv0_axes (kernel)
  std::vector<double> hg_moduli;       // [6][n] E1 E2 E3 G12 G23 G13 along the element axes
  std::vector<double> volume;          // [n] current volume
  std::vector<double> volume0;         // [n] reference volume
  std::vector<double> density;         // [n] density incl. mass scaling
  std::vector<std::int32_t> mesh_hex;  // [n] index into the mesh's hexahedron set
  std::vector<std::uint8_t> eroded;    // [n] 1: removed from the calculation (empty: none yet)
  std::size_t n_eroded = 0;
  // Elements the per-cycle kernel integrates (a rank's run, fem/parallel/domain.hpp); a multiple
  // of the kernel chunk (kHex8Chunk) to the end.
  std::size_t range_begin = 0, range_end = static_cast<std::size_t>(-1);
  double hourglass_stiffness = 1.0;   // scale of the physical stabilisation (1 = exact bending)
  double hourglass_viscosity = 0.05;  // fraction of critical damping on the hourglass modes
  double p_modulus = 0.0;             // modulus of the stable-step bound (uniform-strain hex)
  // Directional step bound: lambda = largest eigenvalue of C G(D0), with D0 = sum_I B0_I B0_I^T
  // of the reference nodal gradients in the material axes, G the 6x6 Gram matrix of the strain
  // operator they make and C the material's stable-step stiffness: the uniform-strain modes of
  // the reference shape have omega^2 <= 8/rho lambda (exact for a parallelepiped). Kept as the
  // modulus 2 lambda lc0^2 at the reference characteristic length lc0 = V0/sqrt(A_max0); in the
  // current shape dt = min(lc0, lc) sqrt(rho / (max(1, lambda_max(Cg)) step_modulus)), Cg the
  // right Cauchy-Green tensor in the material axes: never above the reference bound, and it
  // falls with the characteristic length as the element is crushed, as V/A_max does. Empty (not
  // used) for an isotropic material.
  std::vector<double> step_modulus;  // [n] Pa
  std::vector<double> step_length0;  // [n] m
  // [3][n] reference length of the element along each material axis: volume over the area of
  // its projection on the plane normal to the axis (the edge length of a box along its axes).
  // Damage laws regularise their softening with it (crack band); MaterialBatch::length.
  std::vector<double> axis_length;
};

/// Sets up a block from reference coordinates: volumes, frames, hourglass moduli, density.
/// `material_axes_global` (row-major, axes as columns) gives the material axes in the reference
/// configuration; `element_axes` [9][n] (same layout, per element, block order), when given,
/// replaces it element by element. Throws NumericalError naming the element if a volume is not
/// positive.
void hex8_initialise(Hex8Block& b, const double* x_ref,
                     const std::array<double, 9>& material_axes_global,
                     const double* element_axes = nullptr);

/// Length of a hexahedron (corners x, VTK order) along each of the axes (row-major, axes as
/// columns): its volume over the area of its projection on the plane normal to the axis (a box's
/// edge lengths along its own axes). The crack-band width of a crack normal to the axis.
std::array<double, 3> hex8_axis_lengths(const double (&x)[8][3], const std::array<double, 9>& axes);

/// Element nodal masses (rho V / 8) added into `mass` [3*n_nodes].
void hex8_lumped_mass(const Hex8Block& b, double* mass);

/// Stable time step of every element: the larger of two bounds on the uniform-strain frequency,
/// the characteristic length V/A_max over the wave speed of the largest modulus (Flanagan-
/// Belytschko), and, for an anisotropic material, the directional bound (step_modulus), exact for
/// a parallelepiped at rest, which pairs
/// each modulus with the element's length along its axis (a tow: fibre modulus with the tow
/// length, compaction with the thickness). An eroded element has none (1e300). With
/// `corner_jacobian`, also the smallest corner Jacobian of each element (the triple product of
/// the three edges leaving a corner, over the reference volume; 1 for an undistorted box, <= 0
/// where the element folds over at that corner, which the one-point volume does not see; 1 for
/// an eroded element).
StableStep hex8_stable_step(const Hex8Block& b, const double* x);
/// in_range: only the elements of this rank's range (b.range_begin..range_end) are measured,
/// the others get a step of 1e300 and a corner Jacobian of 1 (several ranks: they are another
/// rank's, and this rank's copies of their nodes may be stale). min_density > 0: only elements
/// at least that dense are measured (the others: 1e300, as eroded ones), e.g. those at the cap of
/// dynamic mass scaling.
void hex8_element_steps(const Hex8Block& b, const double* x, std::vector<double>& dt,
                        std::vector<double>* corner_jacobian = nullptr, bool in_range = false,
                        double min_density = 0);

/// Nodal internal forces f[8][3] (VTK node order of element e) that element e exerts on its
/// nodes at positions x with velocities v, from its current state: what hex8_internal_forces
/// adds for it with a zero step (stress and stabilisation as they stand, viscous hourglass part
/// from v). The block is not changed.
void hex8_element_force(const Hex8Block& b, std::size_t e, const double* x, const double* v,
                        double f[24]);

/// Erodes element e: from now on it adds no force, no energy and no step limit; its nodes keep
/// their mass. Returns the elastic energy it held, 1/2 S:E V0 (exact for a linear law in
/// Green-Lagrange strain), which leaves the model with it.
double hex8_erode(Hex8Block& b, std::size_t e);

/// Internal forces at positions x with velocities v (that moved the nodes over the last step dt):
/// updates stress and hourglass state, subtracts internal forces from f [3*n_nodes], accumulates
/// energy increments and the stable step. Throws NumericalError on a negative or NaN volume.
/// Eroded elements are evaluated at the reference positions x_ref at rest, with zero stress (no
/// force, no work, whatever their nodes do); x_ref may be null while the block has none.
void hex8_internal_forces(Hex8Block& b, const double* x, const double* v, double dt, double* f,
                          ElementEnergyIncrement& energy, StableStep& step,
                          const double* x_ref = nullptr);

// The block behind an element group (fem/elements/block_of.hpp), null for another kind.
template <>
Hex8Block* block_of<Hex8Block>(ElementGroup& g);
template <>
const Hex8Block* block_of<Hex8Block>(const ElementGroup& g);

}  // namespace ncfsim::fem
