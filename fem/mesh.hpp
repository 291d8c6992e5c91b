#pragma once
// The finite-element mesh: reference node coordinates, hexahedra and bars, each element tagged
// with its part. Node and element numbers given by the user are kept for messages; internally
// elements are sorted along a space-filling curve and nodes numbered in the order the sorted
// elements first touch them, so that an element's nodes sit close together in memory.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace ncfsim::fem {

using Hex8Nodes = std::array<std::int32_t, 8>;  // VTK order: bottom face CCW, then top face
using Bar2Nodes = std::array<std::int32_t, 2>;

struct Mesh {
  std::vector<double> coords;            // reference coordinates [3*n_nodes], xyz interleaved
  std::vector<Hex8Nodes> hexes;
  std::vector<std::int32_t> hex_part;    // part index per hexahedron
  std::vector<Bar2Nodes> bars;
  std::vector<std::int32_t> bar_part;    // part index per bar
  std::vector<std::string> part_names;
  std::vector<std::int64_t> node_user_id;  // id for messages (defaults to 1-based input order)
  std::vector<std::int64_t> hex_user_id;
  std::vector<std::int64_t> bar_user_id;
  // Fabric tags per hexahedron: ply index within its blanket and tow index (-1: not a tow);
  // sized like `hexes` by fill_default_user_ids, kept with their element through renumbering.
  std::vector<std::int32_t> hex_ply;
  std::vector<std::int32_t> hex_tow;

  std::size_t n_nodes() const { return coords.size() / 3; }
  int add_part(const std::string& name);
  int find_part(const std::string& name) const;  // -1 when absent
  void fill_default_user_ids();
  /// Throws std::invalid_argument naming the first inconsistency (bad node index, bad part).
  void validate() const;
  std::array<double, 3> node(std::size_t i) const { return {coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]}; }
};

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
