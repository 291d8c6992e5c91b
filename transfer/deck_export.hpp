#pragma once
// Export of the impregnated model for users who run the crush in their own solver: an Abaqus input
// file (C3D8R solids, one *ORIENTATION per element through a *DISTRIBUTION of local axes, one
// *MATERIAL / *SOLID SECTION per material class, *TIE pairs between surfaces given as element
// faces) and an LS-DYNA keyword deck (*ELEMENT_SOLID_ORTHO with the fibre axis per element,
// *MAT_ORTHOTROPIC_ELASTIC per class, *CONTACT_TIED_SURFACE_TO_SURFACE between segment sets).
// Both are plain text; the reader below reads back what these writers write (the counts and the
// local axes), so the round trip is tested.
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

/// A tied interface: faces (element index, face 0..5 in VTK-hexahedron face order: -z, +z, -y,
/// +x, +y, -x of the reference cube) of the slave and master sides.
struct ExportTie {
  std::string name;
  std::vector<std::pair<std::int32_t, int>> slave, master;
};

/// Kept stitches: tension-only yarn bars between model nodes (Abaqus T3D2 with *NO COMPRESSION,
/// LS-DYNA cable: *SECTION_BEAM ELFORM 6 with its area and *MAT_CABLE_DISCRETE_BEAM).
struct ExportStitches {
  std::vector<std::array<std::int32_t, 2>> bars;  // 0-based node indices
  double modulus = 0, area = 0, density = 0;      // Pa, m^2, kg/m^3
};

struct ExportModel {
  std::vector<std::array<double, 3>> nodes;
  std::vector<std::array<std::int32_t, 8>> hex;  // 0-based node indices, VTK order
  std::vector<std::array<double, 9>> frame;      // per element, row-major, axes as columns
  std::vector<std::int32_t> material;            // per element, index into materials
  std::vector<ExportMaterial> materials;
  std::vector<ExportTie> ties;
  ExportStitches stitches;
};

/// Written atomically (fem/io/atomic_file.hpp); throw std::runtime_error naming the file.
void write_abaqus_inp(const std::filesystem::path& file, const ExportModel& m);
void write_lsdyna_keyword(const std::filesystem::path& file, const ExportModel& m);

struct DeckCounts {
  std::size_t nodes = 0, elements = 0, orientations = 0, materials = 0, ties = 0;
  std::size_t bars = 0;  // stitch elements (counted in elements too)
  std::vector<std::array<double, 6>>
      axes;  // per element as read: a1 and a2 (Abaqus) or a1 and v (LS-DYNA)
};
/// Reads back a deck written above ("abaqus" or "lsdyna"). Throws std::runtime_error on a
/// malformed file.
DeckCounts read_deck(const std::filesystem::path& file, const std::string& format);

}  // namespace ncfsim::transfer
