#include "workflow/stages/transfer_export.hpp"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "fem/case/stage_kinds.hpp"
#include "fem/contact/penalty_contact.hpp"
#include "fem/contact/segment_frame.hpp"
#include "fem/contact/tied_contact.hpp"
#include "fem/errors.hpp"
#include "fem/io/stage_handoff.hpp"
#include "fem/solver.hpp"
#include "impact/tow_damage_material.hpp"
#include "transfer/deck_export.hpp"
#include "workflow/case/engine_case.hpp"
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

namespace {

void require_transfer_run(const std::filesystem::path& dir) {
  const auto summary = dir / "summary.json";
  if (!std::filesystem::is_regular_file(summary))
    throw InputError(dir.string(), "", "no summary.json: not the output folder of a run");
  const nlohmann::json j = read_json_file(summary);
  if (!j.is_object()) throw InputError(dir.string(), "", "summary.json cannot be read");
  if (j.value("stage", std::string()) != fem::stage_kind::kTransfer ||
      j.value("status", std::string()) != "completed")
    throw InputError(dir.string(), "",
                     "not a completed transfer run (stage '" + j.value("stage", std::string("?")) +
                         "', status '" + j.value("status", std::string("?")) +
                         "'): run a kind = \"transfer\" case first");
  for (const char* f : {"results.h5", "materials.csv", "ties.csv"})
    if (!std::filesystem::is_regular_file(dir / f))
      throw InputError(dir.string(), "",
                       std::string("the transfer run has no ") + f +
                           " (written with output.frames = \"none\"?)");
}

}  // namespace

ExportResult export_impregnated(const std::filesystem::path& dir, const std::string& format) {
  if (format != "abaqus" && format != "lsdyna")
    throw InputError(dir.string(), "--format",
                     "'" + format + "' is not allowed; one of 'abaqus', 'lsdyna'");
  require_transfer_run(dir);
  const fem::io::StageFrame frame = fem::io::read_last_frame(dir / "results.h5");
  const auto& mesh = frame.mesh;
  transfer::ExportModel m;
  for (std::size_t i = 0; i < frame.n_points(); ++i)
    m.nodes.push_back(
        {frame.coordinates[3 * i], frame.coordinates[3 * i + 1], frame.coordinates[3 * i + 2]});
  const std::size_t n = mesh.n_hex();
  const fem::io::FrameField* axes[3] = {frame.field("fibre_direction"),
                                        frame.field("material_axis_2"),
                                        frame.field("material_axis_3")};
  for (const auto* a : axes)
    if (!a)
      throw InputError(dir.string(), "", "results.h5 has no material axes (not a transfer result)");
  std::map<std::int64_t, std::int32_t> element_of;
  for (std::size_t e = 0; e < n; ++e) {
    std::array<std::int32_t, 8> h{};
    for (std::size_t k = 0; k < 8; ++k)
      h[k] = static_cast<std::int32_t>(mesh.hex().conn[8 * e + k]);
    m.hex.push_back(h);
    std::array<double, 9> f{};
    for (int col = 0; col < 3; ++col)
      for (int row = 0; row < 3; ++row)
        f[static_cast<std::size_t>(3 * row + col)] =
            axes[col]->values[3 * e + static_cast<std::size_t>(row)];
    m.frame.push_back(f);
    m.material.push_back(mesh.hex().material.empty() ? 0 : mesh.hex().material[e]);
    element_of[mesh.hex().user_id.empty() ? static_cast<std::int64_t>(e + 1)
                                          : mesh.hex().user_id[e]] = static_cast<std::int32_t>(e);
  }
  // Kept stitches: bars with the yarn's constants as cell fields (after the hexahedra).
  if (const std::size_t nb = mesh.n_bar(); nb > 0) {
    const fem::io::FrameField* f[3] = {frame.field("stitch_modulus_Pa"),
                                       frame.field("stitch_area_m2"), frame.field("density_kg_m3")};
    for (const auto* x : f)
      if (!x || x->n_components != 1 || x->values.size() != n + nb)
        throw InputError(dir.string(), "",
                         "results.h5 has stitch bars without the yarn's constants");
    auto& st = m.stitches;
    st.modulus = f[0]->values[n], st.area = f[1]->values[n], st.density = f[2]->values[n];
    for (std::size_t b = 0; b < nb; ++b)
      st.bars.push_back({static_cast<std::int32_t>(mesh.bars().conn[2 * b]),
                         static_cast<std::int32_t>(mesh.bars().conn[2 * b + 1])});
  }
  const CsvTable mat = read_csv(dir / "materials.csv");
  const auto vf = mat.column("vf"), rho = mat.column("density_kg_m3");
  const char* names[9] = {"E1_Pa", "E2_Pa",  "E3_Pa",  "nu12",  "nu13",
                          "nu23",  "G12_Pa", "G13_Pa", "G23_Pa"};
  std::vector<std::vector<double>> c;
  for (const char* name : names) c.push_back(mat.column(name));
  for (std::size_t k = 0; k < vf.size(); ++k) {
    transfer::ExportMaterial em;
    em.name = "TOW_VF" + std::to_string(static_cast<int>(std::lround(1000 * vf[k])));
    em.density = rho[k];
    em.elastic = {c[0][k], c[1][k], c[2][k], c[3][k], c[4][k], c[5][k], c[6][k], c[7][k], c[8][k]};
    m.materials.push_back(em);
  }
  // ties.csv: interface, slave element id, slave face, master element id, master face.
  std::ifstream in(dir / "ties.csv");
  std::string line;
  std::getline(in, line);
  std::map<std::string, std::size_t> tie_of;
  std::size_t pairs = 0;
  while (std::getline(in, line)) {
    std::stringstream ss(line);
    std::string name, a, b, cc, d;
    if (!std::getline(ss, name, ',') || !std::getline(ss, a, ',') || !std::getline(ss, b, ',') ||
        !std::getline(ss, cc, ',') || !std::getline(ss, d, ','))
      throw InputError((dir / "ties.csv").string(), "", "malformed row: " + line);
    if (!tie_of.count(name)) {
      tie_of[name] = m.ties.size();
      m.ties.push_back({name, {}, {}, {}});
    }
    auto& t = m.ties[tie_of[name]];
    const auto s = element_of.find(std::stoll(a)), ms = element_of.find(std::stoll(cc));
    if (s == element_of.end() || ms == element_of.end())
      throw InputError((dir / "ties.csv").string(), "", "element id not in results.h5: " + line);
    t.slave.emplace_back(s->second, std::stoi(b));
    t.master.emplace_back(ms->second, std::stoi(d));
    ++pairs;
  }
  ExportResult r;
  r.file = dir / (format == "abaqus" ? "impregnated.inp" : "impregnated.k");
  if (format == "abaqus")
    transfer::write_abaqus_inp(r.file, m);
  else
    transfer::write_lsdyna_keyword(r.file, m);
  r.nodes = m.nodes.size();
  r.elements = m.hex.size();
  r.bars = m.stitches.bars.size();
  r.materials = m.materials.size();
  r.tie_pairs = pairs;
  return r;
}

