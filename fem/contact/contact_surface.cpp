#include "fem/contact/contact_surface.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include "fem/errors.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::fem {

namespace {

// Element faces (fem/elements/element_kind.hpp): corners counter-clockwise seen from outside
// (outward normal by the right-hand rule), and the face opposite each.
struct FaceRecord {
  std::array<std::int32_t, 4> key;  // sorted corners
  std::int32_t hex;                 // mesh-wide element index
  std::int32_t face;
  std::int32_t set;   // in Mesh::sets
  std::int32_t elem;  // in its set
  bool operator<(const FaceRecord& o) const { return key < o.key; }
};

V3 node_at(const double* x, std::int32_t i) { return V3::at(x + 3 * static_cast<std::size_t>(i)); }

// The faces of group g's elements (group_of_part[part] == g), sorted by their corners: a key
// found once is an outer face of the group, twice a face between two of its elements.
void group_faces(const Mesh& mesh, const std::vector<int>& group_of_part, int g,
                 std::vector<FaceRecord>& faces) {
  faces.clear();
  for (std::size_t q = 0; q < mesh.sets.size(); ++q) {
    const ElementSet& set = mesh.sets[q];
    const auto kface = element_faces(set.kind);
    const std::size_t offset = mesh.element_offset(set.kind);
    for (std::size_t e = 0; e < set.size() && !kface.empty(); ++e) {
      if (group_of_part[static_cast<std::size_t>(set.part[e])] != g) continue;
      const auto h = set.nodes(e);
      for (std::size_t f = 0; f < kface.size(); ++f) {
        FaceRecord r;
        for (int k = 0; k < 4; ++k) r.key[k] = h[static_cast<std::size_t>(kface[f].corner[k])];
        std::sort(r.key.begin(), r.key.end());
        r.hex = static_cast<std::int32_t>(offset + e);
        r.face = static_cast<std::int32_t>(f);
        r.set = static_cast<std::int32_t>(q);
        r.elem = static_cast<std::int32_t>(e);
        faces.push_back(r);
      }
    }
  }
  std::sort(faces.begin(), faces.end());
}

}  // namespace

