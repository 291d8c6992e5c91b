#include "workflow/run/result_mesh.hpp"

#include <limits>

#include "fem/elements/element_fields.hpp"
#include "fem/elements/shell4_block.hpp"

namespace ncfsim::workflow {

fem::io::ResultMesh result_mesh(const fem::ExplicitSolver& s) {
  const fem::Model& model = s.model();
  const fem::Mesh& mesh = model.mesh;
  fem::io::ResultMesh m;
  m.points = mesh.coords;
  m.part_names = mesh.part_names;
  m.node_user_id = mesh.node_user_id;
  for (const auto& mat : model.materials) m.material_names.push_back(mat->name());
  for (const auto& law : model.bar_laws) m.bar_law_names.push_back(law.name());
  const fem::ElementSet& hexes = mesh.elements(fem::ElementKind::Hex8);
  const bool tagged = hexes.ply.size() == hexes.size() && hexes.tow.size() == hexes.size();
  auto& hex = m.hex();
  for (const auto& b : s.blocks<fem::Hex8Block>()) {
    const int material = b.material_index;
    for (std::size_t e = 0; e < b.n; ++e) {
      for (int I = 0; I < 8; ++I) hex.conn.push_back(b.conn[static_cast<std::size_t>(I) * b.n + e]);
      hex.part.push_back(b.part);
      hex.user_id.push_back(b.user_id[e]);
      hex.material.push_back(material);
      const auto k = static_cast<std::size_t>(b.mesh_hex[e]);
      m.hex_ply.push_back(tagged ? hexes.ply[k] : -1);
      m.hex_tow.push_back(tagged ? hexes.tow[k] : -1);
    }
  }
  auto& bars = m.bars();
  for (const auto& b : s.blocks<fem::BarBlock>()) {
    const int law = model.parts[static_cast<std::size_t>(b.part)].bar_law;
    for (std::size_t e = 0; e < b.n; ++e) {
      bars.conn.push_back(b.conn[e]);
      bars.conn.push_back(b.conn[b.n + e]);
      bars.part.push_back(b.part);
      bars.user_id.push_back(b.user_id[e]);
      bars.material.push_back(law);
    }
  }
  auto& shells = m.shells();
  for (const auto& b : s.blocks<fem::Shell4Block>()) {
    for (std::size_t e = 0; e < b.n; ++e) {
      for (std::size_t I = 0; I < 4; ++I) shells.conn.push_back(b.conn[I * b.n + e]);
      shells.part.push_back(b.part);
      shells.user_id.push_back(b.user_id[e]);
      // Elastic sections name a [[material]]; membrane-law sections are not in material_names.
      shells.material.push_back(b.section.law ? -1 : b.material_index);
      m.quad_thickness.push_back(b.section.thickness);
    }
  }
  return m;
}

fem::io::Frame make_frame(const fem::ExplicitSolver& s) {
  fem::io::Frame fr;
  fr.time = s.time();
  fr.cycle = static_cast<int>(s.cycle());
  const std::size_t nn = s.model().mesh.n_nodes();
  auto X = s.x.view();
  auto X0 = s.x0.view();
  auto Vv = s.v.view();
  fr.displacement.resize(3 * nn);
  for (std::size_t d = 0; d < 3 * nn; ++d) fr.displacement[d] = X[d] - X0[d];
  fr.fields.push_back({"velocity", false, 3, std::vector<double>(Vv.data(), Vv.data() + 3 * nn)});
  const std::size_t nh = s.n_elements(fem::ElementKind::Hex8),
                    nb = s.n_elements(fem::ElementKind::Bar2),
                    nq = s.n_elements(fem::ElementKind::Quad4), nc = nh + nb + nq;
  const double nan = std::numeric_limits<double>::quiet_NaN();
  fem::io::FrameField stress{"stress", true, 6, std::vector<double>(6 * nc, nan)};
  fem::io::FrameField vm{"von_mises_stress", true, 1, std::vector<double>(nc, nan)};
  fem::io::FrameField fibre{"fibre_direction", true, 3, std::vector<double>(3 * nc, nan)};
  fem::io::FrameField axial{"axial_force", true, 1, std::vector<double>(nc, nan)};
  fem::io::FrameField bstrain{"axial_strain", true, 1, std::vector<double>(nc, nan)};
  fem::io::FrameField shear{"shear_angle_deg", true, 1, std::vector<double>(nc, nan)};
  fem::io::FrameField membrane{"membrane_force", true, 6, std::vector<double>(6 * nc, nan)};
  fem::io::FrameField moment{"bending_moment", true, 6, std::vector<double>(6 * nc, nan)};
  std::size_t off = 0;
  for (const auto& b : s.blocks<fem::Hex8Block>()) {
    fem::hex8_output_fields(b, X.data(), stress.values.data() + 6 * off, vm.values.data() + off,
                            fibre.values.data() + 3 * off);
    off += b.n;
  }
  for (const auto& b : s.blocks<fem::BarBlock>()) {
    for (std::size_t e = 0; e < b.n; ++e) {
      axial.values[off + e] = b.force[e];
      bstrain.values[off + e] = b.strain[e];
    }
    off += b.n;
  }
  for (const auto& b : s.blocks<fem::Shell4Block>()) {
    fem::shell4_output_fields(b, X.data(), shear.values.data() + off,
                              membrane.values.data() + 6 * off, moment.values.data() + 6 * off,
                              fibre.values.data() + 3 * off);
    off += b.n;
  }
  if (nh) {
    fr.fields.push_back(std::move(stress));
    fr.fields.push_back(std::move(vm));
  }
  if (nh || nq) fr.fields.push_back(std::move(fibre));
  if (nq) {
    fr.fields.push_back(std::move(shear));
    fr.fields.push_back(std::move(membrane));
    fr.fields.push_back(std::move(moment));
  }
  if (nh && s.erosion_enabled()) {
    // 1 where a hexahedron was eroded (ParaView: threshold it away)
    fem::io::FrameField eroded{"eroded", true, 1, std::vector<double>(nc, 0.0)};
    std::size_t o = 0;
    for (const auto& b : s.blocks<fem::Hex8Block>()) {
      if (b.n_eroded)
        for (std::size_t e = 0; e < b.n; ++e) eroded.values[o + e] = b.eroded[e];
      o += b.n;
    }
    fr.fields.push_back(std::move(eroded));
  }
  if (nb) {
    fr.fields.push_back(std::move(axial));
    fr.fields.push_back(std::move(bstrain));
  }
  return fr;
}

fem::Mesh mesh_from_stage_frame(const fem::io::StageFrame& frame, bool deformed) {
  const fem::io::ResultMesh& rm = frame.mesh;
  fem::Mesh m;
  m.coords = deformed ? frame.coordinates : rm.points;
  m.part_names = rm.part_names;
  m.node_user_id = rm.node_user_id;
  for (fem::ElementKind k : fem::kElementKinds) {
    const fem::io::ResultCells& c = rm.of(k);
    const std::size_t n = rm.n_of(k);
    if (n == 0) continue;
    fem::ElementSet& set = m.elements(k);
    const auto nodes = static_cast<std::size_t>(fem::nodes_per_element(k));
    std::int32_t ids[fem::kMaxNodesPerElement];
    for (std::size_t e = 0; e < n; ++e) {
      for (std::size_t I = 0; I < nodes; ++I)
        ids[I] = static_cast<std::int32_t>(c.conn[nodes * e + I]);
      set.add(std::span<const std::int32_t>(ids, nodes), c.part[e]);
    }
    if (c.user_id.size() == n) set.user_id = c.user_id;
  }
  if (rm.n_hex()) {
    fem::ElementSet& hexes = m.elements(fem::ElementKind::Hex8);
    hexes.ply = rm.hex_ply;
    hexes.tow = rm.hex_tow;
  }
  m.fill_default_user_ids();  // whatever the file did not hold
  return m;
}

}  // namespace ncfsim::workflow