namespace {

// The model of a crush case as the exporter's data: the formed mesh with its frames and Vf
// classes, the tow damage laws, the resin bonds, the kept stitches, the tools and the controls.
transfer::ExportModel crush_export_model(const EngineCase& ec) {
  const fem::Model& model = ec.model;
  const std::string file = ec.file.string();
  const auto& mesh = model.mesh;
  const auto& hex = mesh.elements(fem::ElementKind::Hex8);
  transfer::ExportModel m;
  for (std::size_t i = 0; i < mesh.n_nodes(); ++i)
    m.nodes.push_back({mesh.coords[3 * i], mesh.coords[3 * i + 1], mesh.coords[3 * i + 2]});
  std::map<int, std::int32_t> group_of_part;
  for (std::size_t e = 0; e < hex.size(); ++e) {
    std::array<std::int32_t, 8> h{};
    for (std::size_t k = 0; k < 8; ++k) h[k] = hex.conn[8 * e + k];
    m.hex.push_back(h);
    std::array<double, 9> f{};
    const double* axes =
        hex.material_axes.empty()
            ? model.parts[static_cast<std::size_t>(hex.part[e])].material_axes.data()
            : &hex.material_axes[9 * e];
    std::copy(axes, axes + 9, f.begin());
    m.frame.push_back(f);
    const int part = hex.part[e];
    const int mat = hex.material.empty() || hex.material[e] < 0
                        ? model.parts[static_cast<std::size_t>(part)].material
                        : hex.material[e];
    m.material.push_back(mat);
    if (!group_of_part.count(part)) {
      group_of_part[part] = static_cast<std::int32_t>(m.group_names.size());
      m.group_names.push_back(mesh.part_names[static_cast<std::size_t>(part)]);
    }
    m.group.push_back(group_of_part[part]);
  }
  auto& cr = m.crush;
  cr.enabled = true;
  cr.name = ec.name;
  for (const auto& material : model.materials) {
    const auto* tow = dynamic_cast<const impact::TowDamageMaterial*>(material.get());
    if (!tow)
      throw InputError(file, "material",
                       "'" + material->name() +
                           "' is not a tow_damage law: the export writes a crush of impregnated "
                           "tows (a kind = \"crush\" case with [model])");
    const auto& c = tow->constants();
    m.materials.push_back({tow->name(), c.density, c.elastic});
    const auto& X = c.strength;
    transfer::ExportFailure f{X.Xt, X.Xc, X.Yt, X.Yc, X.S12, X.S23, {}, c.residual_compression};
    std::copy(c.fracture_energy.begin(), c.fracture_energy.end(), f.fracture_energy.begin());
    std::copy(c.erode_on.begin(), c.erode_on.end(), f.erode_on.begin());
    cr.failure.push_back(f);
  }
  for (const auto& contact : model.contacts) {
    if (const auto* tie = dynamic_cast<const fem::TiedContact*>(contact.get())) {
      const auto& t = tie->config();
      if (!t.slave_nodes.empty()) {  // the kept stitches' nodes on the tows
        m.stitches.tied_nodes = t.slave_nodes;
        continue;
      }
      if (t.face_pairs.empty())
        throw InputError(file, "contact",
                         "tie '" + t.name + "' is given by groups, not face pairs: not exported");
      transfer::ExportTie x{t.name, {}, {}, {}};
      std::set<std::pair<std::int32_t, int>> slave, master;
      for (const auto& p : t.face_pairs) {
        slave.insert({p.slave_hex, p.slave_face});
        master.insert({p.master_hex, p.master_face});
      }
      x.slave.assign(slave.begin(), slave.end());
      x.master.assign(master.begin(), master.end());
      m.ties.push_back(std::move(x));
      cr.bonds.push_back(
          {t.normal_strength, t.shear_strength, t.mode_i_energy, t.mode_ii_energy, t.bk_exponent});
    } else if (const auto* pen = dynamic_cast<const fem::PenaltyContact*>(contact.get())) {
      const auto& p = pen->config();
      for (const auto& pair : p.pairs)
        if (pair.first != pair.second) cr.ply_contact = true, cr.ply_friction = pair.friction;
    }
  }
  // Kept stitches: the cured yarn's bars, a cable of a nominal 1 mm^2 with the law's E A and mass.
  if (const auto& bars = mesh.elements(fem::ElementKind::Bar2); !bars.empty()) {
    const auto& law = model.bar_laws.at(
        static_cast<std::size_t>(model.parts[static_cast<std::size_t>(bars.part[0])].bar_law));
    auto& st = m.stitches;
    st.area = 1e-6;
    st.modulus = law.max_slope() / st.area;
    st.density = law.linear_density() / st.area;
    for (std::size_t b = 0; b < bars.size(); ++b)
      st.bars.push_back({bars.conn[2 * b], bars.conn[2 * b + 1]});
  }
  // Tools: the punch's sphere and the support's plane, at their places (a seated plane where the
  // case seated it), a plane's plate wide enough for the model's footprint.
  for (std::size_t t = 0; t < model.tools.size(); ++t) {
    const auto& tool = model.tools[t];
    const auto& srf = tool.surface;
    if (srf.shape != fem::ToolShape::Sphere && srf.shape != fem::ToolShape::Plane)
      throw InputError(file, "tool[" + std::to_string(t) + "].shape",
                       "only a sphere or a plane tool is exported (the crush's punch and support)");
    if (tool.motion.kind == fem::ToolMotion::Kind::Force)
      throw InputError(file, "tool[" + std::to_string(t) + "].motion",
                       "a force-driven tool is not exported (the crush's tools move at a velocity "
                       "or are fixed)");
    transfer::ExportTool x;
    x.name = tool.name;
    x.sphere = srf.shape == fem::ToolShape::Sphere;
    x.point = {srf.point.x, srf.point.y, srf.point.z};
    x.axis = {srf.axis.x, srf.axis.y, srf.axis.z};
    x.radius = srf.radius;
    if (!tool.motion.curve_time.empty())
      throw InputError(file, "tool[" + std::to_string(t) + "].velocity_curve_time",
                       "a tool with a speed curve is not exported (the decks carry a smooth "
                       "ramp to a constant velocity)");
    if (tool.motion.kind == fem::ToolMotion::Kind::Velocity) {
      x.velocity = {tool.motion.velocity.x, tool.motion.velocity.y, tool.motion.velocity.z};
      x.ramp_time = tool.motion.ramp_time;
    }
    x.friction = tool.friction;
    double reach = 0;
    for (const auto& p : m.nodes) {
      const fem::V3 d{p[0] - srf.point.x, p[1] - srf.point.y, p[2] - srf.point.z};
      const double along = d.x * srf.axis.x + d.y * srf.axis.y + d.z * srf.axis.z;
      reach = std::max(reach,
                       std::sqrt(std::max(0.0, d.x * d.x + d.y * d.y + d.z * d.z - along * along)));
    }
    x.half_size = 1.2 * reach;
    cr.tools.push_back(x);
  }
  cr.punch = ec.crush.punch;
  const auto& time = model.time;
  cr.end_time = time.end_time;
  cr.history_interval = time.history_interval > 0 ? time.history_interval : time.end_time / 200;
  cr.frame_interval = time.frame_interval > 0 ? time.frame_interval : time.end_time / 20;
  cr.safety_factor = time.safety_factor;
  cr.erosion_step_ratio = time.erosion_step_ratio;
  for (int k = 0; k < impact::kModes; ++k)
    cr.raised_elements[static_cast<std::size_t>(k)] =
        ec.crush.crack_band.elements[static_cast<std::size_t>(k)];
  return m;
}

// The crush's ties as its solver builds them (each slave node at the nearest point of a paired
// master face, a penalty stiffness from the masses and the first step): OpenRadioss has no tie of
// that kind, so its deck carries them point by point.
void add_tie_points(EngineCase& ec, transfer::ExportModel& m) {
  const fem::ExplicitSolver solver(ec.model);
  m.crush.first_step = solver.time_step();
  std::size_t i = 0;
  for (const auto& contact : ec.model.contacts) {
    const auto* tie = dynamic_cast<const fem::TiedContact*>(contact.get());
    if (!tie || !tie->config().slave_nodes.empty()) continue;  // the stitches' (not a bond)
    auto& points = m.ties.at(i++).points;
    for (std::size_t t = 0; t < tie->n_ties(); ++t) {
      const auto r = tie->tie(t);
      double N[4];
      fem::segment_shape(r.xi, r.eta, N);
      points.push_back({r.node, r.corner, {N[0], N[1], N[2], N[3]}, r.stiffness, r.area});
    }
  }
}

}  // namespace