ContactSurface extract_contact_surface(const Mesh& mesh, const std::vector<ContactGroup>& groups,
                                       const double* x0, const std::string& file,
                                       const std::string& key_prefix, bool interior_faces) {
  const std::string key = key_prefix + ".groups";
  const auto n_parts = static_cast<int>(mesh.part_names.size());
  std::vector<int> group_of_part(static_cast<std::size_t>(n_parts), -1);
  for (std::size_t g = 0; g < groups.size(); ++g) {
    if (groups[g].parts.empty())
      throw InputError(file, key, "group '" + groups[g].name + "' lists no parts");
    for (int p : groups[g].parts) {
      if (p < 0 || p >= n_parts)
        throw InputError(file, key,
                         "group '" + groups[g].name + "' names part index " + std::to_string(p) +
                             ", outside 0.." + std::to_string(n_parts - 1));
      auto& owner = group_of_part[static_cast<std::size_t>(p)];
      if (owner >= 0 && owner != static_cast<int>(g))
        throw InputError(file, key,
                         "part '" + mesh.part_names[static_cast<std::size_t>(p)] +
                             "' is in groups '" + groups[static_cast<std::size_t>(owner)].name +
                             "' and '" + groups[g].name + "' of one contact");
      owner = static_cast<int>(g);
    }
  }
  std::vector<std::size_t> hexes_of_part(static_cast<std::size_t>(n_parts), 0);
  for (const ElementSet& set : mesh.sets)
    if (!element_faces(set.kind).empty())
      for (auto p : set.part) ++hexes_of_part[static_cast<std::size_t>(p)];
  for (const auto& grp : groups)
    for (int p : grp.parts)
      if (hexes_of_part[static_cast<std::size_t>(p)] == 0)
        throw InputError(file, key,
                         "part '" + mesh.part_names[static_cast<std::size_t>(p)] + "' of group '" +
                             grp.name + "' holds no hexahedra (contact surfaces are hex faces)");

  ContactSurface s;
  std::vector<FaceRecord> faces;
  for (std::size_t g = 0; g < groups.size(); ++g) {
    group_faces(mesh, group_of_part, static_cast<int>(g), faces);
    for (std::size_t i = 0; i < faces.size();) {
      std::size_t j = i + 1;
      while (j < faces.size() && faces[j].key == faces[i].key) ++j;
      // Used by exactly one hexahedron of the group: an outer face; by two: an inner face, a
      // segment from each side (dormant until the other hexahedron is eroded).
      const bool inner = j == i + 2 && interior_faces;
      for (std::size_t r = i; r < (inner ? i + 2 : (j == i + 1 ? i + 1 : i)); ++r) {
        const ElementSet& set = mesh.sets[static_cast<std::size_t>(faces[r].set)];
        const auto elem = static_cast<std::size_t>(faces[r].elem);
        const auto h = set.nodes(elem);
        const ElementFace& face = element_faces(set.kind)[static_cast<std::size_t>(faces[r].face)];
        const auto& fc = face.corner;
        const auto& oc = element_faces(set.kind)[static_cast<std::size_t>(face.opposite)].corner;
        auto at = [&](int local) { return h[static_cast<std::size_t>(local)]; };
        V3 c, co;
        for (int k = 0; k < 4; ++k) {
          c += 0.25 * node_at(x0, at(fc[k]));
          co += 0.25 * node_at(x0, at(oc[k]));
        }
        const V3 a = node_at(x0, at(fc[2])) - node_at(x0, at(fc[0]));
        const V3 b = node_at(x0, at(fc[3])) - node_at(x0, at(fc[1]));
        const V3 n = normalized(cross(a, b));
        for (int k = 0; k < 4; ++k) s.seg_nodes.push_back(at(fc[k]));
        for (auto v : h) s.seg_elem_nodes.push_back(v);
        s.seg_group.push_back(static_cast<std::int32_t>(g));
        s.seg_elem_thickness.push_back(std::abs(dot(co - c, n)));
        s.seg_elem_user_id.push_back(set.user_id.size() == set.size()
                                         ? set.user_id[elem]
                                         : static_cast<std::int64_t>(elem) + 1);
        s.seg_hex.push_back(faces[r].hex);
        s.seg_cover_hex.push_back(inner ? faces[r == i ? i + 1 : i].hex : -1);
      }
      i = j;
    }
  }

  // Surface nodes: unique (node, group), sorted.
  const std::size_t n_seg = s.n_segments();
  std::vector<std::int64_t> keys(4 * n_seg);
  const auto n_groups = static_cast<std::int64_t>(std::max<std::size_t>(groups.size(), 1));
  for (std::size_t q = 0; q < n_seg; ++q)
    for (int k = 0; k < 4; ++k)
      keys[4 * q + k] =
          static_cast<std::int64_t>(s.seg_nodes[4 * q + k]) * n_groups + s.seg_group[q];
  std::vector<std::int64_t> uniq = keys;
  std::sort(uniq.begin(), uniq.end());
  uniq.erase(std::unique(uniq.begin(), uniq.end()), uniq.end());
  s.node.resize(uniq.size());
  s.node_group.resize(uniq.size());
  for (std::size_t i = 0; i < uniq.size(); ++i) {
    s.node[i] = static_cast<std::int32_t>(uniq[i] / n_groups);
    s.node_group[i] = static_cast<std::int32_t>(uniq[i] % n_groups);
  }
  s.seg_surface_node.resize(4 * n_seg);
  s.node_area.assign(uniq.size(), 0.0);
  for (std::size_t q = 0; q < n_seg; ++q) {
    const V3 a = node_at(x0, s.seg_nodes[4 * q + 2]) - node_at(x0, s.seg_nodes[4 * q]);
    const V3 b = node_at(x0, s.seg_nodes[4 * q + 3]) - node_at(x0, s.seg_nodes[4 * q + 1]);
    const double area = s.seg_cover_hex[q] < 0 ? 0.5 * norm(cross(a, b)) : 0.0;
    for (int k = 0; k < 4; ++k) {
      const auto it = std::lower_bound(uniq.begin(), uniq.end(), keys[4 * q + k]);
      const auto i = static_cast<std::size_t>(it - uniq.begin());
      s.seg_surface_node[4 * q + k] = static_cast<std::int32_t>(i);
      s.node_area[i] += 0.25 * area;
    }
  }
  return s;
}

ContactSurfaceSize contact_surface_size(const Mesh& mesh, const std::vector<ContactGroup>& groups,
                                        bool interior_faces) {
  ContactSurfaceSize out;
  const std::size_t n_parts = mesh.part_names.size();
  std::vector<FaceRecord> faces;
  std::vector<char> on_group(mesh.n_nodes()), on_outer(mesh.n_nodes());
  for (const auto& g : groups) {
    std::vector<int> group_of_part(n_parts, -1);  // this group alone: 0
    for (int p : g.parts)
      if (p >= 0 && static_cast<std::size_t>(p) < n_parts)
        group_of_part[static_cast<std::size_t>(p)] = 0;
    group_faces(mesh, group_of_part, 0, faces);
    std::fill(on_group.begin(), on_group.end(), 0);
    std::fill(on_outer.begin(), on_outer.end(), 0);
    for (std::size_t i = 0; i < faces.size();) {
      std::size_t j = i + 1;
      while (j < faces.size() && faces[j].key == faces[i].key) ++j;
      const bool outer = j - i == 1;
      if (outer || (interior_faces && j - i == 2)) {
        out.segments += static_cast<double>(j - i);
        for (auto nd : faces[i].key) {
          on_group[static_cast<std::size_t>(nd)] = 1;
          if (outer) on_outer[static_cast<std::size_t>(nd)] = 1;
        }
      }
      i = j;
    }
    out.nodes += static_cast<double>(std::count(on_group.begin(), on_group.end(), 1));
    out.outer_nodes += static_cast<double>(std::count(on_outer.begin(), on_outer.end(), 1));
  }
  return out;
}

}  // namespace ncfsim::fem
