#pragma once
// Export of the impregnated model for users who run the crush in their own solver: an Abaqus input
// file (C3D8R solids, one *ORIENTATION per element through a *DISTRIBUTION of local axes, one
// *MATERIAL / *SOLID SECTION per material class, *TIE pairs between surfaces given as element
// faces) and an LS-DYNA keyword deck (*ELEMENT_SOLID_ORTHO with the fibre axis per element,
// *MAT_ORTHOTROPIC_ELASTIC per class, *CONTACT_TIED_SURFACE_TO_SURFACE between segment sets).
// With a crush (ExportCrush, from a crush case) the LS-DYNA deck is the whole crush: the tows'
// per-mode failure law (*MAT_262), the resin bonds as tiebreak contacts that soften, the rigid
// punch and support with the punch's motion, the plies' contact, controls and outputs
// (docs/export.md says what maps to what). Plain text; the reader below reads back what these
// writers write (the counts, the local axes and the crush's cards), so the round trip is tested.
#include <array>
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "fem/material.hpp"

namespace ncfsim::transfer {

struct ExportMaterial {
  std::string name;
  double density = 0;
  fem::OrthotropicConstants elastic{};
};

/// One slave node of a tied interface as the crush ties it: held at the point sum_a N_a x_a of a
/// master face by a penalty spring of stiffness k in every direction; it fails on its bond's
/// strength times its tributary area.
struct ExportTiePoint {
  std::int32_t node = 0;                 // 0-based
  std::array<std::int32_t, 4> corner{};  // the master face's corners, 0-based
  std::array<double, 4> weight{};        // N_a at the tied point
  double stiffness = 0;                  // N/m
  double area = 0;                       // m^2
};

/// A tied interface: faces (element index, face 0..5 in VTK-hexahedron face order: -z, +z, -y,
/// +x, +y, -x of the reference cube) of the slave and master sides.
struct ExportTie {
  std::string name;
  std::vector<std::pair<std::int32_t, int>> slave, master;
  /// The crush's own ties (a crush case's export; fem/contact/tied_contact.hpp): a deck whose
  /// solver has no tie like ncfsim's builds them from these (OpenRadioss: a spring per point).
  std::vector<ExportTiePoint> points;
};

/// Kept stitches: tension-only yarn bars between model nodes (Abaqus T3D2 with *NO COMPRESSION,
/// LS-DYNA cable: *SECTION_BEAM ELFORM 6 with its area and *MAT_CABLE_DISCRETE_BEAM).
struct ExportStitches {
  std::vector<std::array<std::int32_t, 2>> bars;  // 0-based node indices
  double modulus = 0, area = 0, density = 0;      // Pa, m^2, kg/m^3
  /// Nodes of the yarn tied to the tow faces they lie on (a crush's; LS-DYNA
  /// *CONTACT_TIED_NODES_TO_SURFACE onto the tows).
  std::vector<std::int32_t> tied_nodes;
};

/// Per material: the tow damage law's failure data (impact/tow_damage_material.hpp).
struct ExportFailure {
  double Xt = 0, Xc = 0, Yt = 0, Yc = 0, S12 = 0, S23 = 0;  // Pa
  /// J/m^2, in the law's mode order: fibre tension, fibre compression, matrix tension, matrix
  /// compression, in-plane shear, transverse shear.
  std::array<double, 6> fracture_energy{};
  double residual_compression = 0;  // share of Xc, Yc a crushed tow still carries
  /// Modes whose full damage erodes the element, in the same order (the law's erode_on).
  std::array<bool, 6> erode_on{true, true, false, false, false, false};
};

/// Per tie: the bilinear mixed-mode cohesive law of a resin bond (fem/contact/cohesive_law.hpp).
struct ExportBond {
  double normal_strength = 0, shear_strength = 0;  // Pa
  double mode_i_energy = 0, mode_ii_energy = 0;    // J/m^2
  double bk_exponent = 1.45;                       // Benzeggagh-Kenane
};

/// A rigid tool of the crush: a sphere (the punch's tip) or a plane (the support).
struct ExportTool {
  std::string name;
  bool sphere = false;
  std::array<double, 3> point{};        // sphere centre, or a point of the plane
  std::array<double, 3> axis{0, 0, 1};  // plane: unit normal towards the body
  double radius = 0;                    // sphere
  double half_size = 0;                 // plane: half the side of the square plate written, m
  std::array<double, 3> velocity{};     // m/s after the ramp; zero: held fixed
  double ramp_time = 0;                 // s, smooth (cubic) ramp from rest
  double friction = 0;
};

/// What a crush case adds around the model, so that a deck crushes what `ncfsim run CASE` does.
struct ExportCrush {
  bool enabled = false;
  std::string name;                    // the case's
  std::vector<ExportFailure> failure;  // per material
  std::vector<ExportBond> bonds;       // per tie
  std::vector<ExportTool> tools;
  int punch = -1;            // index into tools: its force is the crush's measure
  bool ply_contact = false;  // the plies push on each other once debonded
  double ply_friction = 0;
  double end_time = 0;            // s
  double history_interval = 0;    // s, force and energies
  double frame_interval = 0;      // s, field output
  double safety_factor = 0.9;     // of the stable step
  double first_step = 0;          // s, ncfsim's first step (its ties' stiffness is set by it)
  double erosion_step_ratio = 0;  // 0: none; else a hexahedron whose step falls below
                                  // this share of the first is eroded
  /// Elements whose fracture energy ncfsim raises to their crack band, per mode (the deck's
  /// solver regularises with its own characteristic length: said in the deck).
  std::array<std::size_t, 6> raised_elements{};
};

struct ExportModel {
  std::vector<std::array<double, 3>> nodes;
  std::vector<std::array<std::int32_t, 8>> hex;  // 0-based node indices, VTK order
  std::vector<std::array<double, 9>> frame;      // per element, row-major, axes as columns
  std::vector<std::int32_t> material;            // per element, index into materials
  std::vector<ExportMaterial> materials;
  std::vector<ExportTie> ties;
  ExportStitches stitches;
  /// Per element: its group (a ply: a part per group and material in the LS-DYNA deck), or
  /// empty: one group.
  std::vector<std::int32_t> group;
  std::vector<std::string> group_names;
  ExportCrush crush;
};

/// What a deck of this format carries of the model and what it leaves out, a line each (the
/// export command prints them; docs/export.md).
struct DeckContents {
  std::vector<std::string> carried, left_out;
};
DeckContents deck_contents(const ExportModel& m, const std::string& format);

/// Written atomically (fem/io/atomic_file.hpp); throw std::runtime_error naming the file.
void write_abaqus_inp(const std::filesystem::path& file, const ExportModel& m);
void write_lsdyna_keyword(const std::filesystem::path& file, const ExportModel& m);
/// OpenRadioss block format, a crush only: dir/<name>_0000.rad (starter) and _0001.rad (engine),
/// returned in that order.
std::vector<std::filesystem::path> write_radioss_deck(const std::filesystem::path& dir,
                                                      const ExportModel& m);

struct DeckCounts {
  std::size_t nodes = 0, elements = 0, orientations = 0, materials = 0, ties = 0;
  std::size_t bars = 0;  // stitch elements (counted in elements too)
  // The crush's cards: per-mode failure materials, bonds that soften (LS-DYNA) or fail (Radioss),
  // rigid tool parts and their shell elements, prescribed motions, plies' contacts, the end time
  // (0: none).
  std::size_t failure_materials = 0, softening_ties = 0, rigid_parts = 0, tool_elements = 0;
  std::size_t tie_points = 0;  // Radioss: the ties' /RBE3 points (a spring each)
  std::size_t motions = 0, contacts = 0;
  double end_time = 0;
  std::vector<std::array<double, 6>>
      axes;  // per element as read: a1 and a2 (Abaqus) or a1 and v (LS-DYNA)
};
/// Reads back a deck written above ("abaqus", "lsdyna", or "radioss": the starter file, and the
/// end time from the engine file beside it). Throws std::runtime_error on a malformed file.
DeckCounts read_deck(const std::filesystem::path& file, const std::string& format);

}  // namespace ncfsim::transfer
