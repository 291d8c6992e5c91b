#pragma once
// Contact surfaces: the outer faces (quadrilateral segments) of the hexahedra of the parts of
// each contact group, and the surface nodes. Built once before the time loop.
#include <cstdint>
#include <string>
#include <vector>

#include "fem/contact/contact_config.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::fem {

/// Segments and surface nodes of a list of groups. A mesh node on the surface of two groups gets
/// one surface-node entry per group. Surface nodes are sorted by (mesh node, group), so a loop
/// over them walks the nodal arrays forwards.
struct ContactSurface {
  std::vector<std::int32_t> seg_nodes;         // [n_seg][4] mesh nodes, CCW seen from outside
  std::vector<std::int32_t> seg_group;         // [n_seg] group index
  std::vector<std::int32_t> seg_elem_nodes;    // [n_seg][8] nodes of the hexahedron owning the face
  std::vector<std::int32_t> seg_surface_node;  // [n_seg][4] surface-node entry of each corner
  std::vector<double>
      seg_elem_thickness;  // [n_seg] owning hexahedron's thickness normal to the face at x0, m
  std::vector<std::int64_t> seg_elem_user_id;  // [n_seg] for messages
  std::vector<std::int32_t>
      seg_hex;  // [n_seg] owning element (mesh-wide index, Mesh::element_offset)
  // [n_seg] -1: an outer face; else an inner face (only with interior_faces), covered by this
  // hexahedron of the same group: a surface segment only once that one is eroded.
  std::vector<std::int32_t> seg_cover_hex;
  std::vector<std::int32_t> node;        // [n_snode] mesh node of each surface node
  std::vector<std::int32_t> node_group;  // [n_snode] group of each surface node
  std::vector<double>
      node_area;  // [n_snode] tributary area at x0 (quarter of each outer segment), m^2

  std::size_t n_segments() const { return seg_group.size(); }
  std::size_t n_nodes() const { return node.size(); }
};

/// How large extract_contact_surface's result for these groups will be, counted without building
/// it (the memory estimate): segments, surface nodes, and the nodes on outer faces (the ones that
/// get facets). Part indices outside the mesh are skipped (extract_contact_surface reports them).
struct ContactSurfaceSize {
  double segments = 0, nodes = 0, outer_nodes = 0;
};
ContactSurfaceSize contact_surface_size(const Mesh& mesh, const std::vector<ContactGroup>& groups,
                                        bool interior_faces);

/// Outer faces of each group (faces used by exactly one hexahedron of the group's parts). With
/// `interior_faces`, also each face shared by two hexahedra of a group, once from each side (as
/// the outer face of one, covered by the other), and their nodes: what erosion may uncover.
/// Throws InputError(file, key_prefix + ".groups", ...) for a part index outside the mesh, a part
/// without hexahedra, a part listed in two groups, or a group without parts.
ContactSurface extract_contact_surface(const Mesh& mesh, const std::vector<ContactGroup>& groups,
                                       const double* x0, const std::string& file,
                                       const std::string& key_prefix, bool interior_faces = false);

}  // namespace ncfsim::fem
