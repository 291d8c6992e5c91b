// The case orchestration: [case], the module readers in order (fem/case, drape/case), [output]
// and [figures]. Every module reads and range-checks its own sections; docs/architecture.md.
#include "workflow/case/engine_case.hpp"

#include <algorithm>
#include <limits>

#include "drape/case/drape_case.hpp"
#include "fem/case/case_context.hpp"
#include "fem/case/fem_case.hpp"
#include "fem/case/stage_kinds.hpp"
#include "fem/errors.hpp"

namespace ncfsim::workflow {

namespace {

using fem::CaseReadContext;
using fem::TableReader;

void read_case_header(const TableReader& root, EngineCase& ec) {
  const TableReader c = root.required_table("case");
  ec.name = fem::read_case_name(c);
  ec.kind = c.choice("kind", {fem::stage_kind::kEngine, fem::stage_kind::kCrush},
                     fem::stage_kind::kEngine);
  ec.description = c.string("description", "");
}

struct DrapeMeshEntries {
  std::vector<drape::FabricEntry> fabrics;
  std::vector<drape::ShellStitchEntry> shell_stitches;
};

// [mesh]: fem's blocks, lines and plates, drape's fabrics and shell stitches, then the renumbering
// all follow.
DrapeMeshEntries read_mesh(CaseReadContext& ctx) {
  if (!ctx.root.has("mesh"))
    ctx.root.fail("mesh",
                  "missing (required section [mesh] with [[mesh.block]] or [[mesh.line]] entries)");
  const TableReader m = ctx.root.required_table("mesh");
  fem::read_mesh_blocks(ctx, m);
  if (m.tables("block").empty() && m.tables("line").empty() && m.tables("plate").empty() &&
      !m.has("fabric"))
    m.fail("block",
           "the mesh has no elements: give at least one [[mesh.block]], [[mesh.line]], "
           "[[mesh.plate]] or [[mesh.fabric]]");
  DrapeMeshEntries d;
  d.fabrics = drape::read_fabrics(ctx, m);
  d.shell_stitches = drape::read_shell_stitches(ctx, m);
  const auto new_of_old = fem::finish_mesh(ctx);
  drape::renumber_fabrics(ctx, d.fabrics, new_of_old);
  drape::renumber_shell_stitches(ctx, d.shell_stitches, new_of_old);
  return d;
}

SummaryMean read_mean(const TableReader& t) {
  SummaryMean sm;
  sm.name = t.string("name");
  sm.column = t.string("column");
  sm.from_time = t.number("from_time", Range::non_negative());
  sm.to_time = t.number("to_time", Range::positive());
  if (!(sm.to_time > sm.from_time)) t.fail("to_time", "must be after from_time");
  sm.scale = t.number("scale", 1.0, {});
  sm.per_column = t.string("per_column", "");
  return sm;
}

SummaryTarget read_target(const TableReader& t) {
  SummaryTarget st;
  st.quantity = t.string("quantity");
  if (t.has("target") == t.has("target_quantity"))
    t.fail("target", "give one of target (a number) and target_quantity (a summary.json key)");
  if (t.has("target"))
    st.target = t.number("target", Range{});
  else
    st.target_quantity = t.string("target_quantity");
  if (t.has("tolerance") && t.has("relative_tolerance"))
    t.fail("tolerance", "give at most one of tolerance (absolute) and relative_tolerance");
  if (t.has("tolerance")) st.tolerance = t.number("tolerance", Range::non_negative());
  if (t.has("relative_tolerance"))
    st.relative_tolerance = t.number("relative_tolerance", Range::closed(0, 10));
  st.source = t.string("source", "");
  return st;
}

SummarySamples read_sample(const TableReader& t) {
  SummarySamples ss;
  ss.x = t.string("x");
  ss.x_display_scale = t.number("x_display_scale", 1e3, Range::positive());
  ss.x_unit = t.string("x_unit", "mm");
  ss.at = t.numbers("at", {}, 1);
  if (auto cols = t.table("columns"))
    for (const auto& k : cols->keys()) ss.columns.emplace_back(k, cols->string(k));
  if (const auto coupon = drape::read_bias_extension_analytic(t)) {
    ss.bias_extension_analytic = true;
    ss.coupon_length = coupon->length;
    ss.coupon_width = coupon->width;
  }
  return ss;
}

void read_output(const CaseReadContext& ctx, EngineCase& ec) {
  const auto o = ctx.root.table("output");
  if (!o) return;
  const std::string frames = o->choice("frames", {"xdmf", "vtu", "both", "none"}, "xdmf");
  ec.output.xdmf = frames == "xdmf" || frames == "both";
  ec.output.vtu = frames == "vtu" || frames == "both";
  ec.output.figures = o->boolean("figures", true);
  ec.output.report = o->boolean("report", false);
  ec.output.checkpoint_interval_min = o->number("checkpoint_interval", 10.0, Range::closed(0, 1e4));
  ec.output.checkpoint_every_cycles =
      o->integer("checkpoint_every_cycles", 0, 0, std::int64_t{1} << 40);
  for (const auto& t : o->tables("probe"))
    ec.probes.push_back({t.string("name"), fem::select_nodes(ctx, t, "nodes")});
  const auto& hexes = ctx.model.mesh.elements(fem::ElementKind::Hex8);
  for (const auto& t : o->tables("element")) {
    ElementProbe ep{t.string("name"),
                    t.integer("element", 1, std::numeric_limits<std::int64_t>::max())};
    if (std::find(hexes.user_id.begin(), hexes.user_id.end(), ep.element) == hexes.user_id.end())
      t.fail("element", "no hexahedron has the id " + std::to_string(ep.element));
    ec.element_probes.push_back(ep);
  }
  ec.shear_probes = drape::read_shear_probes(ctx, *o);
  ec.ring_probes = drape::read_ring_shear_probes(ctx, *o);
  for (const auto& t : o->tables("mean")) ec.means.push_back(read_mean(t));
  for (const auto& t : o->tables("target")) ec.targets.push_back(read_target(t));
  ec.bending = drape::read_bending_probes(ctx, *o);
  for (const auto& t : o->tables("sample")) ec.samples.push_back(read_sample(t));
}

ImportedSeries read_import(const TableReader& it) {
  ImportedSeries is;
  is.file = it.string("file");
  if (is.file.is_relative()) is.file = std::filesystem::absolute(it.file().parent_path() / is.file);
  if (!std::filesystem::exists(is.file)) it.fail("file", "no such file: " + is.file.string());
  is.x = it.string("x");
  is.y = it.string("y");
  is.label = it.string("label", is.file.stem().string());
  is.x_scale = it.number("x_scale", 1.0, {});
  is.y_scale = it.number("y_scale", 1.0, {});
  return is;
}

PlotSpec read_plot(const TableReader& t) {
  PlotSpec p;
  p.name = t.string("name");
  p.title = t.string("title", p.name);
  p.source = t.choice("source", {"history.csv", "ring_shear.csv"}, "history.csv");
  p.x = t.string("x", p.source == "ring_shear.csv" ? "azimuth_deg" : "time");
  p.y = t.strings("y");
  p.x_scale = t.number("x_scale", 1.0, {});
  p.y_scale = t.number("y_scale", 1.0, {});
  p.x_label = t.string("x_label", p.x);
  p.y_label = t.string("y_label", p.y.empty() ? "" : p.y.front());
  for (const auto& it : t.tables("import")) p.imports.push_back(read_import(it));
  for (const auto& rt : t.tables("reference"))
    p.references.push_back({rt.string("label"), rt.number("y", {})});
  return p;
}

PictureSpec read_picture(const TableReader& t, const fem::Mesh& mesh) {
  PictureSpec p;
  p.name = t.string("name");
  p.field = t.choice("field",
                     {"displacement_magnitude",
                      "displacement",
                      "velocity",
                      "stress",
                      "von_mises_stress",
                      "fibre_direction",
                      "axial_force",
                      "axial_strain",
                      "shear_angle_deg",
                      "membrane_force",
                      "bending_moment",
                      "interply_slip_m",
                      "wrinkle_angle_deg",
                      "vf",
                      "damage_fibre_tension",
                      "damage_fibre_compression",
                      "damage_matrix_tension",
                      "damage_matrix_compression",
                      "damage_in_plane_shear",
                      "damage_transverse_shear",
                      "failed_mode",
                      "eroded",
                      "none"},
                     "displacement_magnitude");
  p.component = static_cast<int>(t.integer("component", -1, -1, 5));
  p.camera = t.choice("camera", {"iso", "top", "front"}, "iso");
  p.title = t.string("title", "");
  p.follow_part = t.string("follow_part", "");
  if (!p.follow_part.empty() && mesh.find_part(p.follow_part) < 0)
    t.fail("follow_part", "no part named '" + p.follow_part + "'");
  p.deformation_scale = t.number("deformation_scale", 1.0, Range::non_negative());
  return p;
}

void read_figures(const CaseReadContext& ctx, EngineCase& ec) {
  const auto f = ctx.root.table("figures");
  if (!f) return;
  for (const auto& t : f->tables("plot")) ec.plots.push_back(read_plot(t));
  for (const auto& t : f->tables("picture")) ec.pictures.push_back(read_picture(t, ctx.model.mesh));
}

// The constraint sets whose reactions go to history.csv: fixed, then prescribed velocities.
void collect_reactions(EngineCase& ec) {
  for (const auto& fx : ec.model.fixed) ec.reactions.push_back({fx.name, fx.nodes});
  for (const auto& pv : ec.model.velocities) ec.reactions.push_back({pv.name, pv.nodes});
}

}  // namespace

fem::CaseTypeRegistry engine_case_types() {
  fem::CaseTypeRegistry types;
  fem::register_fem_case_types(types);
  drape::register_drape_case_types(types);
  impact::register_impact_case_types(types);
  return types;
}

EngineCase load_engine_case(const std::filesystem::path& file,
                            const std::vector<std::string>& overrides) {
  fem::CaseDocument doc = fem::CaseDocument::load(file, overrides);
  doc.apply_laws_files();  // a calibration's laws, handed on by a workflow
  const fem::CaseTypeRegistry types = engine_case_types();
  EngineCase ec;
  ec.file = file;
  ec.laws_replaced = doc.laws_replaced();
  CaseReadContext ctx(doc, ec.model, types);
  read_case_header(ctx.root, ec);
  // The mesh: [mesh] blocks and fabrics, or [model], the impregnated part a transfer wrote.
  const bool imported = impact::has_impregnated_model(ctx);
  if (imported && ctx.root.has("mesh"))
    ctx.root.fail("model", "give either [mesh] or [model] (an imported transfer result), not both");
  if (ec.kind == fem::stage_kind::kCrush && !imported)
    ctx.root.fail(
        "model",
        "missing: a crush case reads its part from a transfer's results ([model] source = ...)");
  impact::ImpregnatedImport import;
  DrapeMeshEntries drape_mesh;
  if (imported)
    import = impact::read_impregnated_model(ctx);
  else
    drape_mesh = read_mesh(ctx);
  ec.resolution = ctx.resolution;
  fem::read_materials(ctx);
  fem::read_bar_laws(ctx);
  fem::read_membrane_laws(ctx);
  fem::read_parts(ctx);
  if (imported) impact::assign_impregnated_parts(ctx, import);
  ec.fabric_summaries = drape::assign_fabric_parts(ctx, drape_mesh.fabrics);
  drape::assign_shell_stitch_parts(ctx, drape_mesh.shell_stitches);
  fem::check_parts_defined(ctx);
  fem::read_boundary(ctx);
  fem::read_loads(ctx);
  fem::read_tools(ctx);
  fem::read_contacts(ctx);
  fem::read_time(ctx);
  collect_reactions(ec);
  ec.frame_fabric_length = ctx.frame_fabric_length;
  ec.crush = impact::read_crush(ctx);
  read_output(ctx, ec);
  read_figures(ctx, ec);
  ec.crush.crack_band = impact::check_crack_band(ctx);
  doc.check_unknown_keys();
  return ec;
}

}  // namespace ncfsim::workflow
