// [[mesh.fabric]] and the tow_biphase material type.
#include <algorithm>
#include <climits>
#include <cmath>

#include "drape/case/drape_case.hpp"
#include "drape/fabric_membrane.hpp"
#include "drape/tow_material.hpp"
#include "fem/case/model_size.hpp"
#include "fem/errors.hpp"

namespace ncfsim::drape {

using fem::TableReader;

namespace {

std::unique_ptr<fem::SolidMaterial> read_tow_biphase(const TableReader& t, const std::string& name,
                                                     double rho) {
  TowConstants c;
  c.density = rho;
  c.E11f = t.number("E11f", Range::non_negative());
  c.E11f_axial = t.number("E11f_axial", 0.0, Range::non_negative());
  c.E11m = t.number("E11m", Range::positive());
  c.E22m = t.number("E22m", Range::positive());
  c.E33m = t.number("E33m", Range::positive());
  c.nu12m = t.number("nu12m", 0.0, {-1.0, 1.0, true, true});
  c.nu13m = t.number("nu13m", 0.0, {-1.0, 1.0, true, true});
  c.nu23m = t.number("nu23m", 0.0, {-1.0, 1.0, true, true});
  c.G12m = t.number("G12m", Range::positive());
  c.G13m = t.number("G13m", c.G12m, Range::positive());
  c.G23m = t.number("G23m", c.G12m, Range::positive());
  c.compaction_modulus = t.number("compaction_modulus", 0.0, Range::non_negative());
  c.locking_width_ratio = t.number("locking_width_ratio", 0.7, {0.0, 1.0, true, true});
  c.lock_stiffness_ratio = t.number("lock_stiffness_ratio", 50.0, Range::closed(1, 1e4));
  c.compaction_of_fibre_sheets =
      t.choice("compaction_measure", {"transverse_strain", "fibre_sheet_spacing"},
               "transverse_strain") == "fibre_sheet_spacing";
  return std::make_unique<TowMaterial>(name, c);
}

int read_int(const TableReader& t, std::string_view key, int fallback) {
  return static_cast<int>(t.integer(key, fallback, INT_MIN, INT_MAX));
}

// The fabric's own keys. Their ranges are checked once, by drape::validate (drape/fabric.cpp):
// on the keys as given here, on the spec as meshed (the resolution's divisions) by
// generate_blanket.
FabricSpec read_fabric_spec(const TableReader& fb, const std::string& resolution) {
  FabricSpec f;
  if (fb.has("ply_angles_deg")) f.ply_angles_deg = fb.numbers("ply_angles_deg", {});
  f.tow_width = fb.number("tow_width", f.tow_width, {});
  f.tow_gap = fb.number("tow_gap", f.tow_gap, {});
  f.areal_weight = fb.number("areal_weight", f.areal_weight, {});
  f.fibre_density = fb.number("fibre_density", f.fibre_density, {});
  f.tow_fibre_volume_fraction =
      fb.number("tow_fibre_volume_fraction", f.tow_fibre_volume_fraction, {});
  const std::string stitch = fb.choice("stitch", {"tricot", "chain", "none"}, "tricot");
  f.stitch = stitch == "tricot"  ? StitchPattern::Tricot
             : stitch == "chain" ? StitchPattern::Chain
                                 : StitchPattern::None;
  f.stitch_direction_deg = fb.number("stitch_direction_deg", 0.0, {});
  f.stitch_gauge = fb.number("stitch_gauge", 0.0, {});
  f.stitch_length = fb.number("stitch_length", 0.0, {});
  if (fb.has("stitch_edge_margin"))
    f.stitch_edge_margin = fb.number("stitch_edge_margin", Range::non_negative());
  f.elements_across_tow = read_int(fb, "elements_across_tow", 2);
  f.elements_through_thickness = read_int(fb, "elements_through_thickness", 1);
  f.element_length = fb.number("element_length", 0.0, {});
  try {
    validate(f, fb.file().string(), fb.path());
  } catch (const InputError& e) {
    // A key the entry takes from its [fabric.NAME] is named there.
    const std::string own = fb.path() + ".";
    if (e.key().rfind(own, 0) != 0) throw;
    const std::string key = e.key().substr(own.size());
    if (fb.key_path(key) == e.key()) throw;
    throw InputError(e.file(), fb.key_path(key), e.message(), e.value(), e.allowed());
  }
  if (resolution == "coarse") {
    f.elements_across_tow = std::max(1, f.elements_across_tow / 2);
    f.element_length = 2 * (f.element_length > 0 ? f.element_length : f.tow_pitch());
  } else if (resolution == "fine") {
    f.elements_across_tow *= 2;
    f.element_length = 0.5 * (f.element_length > 0 ? f.element_length : f.tow_pitch());
  }
  return f;
}

void read_stitch_laws(const TableReader& fb, const FabricSpec& f, FabricEntry& fe) {
  if (f.stitch == StitchPattern::None) {
    // A blank without stitch may keep its stitch keys (a control case made from a stitched one
    // by stitch = "none" alone): they are read and have no effect.
    for (const char* k : {"stitch_law_I", "stitch_law_Lambda", "stitch_law_legs"})
      (void)fb.string(k, "");
    for (const char* k :
         {"connection_sliding_force", "connection_transverse_force", "connection_stiffness"})
      (void)fb.number(k, 0.0, {});
    return;
  }
  fe.law_I = fb.string("stitch_law_I");
  fe.law_Lambda = f.stitch == StitchPattern::Tricot ? fb.string("stitch_law_Lambda") : fe.law_I;
  fe.law_legs = fb.string("stitch_law_legs", fe.law_I);
  fe.connection.sliding_force = fb.number("connection_sliding_force", 0.05, Range::positive());
  fe.connection.transverse_force = fb.number(
      "connection_transverse_force", 3 * fe.connection.sliding_force, Range::non_negative());
  fe.connection.stiffness = fb.number("connection_stiffness", 0.0, Range::non_negative());
}

// The keys a [[mesh.fabric]] entry may give beside the [fabric.NAME] it names: where the blanket
// lies and how it is meshed, and how a specimen is cut from the fabric (its plies' angles and
// wale direction to the test's axes, its stitch left out). Every other key is the fabric's own.
bool specimen_key(const std::string& key) {
  static const char* const keys[] = {"name",
                                     "fabric",
                                     "origin",
                                     "size",
                                     "elements_across_tow",
                                     "elements_through_thickness",
                                     "element_length",
                                     "ply_angles_deg",
                                     "stitch_direction_deg",
                                     "stitch_edge_margin"};
  return std::find(std::begin(keys), std::end(keys), key) != std::end(keys);
}

// `fabric = "NAME"`: the entry over [fabric.NAME] (a fabric file's, cases/fabrics/), so that the
// virtual tests and the forming cases of a fabric read the same data. A fabric key given in both
// is bad input: a case does not keep its own copy of its fabric (a variant changes it with
// `set`, e.g. "fabric.NAME.tow_gap = ..."), except `stitch = "none"`, a specimen without stitch.
TableReader over_its_fabric(const fem::CaseReadContext& ctx, const TableReader& fb,
                            std::string& fabric) {
  if (!fb.holds("fabric")) return fb;
  fabric = fb.string("fabric");
  const auto fabrics = ctx.root.table("fabric");
  const auto own = fabrics ? fabrics->table(fabric) : std::nullopt;
  if (!own) {
    std::string known;
    if (fabrics)
      for (const auto& k : fabrics->keys()) known += (known.empty() ? "" : ", ") + k;
    fb.fail("fabric", "no [fabric." + fabric + "] in the case or the files it includes" +
                          (known.empty() ? std::string(" (include a fabric file: cases/fabrics/)")
                                         : " (there are: " + known + ")"));
  }
  for (const auto& key : own->keys()) {
    if (!fb.holds(key)) continue;
    own->mark(key);  // read, though the entry's own value counts
    if (specimen_key(key)) continue;
    if (key == "stitch" && fb.string("stitch") == "none") continue;
    fb.fail(key, "given both here and in [fabric." + fabric +
                     "] (a case reads its fabric from one place: change it there, or give the "
                     "change as fabric." +
                     fabric + "." + key + " in --set or a variant's set)");
  }
  return fb.with_defaults(*own);
}

FabricEntry read_fabric(fem::CaseReadContext& ctx, const TableReader& entry) {
  FabricEntry fe;
  fe.path = entry.path();
  const TableReader fb = over_its_fabric(ctx, entry, fe.fabric);
  fe.name = fb.string("name");
  for (const char* k : {"tow_material", "stitch_law_I", "stitch_law_Lambda", "stitch_law_legs"})
    fe.key_paths[k] = fb.key_path(k);
  // The fabric's Coulomb coefficients, which its cases' contact pairs and tools refer to
  // ("&fabric.NAME.friction_tow_tow"): checked here, with the rest of the fabric.
  for (const char* k : {"friction_tow_tow", "friction_tow_tow_crossing", "friction_tool"})
    if (fb.has(k)) (void)fb.number(k, Range::non_negative());
  // The tow's ASTM D1388 bending length, the target its E11f is calibrated to (a calibration
  // stage refers to it).
  if (fb.has("tow_bending_length")) (void)fb.number("tow_bending_length", Range::positive());
  const FabricSpec f = read_fabric_spec(fb, ctx.resolution);
  BlanketSpec bl;
  const auto origin = fb.vec3_or("origin", {0, 0, 0});
  bl.origin = {origin[0], origin[1]};
  bl.z0 = origin[2];
  const auto size = fb.numbers("size", Range::positive(), 2);
  if (size.size() != 2) fb.fail("size", "must hold 2 numbers [length along x, width along y]");
  bl.size = {size[0], size[1]};
  fe.tow_material = fb.string("tow_material");
  read_stitch_laws(fb, f, fe);
  fe.angles = f.ply_angles_deg;
  fe.elements_through_thickness = f.elements_through_thickness;
  if (fe.name.empty() || fe.name.find_first_of(" ./\\") != std::string::npos)
    fb.fail(
        "name",
        "must be a non-empty name without spaces, dots or slashes (it prefixes the part names)");
  fem::Mesh& mesh = ctx.model.mesh;
  {  // before meshing: a blanket too fine or too large for the machine is bad input
    const double pitch = f.tow_pitch(), el = f.element_length > 0 ? f.element_length : pitch;
    const double ac = f.elements_across_tow, tt = f.elements_through_thickness;
    const double area = bl.size[0] * bl.size[1];
    const double n_hex =
        static_cast<double>(f.ply_angles_deg.size()) * tt * ac * area / (pitch * el);
    const double n_nodes = n_hex * (ac + 1) * (tt + 1) / (ac * tt);
    const double n_stitch = f.stitch == StitchPattern::None ? 0.0 : 10.0 * area / (pitch * pitch);
    fem::require_model_fits(
        fb.file().string(), fb.key_path("size") + ", " + fb.key_path("element_length"),
        static_cast<double>(mesh.n_nodes()) + n_nodes,
        static_cast<double>(mesh.elements(fem::ElementKind::Hex8).size()) + n_hex,
        static_cast<double>(mesh.elements(fem::ElementKind::Bar2).size()) + n_stitch);
  }
  try {
    fe.model = generate_blanket(mesh, f, bl, ctx.file, fe.name + "_", fe.path);
  } catch (const InputError& e) {
    // The value checked is the one meshed: say where it came from.
    if (e.key() != fe.path + ".elements_across_tow" || ctx.resolution == "default") throw;
    throw InputError(e.file(), e.key(),
                     "value " + e.value() + " (mesh.resolution = " + ctx.resolution + " of " +
                         std::to_string(fb.integer("elements_across_tow", 2, INT_MIN, INT_MAX)) +
                         ") out of range, allowed " + e.allowed(),
                     e.value(), e.allowed());
  }
  auto generated = [&](int p, fem::PartKind kind) {
    const std::string& part = mesh.part_names[static_cast<std::size_t>(p)];
    ctx.part_kind[part] = kind;
    ctx.generated_parts[part] = "[[mesh.fabric]]";
  };
  for (int p : fe.model.ply_parts) generated(p, fem::PartKind::Solid);
  for (int p : {fe.model.stitch_I_part, fe.model.stitch_Lambda_part, fe.model.stitch_leg_part})
    if (p >= 0) generated(p, fem::PartKind::Bar);
  return fe;
}

int named_index(const fem::CaseReadContext& ctx, const FabricEntry& fe,
                const std::map<std::string, int>& names, const std::string& n,
                const std::string& key) {
  if (!names.count(n))
    throw InputError(ctx.file, fe.key_paths.count(key) ? fe.key_paths.at(key) : fe.path + "." + key,
                     "no such " +
                         std::string(key == "tow_material" ? "[[material]]" : "[[bar_law]]") +
                         " '" + n + "'");
  return names.at(n);
}

void assign_ply_parts(fem::CaseReadContext& ctx, const FabricEntry& fe) {
  const int tow = named_index(ctx, fe, ctx.materials, fe.tow_material, "tow_material");
  // E11f_axial leaves bending to E11f through the hourglass moduli, which carry all of the
  // bending only with one hexahedron through the tow: with more, the layers' stretch (E11f_axial)
  // would bend it.
  const auto* tow_law =
      dynamic_cast<const TowMaterial*>(ctx.model.materials[static_cast<std::size_t>(tow)].get());
  if (tow_law && tow_law->constants().E11f_axial > 0 && fe.elements_through_thickness > 1)
    throw InputError(ctx.file, fe.path + ".elements_through_thickness",
                     "must be 1 with tow material '" + fe.tow_material +
                         "', which sets E11f_axial (its bending stiffness, E11f, is separate "
                         "from its stretch only with "
                         "one hexahedron through the tow thickness)");
  for (std::size_t q = 0; q < fe.model.ply_parts.size(); ++q) {
    const auto p = static_cast<std::size_t>(fe.model.ply_parts[q]);
    auto& pp = ctx.model.parts[p];
    pp.material = tow;
    const double al = fe.angles[q] * M_PI / 180.0;
    pp.material_axes = {std::cos(al), -std::sin(al), 0, std::sin(al), std::cos(al), 0, 0, 0, 1};
    ctx.part_defined[p] = 1;
  }
}

void assign_stitch_parts(fem::CaseReadContext& ctx, const FabricEntry& fe) {
  const std::pair<int, std::string> bar_parts[] = {{fe.model.stitch_I_part, fe.law_I},
                                                   {fe.model.stitch_Lambda_part, fe.law_Lambda},
                                                   {fe.model.stitch_leg_part, fe.law_legs}};
  for (const auto& [p, law] : bar_parts) {
    if (p < 0) continue;
    auto& pp = ctx.model.parts[static_cast<std::size_t>(p)];
    pp.bar_law = named_index(ctx, fe, ctx.bar_laws, law,
                             law == fe.law_I        ? "stitch_law_I"
                             : law == fe.law_Lambda ? "stitch_law_Lambda"
                                                    : "stitch_law_legs");
    ctx.part_defined[static_cast<std::size_t>(p)] = 1;
  }
}

}  // namespace

namespace {

// [[membrane_law]] type = "fabric": the macro membrane law of the fabric (shells).
std::unique_ptr<fem::MembraneLaw> read_fabric_membrane(const TableReader& t,
                                                       const std::string& name) {
  FabricMembraneConstants c;
  c.areal_density = t.number("areal_density", Range::positive());
  const auto ang = t.has("fibre_angles_deg")
                       ? t.numbers("fibre_angles_deg", Range::closed(-180, 180), 2)
                       : std::vector<double>{45.0, -45.0};
  if (ang.size() != 2) t.fail("fibre_angles_deg", "must hold exactly 2 angles (deg)");
  c.fibre_angles = {ang[0] * M_PI / 180, ang[1] * M_PI / 180};
  c.fibre_tension_stiffness = t.number("fibre_tension_stiffness", Range::positive());
  c.fibre_compression_ratio = t.number("fibre_compression_ratio", 1e-3, Range::closed(0, 1));
  c.bending_stiffness = t.number("bending_stiffness", Range::positive());
  auto curve = [&](const char* akey, const char* fkey) {
    const auto a = t.numbers(akey, Range::closed(0, 89), 1);
    const auto f = t.numbers(fkey, {}, 1);
    if (a.size() != f.size()) t.fail(fkey, std::string("needs as many values as `") + akey + "`");
    std::vector<double> rad(a.size());
    for (std::size_t i = 0; i < a.size(); ++i) rad[i] = a[i] * M_PI / 180;
    try {
      return ShearCurve(rad, f);
    } catch (const std::invalid_argument& e) {
      t.fail(akey, e.what());
    }
  };
  c.positive = curve("shear_angle_deg", "shear_force");
  if (t.has("negative_shear_angle_deg") || t.has("negative_shear_force"))
    c.negative = curve("negative_shear_angle_deg", "negative_shear_force");
  try {
    return std::make_unique<FabricMembraneLaw>(name, std::move(c));
  } catch (const std::invalid_argument& e) {
    t.fail("type", e.what());
  }
}

}  // namespace

void register_drape_case_types(fem::CaseTypeRegistry& registry) {
  registry.add_material_type("tow_biphase", read_tow_biphase);
  registry.add_membrane_law_type("fabric", read_fabric_membrane);
}

std::vector<FabricEntry> read_fabrics(fem::CaseReadContext& ctx, const TableReader& m) {
  std::vector<FabricEntry> fabrics;
  for (const auto& fb : m.tables("fabric")) fabrics.push_back(read_fabric(ctx, fb));
  // A fabric no entry names (a case including its fabric file for the laws alone, e.g. the macro
  // model's stitch) is not read; its keys are not unknown. Those of a fabric an entry names are
  // read there, so that a misspelt key in a fabric file is found.
  if (const auto all = ctx.root.table("fabric"))
    for (const auto& name : all->keys()) {
      const bool named = std::any_of(fabrics.begin(), fabrics.end(),
                                     [&](const FabricEntry& fe) { return fe.fabric == name; });
      if (const auto one = all->table(name); one && !named)
        for (const auto& key : one->keys()) one->mark(key);
    }
  return fabrics;
}

void renumber_fabrics(fem::CaseReadContext& ctx, std::vector<FabricEntry>& fabrics,
                      const std::vector<std::int32_t>& new_of_old) {
  auto& pins = ctx.node_sets["tow_end_pins"];
  pins.owner = "[[mesh.fabric]]";
  auto& stitch_pins = ctx.node_sets["stitch_end_pins"];
  stitch_pins.owner = "[[mesh.fabric]]";
  for (auto& fe : fabrics) {
    for (auto& c : fe.model.connections)
      for (std::int32_t* nd : {&c.stitch_node, &c.tow_node, &c.tow_axis_node})
        *nd = new_of_old[static_cast<std::size_t>(*nd)];
    for (auto& nd : fe.model.stitch_nodes) nd = new_of_old[static_cast<std::size_t>(nd)];
    for (auto& nd : fe.model.tow_end_pins) nd = new_of_old[static_cast<std::size_t>(nd)];
    for (auto& nd : fe.model.stitch_end_pins) nd = new_of_old[static_cast<std::size_t>(nd)];
    pins.sets[fe.name] = fe.model.tow_end_pins;
    stitch_pins.sets[fe.name] = fe.model.stitch_end_pins;
  }
}

std::vector<FabricSummary> assign_fabric_parts(fem::CaseReadContext& ctx,
                                               const std::vector<FabricEntry>& fabrics) {
  std::vector<FabricSummary> summaries;
  for (const auto& fe : fabrics) {
    assign_ply_parts(ctx, fe);
    assign_stitch_parts(ctx, fe);
    int connection_contact = -1;
    if (!fe.model.connections.empty()) {
      connection_contact = static_cast<int>(ctx.model.contacts.size());
      ctx.model.contacts.push_back(std::make_unique<StitchToTowConnection>(
          fe.name + "_stitch_tow", fe.model.connections, fe.connection));
    }
    summaries.push_back({fe.name, fe.model.n_tows, fe.model.n_dropped_tows, fe.model.n_penetrations,
                         fe.model.connections.size(), fe.model.tow_thickness, connection_contact,
                         fe.model.ply_parts});
  }
  return summaries;
}

}  // namespace ncfsim::drape
