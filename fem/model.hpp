#pragma once
// Everything the explicit solver needs, checked before the time loop starts: mesh, materials,
// part properties, constraints, loads, tools and time controls. Node lists refer to the mesh's
// (renumbered) node indices.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "fem/elements/bar_block.hpp"
#include "fem/contact_interface.hpp"
#include "fem/boundary/picture_frame.hpp"
#include "fem/material.hpp"
#include "fem/membrane_law.hpp"
#include "fem/mesh.hpp"
#include "fem/rigid_tool.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::fem {

constexpr std::array<double, 9> kIdentityAxes{1, 0, 0, 0, 1, 0, 0, 0, 1};

// What a part's elements need, by kind: the kind itself comes from the mesh (the element set the
// part's elements are in); each group reads the fields of its kind (fem/elements/*_group.cpp).
struct PartProperties {
  int material = -1;  // index into Model::materials (solids)
  int bar_law = -1;   // index into Model::bar_laws (bars)
  std::array<double, 9> material_axes = kIdentityAxes;  // row-major, axes as columns, global
  double hourglass_stiffness = 1.0;
  double hourglass_viscosity = 0.05;
  // Shells (Quad4): the section. A membrane law (a dry fabric) or the part's `material` (elastic
  // isotropic, plane stress, integrated at Gauss points through the thickness).
  double shell_thickness = 0;        // m
  int shell_integration_points = 2;  // through the thickness
  int membrane_law = -1;             // index into Model::membrane_laws
};

struct FixedDofs {
  std::string name;
  std::vector<std::int32_t> nodes;
  std::array<bool, 3> dofs{true, true, true};
  std::array<bool, 3> rotations{false, false, false};  // shell nodes' rotations about x, y, z
};

struct PrescribedVelocity {
  std::string name;
  std::vector<std::int32_t> nodes;
  std::array<bool, 3> dofs{false, false, false};  // which components are prescribed
  V3 velocity;                                     // value after the ramp
  double ramp_time = 0;                            // smooth ramp from 0
  double start_time = 0;                           // zero before this time
};

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
  // Mass scaling again during the run: a hexahedron whose step falls below mass_scaling_dt gets
  // mass so that it is back 5 % above it (dynamic mass scaling, as forming codes do), up to
  // mass_scaling_max_ratio times its physical mass added; beyond, its step falls (and it is
  // eroded at erosion_step_ratio): a folding element would otherwise take mass without bound.
  bool mass_scaling_dynamic = false;
  double mass_scaling_max_ratio = 10.0;
  // An element at that cap whose step still falls below mass_scaling_dt is eroded at once
  // (mass scaling cannot hold it any more), so the run keeps its step.
  bool mass_scaling_erode_at_cap = false;
  double history_interval = 0;      // 0: 200 rows over the run
  double frame_interval = 0;        // 0: 20 frames over the run
  std::int64_t max_cycles = 0;      // 0: unlimited
  double energy_balance_limit = 0.05;
  // Quasi-static check: kinetic / internal energy is tracked from this time on (s; forming runs
  // read it after the blankholder has closed) and warned about above the limit (0: never).
  double quasi_static_from = 0;
  double kinetic_to_internal_limit = 0;
  double min_step_ratio = 1e-4;     // stop when the step falls below this share of the initial one
  double erosion_step_ratio = 0;    // 0: off; else erode an element (hexahedra) whose step falls below this
                                    // share of the initial one (LS-DYNA's ERODE with DTMIN)
};

// Runs on several MPI ranks (docs/parallel.md).
struct ParallelControl {
  // How far from its own surface nodes a rank keeps the remote contact segments (the contact
  // halo): surfaces that slide further than this relative to each other across a partition
  // boundary between two builds of the halo are not seen (the run stops, naming it), m.
  double contact_halo = 0.01;
  // The halo is built again at the nodes' current positions once they may have slid this share
  // of it relative to each other (a pass over the owned nodes and a max over the ranks decide,
  // when a running bound on the nodes' travel says it could be so); 0: fixed at the start.
  double contact_halo_refresh = 0.25;
};

struct Model {
  Mesh mesh;
  std::vector<std::unique_ptr<SolidMaterial>> materials;
  std::vector<BarForceLaw> bar_laws;
  std::vector<std::unique_ptr<MembraneLaw>> membrane_laws;  // shells' membrane laws
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
  ParallelControl parallel;
};

}  // namespace ncfsim::fem
