#pragma once
// The finite-element mesh: reference node coordinates and one element set per element kind, each
// element tagged with its part. Node and element numbers given by the user are kept for messages;
// internally elements are sorted along a space-filling curve and nodes numbered in the order the
// sorted elements first touch them, so that an element's nodes sit close together in memory.
#include <array>
#include <cstdint>
#include <initializer_list>
#include <span>
#include <string>
#include <vector>

#include "fem/elements/element_kind.hpp"

namespace ncfsim::fem {

/// The elements of one kind: connectivity and per-element tags, all indexed by the element's
/// position in the set.
struct ElementSet {
  ElementKind kind = ElementKind::Hex8;
  int nodes_per_element = 8;
  std::vector<std::int32_t> conn;     // [n][nodes_per_element] (hexahedra: VTK order)
  std::vector<std::int32_t> part;     // [n] part index
  std::vector<std::int64_t> user_id;  // [n] id for messages (defaults to 1-based input order)
  // Fabric tags: ply index within its blanket and tow index (-1: none); sized like `part` by
  // fill_default_user_ids, kept with their element through renumbering.
  std::vector<std::int32_t> ply;
  std::vector<std::int32_t> tow;
  // Per-element material axes [n][9] (row-major, axes as columns, global), or empty: the part's
  // (PartProperties::material_axes). A formed part's tows each have their own fibre direction.
  std::vector<double> material_axes;
  // Per-element material (index into Model::materials; -1: the part's), or empty: the part's. A
  // formed part's tows each have their fibre volume fraction, so their own impregnated material.
  std::vector<std::int32_t> material;

  std::size_t size() const { return part.size(); }
  bool empty() const { return part.empty(); }
  std::span<const std::int32_t> nodes(std::size_t e) const {
    return {conn.data() + e * static_cast<std::size_t>(nodes_per_element),
            static_cast<std::size_t>(nodes_per_element)};
  }
  std::span<std::int32_t> nodes(std::size_t e) {
    return {conn.data() + e * static_cast<std::size_t>(nodes_per_element),
            static_cast<std::size_t>(nodes_per_element)};
  }
  /// Appends an element (nodes_per_element node indices) of part `part_index`.
  void add(std::span<const std::int32_t> element_nodes, int part_index);
  void add(std::initializer_list<std::int32_t> element_nodes, int part_index) {
    add(std::span<const std::int32_t>(element_nodes.begin(), element_nodes.size()), part_index);
  }
};

struct Mesh {
  std::vector<double> coords;    // reference coordinates [3*n_nodes], xyz interleaved
  std::vector<ElementSet> sets;  // at most one per kind, in ElementKind order (see elements())
  std::vector<std::string> part_names;
  std::vector<std::int64_t> node_user_id;  // id for messages (defaults to 1-based input order)

  std::size_t n_nodes() const { return coords.size() / 3; }
  /// The set of a kind, created (empty, in kind order) when absent.
  ElementSet& elements(ElementKind kind);
  /// The set of a kind; an empty set when the mesh has none.
  const ElementSet& elements(ElementKind kind) const;
  const ElementSet* find_set(ElementKind kind) const;
  std::size_t n_elements(ElementKind kind) const { return elements(kind).size(); }
  std::size_t n_elements() const;
  /// Elements of the sets before `kind` (a mesh-wide element index is this plus the set index).
  std::size_t element_offset(ElementKind kind) const;
  /// Calls f(node) for every node of every element of part `part` (a node as often as it is used).
  template <class F>
  void for_each_element_node(int part, F&& f) const {
    for (const auto& s : sets)
      for (std::size_t e = 0; e < s.size(); ++e)
        if (s.part[e] == part)
          for (auto node : s.nodes(e)) f(node);
  }

  int add_part(const std::string& name);
  int find_part(const std::string& name) const;  // -1 when absent
  void fill_default_user_ids();
  /// Throws std::invalid_argument naming the first inconsistency (bad node index, bad part).
  void validate() const;
  std::array<double, 3> node(std::size_t i) const {
    return {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]};
  }
};

/// Position of point c along the Morton curve of the box [lo, lo + span] (21 bits per axis): the
/// order renumber_for_locality sorts elements in (by centroid, the box of all nodes).
std::uint64_t morton_key(const std::array<double, 3>& c, const std::array<double, 3>& lo,
                         const std::array<double, 3>& span);
/// Reorders elements along a Morton curve of their centroids and renumbers nodes by first use.
/// Returns the new-from-old node map (new_index = map[old_index]).
std::vector<std::int32_t> renumber_for_locality(Mesh& mesh);

/// Hexahedra of a structured node grid already in the mesh: node (i, j, k) is
/// first + i + (nx + 1) (j + (ny + 1) k), cells = {nx, ny, nz}; (i, j) counter-clockwise seen from
/// +k (VTK order, positive volume when the grid axes are right-handed).
void append_grid_hexes(Mesh& mesh, int part, std::int32_t first, const std::array<int, 3>& cells);

/// A structured block of hexahedra (origin, edge lengths, divisions), appended to `mesh`.
/// Returns the node indices of the block in i-fastest order [(nx+1)*(ny+1)*(nz+1)].
std::vector<std::int32_t> add_hex_block(Mesh& mesh, int part, const std::array<double, 3>& origin,
                                        const std::array<double, 3>& size,
                                        const std::array<int, 3>& divisions);

}  // namespace ncfsim::fem
