#pragma once
// Shared by the deck writers (transfer/deck_*.cpp): the model's checks and the geometry a deck
// derives from it. Not part of the module's interface (transfer/deck_export.hpp is).
#include <array>
#include <string>
#include <vector>

#include "transfer/deck_export.hpp"

namespace ncfsim::transfer::deck {

/// Throws std::invalid_argument when the model is inconsistent (sizes, indices, a crush without
/// its per-material data).
void check(const ExportModel& m);

/// A part of the deck: the elements of one group (ply) and one material.
struct DeckPart {
  std::int32_t group = 0, material = 0;
  std::string name;
};
/// The parts in (group, material) order and each element's part index.
std::vector<DeckPart> tow_parts(const ExportModel& m, std::vector<std::int32_t>& part_of);

/// Volume of hexahedron e (six tetrahedra on its 0-6 diagonal: exact for a trilinear brick).
double hex_volume(const ExportModel& m, std::size_t e);

/// Mean element size per material, the cube root of the mean volume (m): the length the
/// rupture strains of a law written as strains are made with (a crack band of the mean element).
std::vector<double> mean_element_length(const ExportModel& m);

/// A rigid tool as a mesh of 4-node facets (a degenerate quad closes a sphere's pole), in the
/// tool's position: a sphere's half towards the body (below its centre against the motion), a
/// plane's square of side 2 half_size.
struct ToolMesh {
  std::vector<std::array<double, 3>> nodes;
  std::vector<std::array<std::int32_t, 4>> quads;  // 0-based into nodes, outward
};
ToolMesh tool_mesh(const ExportTool& t);

/// The directions (x, y, z) a rigid tool is held in: those it does not move along. LS-DYNA's
/// prescribed motion and OpenRadioss's IMPVEL read a zero scale as 1, so a direction at rest is
/// held (CON1, BCS) rather than given a zero velocity.
inline std::array<bool, 3> held_directions(const ExportTool& t) {
  return {t.velocity[0] == 0, t.velocity[1] == 0, t.velocity[2] == 0};
}

/// The smooth ramp of a tool's velocity (cubic, as the engine's smooth_ramp) as (time, factor)
/// points to the end time.
std::vector<std::array<double, 2>> ramp_curve(double ramp_time, double end_time);

/// A number in a fixed field of `width` characters, as many digits as fit.
std::string field(double v, int width = 10);

}  // namespace ncfsim::transfer::deck
