#pragma once
// The element kinds the engine knows, with what the rest of the code may ask of a kind without
// naming it: nodes per element, names for messages and output files, and the faces that bound a
// solid element (contact surfaces are made of them). A new kind adds an enumerator here, a row in
// each table below and a group in fem/elements/ (docs/architecture.md).
#include <array>
#include <cstdint>
#include <span>

namespace ncfsim::fem {

/// Kinds in the order the mesh keeps its element sets and the solver its groups (renumbering and
/// the order in which element forces are summed depend on it: append new kinds at the end).
enum class ElementKind : std::uint8_t { Hex8, Bar2, Quad4 };
constexpr std::array<ElementKind, 3> kElementKinds{ElementKind::Hex8, ElementKind::Bar2,
                                                   ElementKind::Quad4};
constexpr int kMaxNodesPerElement = 8;

constexpr int nodes_per_element(ElementKind k) {
  constexpr int n[] = {8, 2, 4};
  return n[static_cast<int>(k)];
}
/// Noun for messages ("hexahedron 12 at ...").
constexpr const char* element_noun(ElementKind k) {
  constexpr const char* n[] = {"hexahedron", "bar", "shell"};
  return n[static_cast<int>(k)];
}
/// Plural noun for counts in messages ("1200 hexahedra").
constexpr const char* element_plural(ElementKind k) {
  constexpr const char* n[] = {"hexahedra", "bars", "shells"};
  return n[static_cast<int>(k)];
}
/// Short name for output and summaries ("hex8").
constexpr const char* element_kind_name(ElementKind k) {
  constexpr const char* n[] = {"hex8", "bar2", "quad4"};
  return n[static_cast<int>(k)];
}

/// What the result files (fem/io/result_writers.hpp) call a kind's arrays and how they draw it:
/// /mesh/<element_kind_name> (connectivity, and the frames' cell-field group), /mesh/<part>,
/// /mesh/<user_id>, /mesh/<material> (an index into material_names, or into bar_law_names for a
/// kind whose law is a bar law), its results.xdmf grid and topology, its VTK cell type.
struct ElementOutput {
  const char* part;
  const char* user_id;
  const char* material;
  bool bar_law;          // material indexes the bar laws
  bool always_in_file;   // /mesh/<name> and <part> written even when empty (files before shells)
  const char* grid;      // results.xdmf Uniform grid
  const char* topology;  // its Topology attributes
  int vtk_cell_type;     // VTK_HEXAHEDRON, VTK_LINE, VTK_QUAD
};
constexpr ElementOutput element_output(ElementKind k) {
  constexpr ElementOutput o[] = {{"hex_part", "hex_user_id", "hex_material", false, true, "solids",
                                  "TopologyType=\"Hexahedron\"", 12},
                                 {"bar_part", "bar_user_id", "bar_material", true, true, "bars",
                                  "TopologyType=\"Polyline\" NodesPerElement=\"2\"", 3},
                                 {"quad_part", "quad_user_id", "quad_material", false, false,
                                  "shells", "TopologyType=\"Quadrilateral\"", 9}};
  return o[static_cast<int>(k)];
}

/// What one element of a kind costs in memory, bytes (fem/memory_estimate.cpp; counted from the
/// arrays, but `figures`, measured: docs/performance.md, "Memory"). Every kind's row is summed
/// alike, so a new kind's memory is this row.
struct ElementMemory {
  const char* share;            // the estimate's line ("hexahedra")
  double fixed;                 // integers (and any fixed doubles) of the group and the mesh
  double doubles;               // doubles of the group's state, before the material law's history
  bool law_history;             // + the law's history doubles, kept per element by the group
  double own_axes;              // per-element material axes and material (a formed part's mesh)
  double node_arrays_per_part;  // per node of the model, for each part of the kind (own group)
  double writer;                // each result writer's copy of the cells
  double vtu;                   // the VTU writer's own topology
  double checkpoint;            // a checkpoint's copy of the element's state
  double figures;               // what the figures drawn at the end add
};
constexpr ElementMemory element_memory(ElementKind k) {
  constexpr ElementMemory m[] = {{"hexahedra", 48 + 52 + 16, 75, true, 76, 0, 88, 77, 8 * 38, 1770},
                                 {"bars", 88, 0, false, 0, 0, 32, 0, 0, 0},
                                 {"shells", 32 + 36, 41, false, 0, 59, 56, 0, 0, 0}};
  return m[static_cast<int>(k)];
}

/// A two-node element must join two different nodes (checked by Mesh::validate).
constexpr bool element_needs_distinct_nodes(ElementKind k) { return nodes_per_element(k) == 2; }

/// A quadrilateral face of a solid element: corners (local node numbers) counter-clockwise seen
/// from outside, and the face opposite it (its distance is the element's thickness behind the
/// face).
struct ElementFace {
  std::array<int, 4> corner;
  int opposite;
};
/// Faces of a solid kind (VTK hexahedron order); empty for a kind that bounds no volume.
constexpr std::array<ElementFace, 6> kHex8Faces{{{{0, 3, 2, 1}, 1},
                                                 {{4, 5, 6, 7}, 0},
                                                 {{0, 1, 5, 4}, 4},
                                                 {{1, 2, 6, 5}, 5},
                                                 {{2, 3, 7, 6}, 2},
                                                 {{3, 0, 4, 7}, 3}}};
inline std::span<const ElementFace> element_faces(ElementKind k) {
  if (k == ElementKind::Hex8) return kHex8Faces;
  return {};
}

}  // namespace ncfsim::fem
