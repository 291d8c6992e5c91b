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
  for (const auto& b : s.blocks<fem::Hex8Block>()) {
    const int material = b.material_index;
    for (std::size_t e = 0; e < b.n; ++e) {
      for (int I = 0; I < 8; ++I) m.hex8.push_back(b.conn[static_cast<std::size_t>(I) * b.n + e]);
      m.hex_part.push_back(b.part);
      m.hex_user_id.push_back(b.user_id[e]);
      m.hex_material.push_back(material);
      const auto k = static_cast<std::size_t>(b.mesh_hex[e]);
      m.hex_ply.push_back(tagged ? hexes.ply[k] : -1);
      m.hex_tow.push_back(tagged ? hexes.tow[k] : -1);
    }
  }
  for (const auto& b : s.blocks<fem::BarBlock>()) {
    const int law = model.parts[static_cast<std::size_t>(b.part)].bar_law;
    for (std::size_t e = 0; e < b.n; ++e) {
      m.bar2.push_back(b.conn[e]);
      m.bar2.push_back(b.conn[b.n + e]);
      m.bar_part.push_back(b.part);
      m.bar_user_id.push_back(b.user_id[e]);
      m.bar_material.push_back(law);
    }
  }
  for (const auto& b : s.blocks<fem::Shell4Block>()) {
    for (std::size_t e = 0; e < b.n; ++e) {
      for (std::size_t I = 0; I < 4; ++I) m.quad4.push_back(b.conn[I * b.n + e]);
      m.quad_part.push_back(b.part);
      m.quad_user_id.push_back(b.user_id[e]);
      // Elastic sections name a [[material]]; membrane-law sections are not in material_names.
      m.quad_material.push_back(b.section.law ? -1 : b.material_index);
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
  const std::size_t nh = rm.n_hex(), nb = rm.n_bar();
  m.node_user_id = rm.node_user_id;
  if (nh) {
    fem::ElementSet& hexes = m.elements(fem::ElementKind::Hex8);
    for (std::size_t e = 0; e < nh; ++e) {
      std::int32_t n[8];
      for (std::size_t I = 0; I < 8; ++I) n[I] = static_cast<std::int32_t>(rm.hex8[8 * e + I]);
      hexes.add(std::span<const std::int32_t>(n, 8), rm.hex_part[e]);
    }
    hexes.user_id = rm.hex_user_id;
    hexes.ply = rm.hex_ply;
    hexes.tow = rm.hex_tow;
  }
  if (nb) {
    fem::ElementSet& bars = m.elements(fem::ElementKind::Bar2);
    for (std::size_t e = 0; e < nb; ++e)
      bars.add({static_cast<std::int32_t>(rm.bar2[2 * e]),
                static_cast<std::int32_t>(rm.bar2[2 * e + 1])},
               rm.bar_part[e]);
    bars.user_id = rm.bar_user_id;
  }
  if (const std::size_t nq = rm.n_quad(); nq) {
    fem::ElementSet& shells = m.elements(fem::ElementKind::Quad4);
    for (std::size_t e = 0; e < nq; ++e)
      shells.add({static_cast<std::int32_t>(rm.quad4[4 * e]),
                  static_cast<std::int32_t>(rm.quad4[4 * e + 1]),
                  static_cast<std::int32_t>(rm.quad4[4 * e + 2]),
                  static_cast<std::int32_t>(rm.quad4[4 * e + 3])},
                 rm.quad_part[e]);
    if (rm.quad_user_id.size() == nq) shells.user_id = rm.quad_user_id;
  }
  m.fill_default_user_ids();  // whatever the file did not hold
  return m;
}

}  // namespace ncfsim::workflow