CrushExport export_crush_case(const std::filesystem::path& case_file,
                              const std::vector<std::string>& overrides, const std::string& format,
                              const std::filesystem::path& out_dir) {
  if (format != "abaqus" && format != "lsdyna" && format != "radioss")
    throw InputError(case_file.string(), "--format",
                     "'" + format + "' is not allowed; one of 'abaqus', 'lsdyna', 'radioss'");
  EngineCase ec = load_engine_case(case_file, overrides);
  if (ec.kind != fem::stage_kind::kCrush || !ec.crush.enabled)
    throw InputError(case_file.string(), "case.kind",
                     "'" + ec.kind +
                         "': the export of a case writes a crush (kind = \"crush\"); export a "
                         "transfer run's folder for its model alone");
  transfer::ExportModel m = crush_export_model(ec);
  if (format == "radioss") add_tie_points(ec, m);
  const std::filesystem::path dir =
      out_dir.empty() ? std::filesystem::path("results") / (ec.name + "_" + format) : out_dir;
  std::filesystem::create_directories(dir);
  CrushExport r;
  if (format == "radioss") {
    r.result.file = transfer::write_radioss_deck(dir, m).front();
  } else {
    r.result.file = dir / (ec.name + (format == "abaqus" ? ".inp" : ".k"));
    if (format == "abaqus")
      transfer::write_abaqus_inp(r.result.file, m);
    else
      transfer::write_lsdyna_keyword(r.result.file, m);
  }
  r.result.nodes = m.nodes.size();
  r.result.elements = m.hex.size();
  r.result.bars = m.stitches.bars.size();
  r.result.materials = m.materials.size();
  for (const auto& t : m.ties) r.result.tie_pairs += t.slave.size();
  const auto contents = transfer::deck_contents(m, format);
  r.carried = contents.carried;
  r.left_out = contents.left_out;
  return r;
}

}  // namespace ncfsim::workflow
