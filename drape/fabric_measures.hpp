#pragma once
// Measures of a formed fabric taken on plain arrays (current element centroids, convected fibre
// directions, hexahedron connectivity), so that the run, the results reader and the tests share
// them:
//  * the inter-ply shear angle of each tow element: 90 deg minus the angle between its fibre
//    direction and that of the nearest element (current centroids) of the other ply;
//  * the outer faces of a set of hexahedra as triangles, and element values averaged to their
//    nodes: the surface the ring measure (drape/ring_measure.hpp) reads.
#include <array>
#include <cstdint>
#include <vector>

#include "fem/vec3.hpp"

namespace ncfsim::drape {

/// For every element of `ply_a` (indices into centroid), writes into nearest[e] the element of
/// `ply_b` whose centroid is nearest (within `reach` m; -1 where none is). nearest is sized like
/// centroid.
void nearest_in_other_ply(const std::vector<fem::V3>& centroid, const std::vector<std::int32_t>& ply_a,
                          const std::vector<std::int32_t>& ply_b, double reach,
                          std::vector<std::int32_t>& nearest);

/// For every element of `ply_a` (indices into centroid/fibre), writes into shear_deg[e] the shear
/// angle against the nearest element of `ply_b` (within `reach` m of its centroid; NaN where none
/// is). shear_deg must be sized like centroid.
void interply_shear_deg(const std::vector<fem::V3>& centroid, const std::vector<fem::V3>& fibre,
                        const std::vector<std::int32_t>& ply_a,
                        const std::vector<std::int32_t>& ply_b, double reach,
                        std::vector<double>& shear_deg);

/// Faces of the hexahedra `elements` (conn: 8 node indices per hexahedron, VTK order) not shared
/// by two of them, two triangles each.
std::vector<std::array<std::int32_t, 3>> outer_face_triangles(
    const std::vector<std::array<std::int32_t, 8>>& conn,
    const std::vector<std::int32_t>& elements);

/// Mean of the finite element values of `elements` at each of their nodes (0 at nodes they do not
/// touch); n_nodes values.
std::vector<double> element_to_node_mean(const std::vector<std::array<std::int32_t, 8>>& conn,
                                         const std::vector<std::int32_t>& elements,
                                         const std::vector<double>& value, std::size_t n_nodes);

}  // namespace ncfsim::drape
