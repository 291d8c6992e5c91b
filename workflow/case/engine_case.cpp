#include "workflow/case/engine_case.hpp"

#include <algorithm>
#include <cmath>
#include <map>

#include "drape/fabric_generator.hpp"
#include "drape/stitch_connection.hpp"
#include "drape/tow_material.hpp"
#include "fem/contact/penalty_contact.hpp"
#include "fem/contact/tied_contact.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"
#include "workflow/case/toml_reader.hpp"

namespace ncfsim::workflow {

namespace {

using fem::V3;

V3 to_v3(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }

double resolution_factor(const std::string& r) {
  if (r == "coarse") return 0.5;
  if (r == "fine") return 2.0;
  return 1.0;
}

int axis_index(const TableReader& t, std::string_view key, const std::string& value) {
  if (value == "x") return 0;
  if (value == "y") return 1;
  if (value == "z") return 2;
  t.fail(key, "'" + value + "' is not an axis; one of 'x', 'y', 'z'");
}

std::array<bool, 3> read_dofs(const TableReader& t, std::string_view key, std::array<bool, 3> fallback) {
  if (!t.has(key)) return fallback;
  std::array<bool, 3> d{false, false, false};
  for (const auto& s : t.strings(key)) d[static_cast<std::size_t>(axis_index(t, key, s))] = true;
  return d;
}

// Tow end pins of the [[mesh.fabric]] blankets of the case being read, by fabric name (reset by
// every load_engine_case; a selector `tow_end_pins = "name"` picks them).
std::map<std::string, std::vector<std::int32_t>> g_tow_end_pins;

// Node selection: the intersection of the criteria given (part, box, plane); "all" if none.
std::vector<std::int32_t> select_nodes(const TableReader& owner, std::string_view key, const fem::Mesh& mesh) {
  auto sel = owner.table(key);
  if (!sel) owner.fail(key, "missing (required node selection, e.g. { part = \"beam\" } or "
                            "{ axis = \"x\", value = 0.0 })");
  const std::size_t n = mesh.n_nodes();
  std::vector<char> keep(n, 1);
  bool any = false;
  if (sel->has("part")) {
    any = true;
    std::vector<std::string> names;
    if (sel->has("part")) {
      // a string or an array of strings
      try {
        names = {sel->string("part")};
      } catch (const InputError&) {
        names = sel->strings("part");
      }
    }
    std::vector<char> in_part(n, 0);
    for (const auto& name : names) {
      const int p = mesh.find_part(name);
      if (p < 0) sel->fail("part", "no part named '" + name + "'");
      mesh.for_each_element_node(p, [&](std::int32_t node) { in_part[static_cast<std::size_t>(node)] = 1; });
    }
    for (std::size_t i = 0; i < n; ++i) keep[i] &= in_part[i];
  }
  const double tol = sel->number("tolerance", 1e-9, Range::non_negative());
  if (sel->has("box_min") || sel->has("box_max")) {
    any = true;
    const auto lo = sel->vec3("box_min"), hi = sel->vec3("box_max");
    for (std::size_t i = 0; i < n; ++i)
      for (int c = 0; c < 3; ++c) {
        const double v = mesh.coords[3 * i + static_cast<std::size_t>(c)];
        if (v < lo[static_cast<std::size_t>(c)] - tol || v > hi[static_cast<std::size_t>(c)] + tol) keep[i] = 0;
      }
  }
  if (sel->has("axis") || sel->has("value")) {
    any = true;
    const int a = axis_index(*sel, "axis", sel->string("axis"));
    const double value = sel->number("value", {});
    for (std::size_t i = 0; i < n; ++i)
      if (std::abs(mesh.coords[3 * i + static_cast<std::size_t>(a)] - value) > tol) keep[i] = 0;
  }
  if (sel->has("outline")) {  // on the x-y outline of the bounding box of the selection so far
    any = true;
    if (!sel->boolean("outline", false)) sel->fail("outline", "only `outline = true` is meaningful");
    double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
    for (std::size_t i = 0; i < n; ++i)
      if (keep[i])
        for (int c = 0; c < 2; ++c) {
          lo[c] = std::min(lo[c], mesh.coords[3 * i + static_cast<std::size_t>(c)]);
          hi[c] = std::max(hi[c], mesh.coords[3 * i + static_cast<std::size_t>(c)]);
        }
    for (std::size_t i = 0; i < n; ++i) {
      bool on = false;
      for (int c = 0; c < 2; ++c) {
        const double v = mesh.coords[3 * i + static_cast<std::size_t>(c)];
        on = on || std::abs(v - lo[c]) <= tol || std::abs(v - hi[c]) <= tol;
      }
      if (!on) keep[i] = 0;
    }
  }
  if (sel->has("tow_end_pins")) {
    any = true;
    const std::string fabric = sel->string("tow_end_pins");
    const auto it = g_tow_end_pins.find(fabric);
    if (it == g_tow_end_pins.end()) sel->fail("tow_end_pins", "no [[mesh.fabric]] named '" + fabric + "'");
    std::vector<char> pin(n, 0);
    for (auto nd : it->second) pin[static_cast<std::size_t>(nd)] = 1;
    for (std::size_t i = 0; i < n; ++i) keep[i] &= pin[i];
  }
  if (sel->has("all")) {
    any = true;
    if (!sel->boolean("all", false)) sel->fail("all", "only `all = true` is meaningful");
  }
  if (!any) owner.fail(key, "selects nothing: give part, box_min/box_max, axis/value or all = true");
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < n; ++i)
    if (keep[i]) out.push_back(static_cast<std::int32_t>(i));
  if (out.empty()) owner.fail(key, "the selection holds no node (check coordinates and tolerance)");
  return out;
}

std::unique_ptr<fem::SolidMaterial> read_material(const TableReader& t, const std::string& name) {
  const std::string type = t.choice("type", {"elastic_isotropic", "elastic_orthotropic", "tow_biphase"}, "");
  const double rho = t.number("density", Range::positive());
  try {
    if (type == "tow_biphase") {
      drape::TowConstants c;
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
          t.choice("compaction_measure", {"transverse_strain", "fibre_sheet_spacing"}, "transverse_strain") ==
          "fibre_sheet_spacing";
      return std::make_unique<drape::TowMaterial>(name, c);
    }
    if (type == "elastic_isotropic") {
      const double E = t.number("youngs_modulus", Range::positive());
      const double nu = t.number("poisson_ratio", {-1.0, 0.5, true, true});
      return std::make_unique<fem::ElasticIsotropic>(name, rho, E, nu);
    }
    fem::OrthotropicConstants c{};
    c.E1 = t.number("E1", Range::positive());
    c.E2 = t.number("E2", Range::positive());
    c.E3 = t.number("E3", Range::positive());
    c.nu12 = t.number("nu12", {-1.0, 1.0, true, true});
    c.nu13 = t.number("nu13", {-1.0, 1.0, true, true});
    c.nu23 = t.number("nu23", {-1.0, 1.0, true, true});
    c.G12 = t.number("G12", Range::positive());
    c.G13 = t.number("G13", Range::positive());
    c.G23 = t.number("G23", Range::positive());
    return std::make_unique<fem::ElasticOrthotropic>(name, rho, c);
  } catch (const std::invalid_argument& e) {
    t.fail("type", e.what());
  }
}

fem::BarForceLaw read_bar_law(const TableReader& t, const std::string& name) {
  const std::string type = t.choice("type", {"linear", "tabulated"}, "");
  const double rho_l = t.number("linear_density", Range::positive());
  const bool tension_only = t.boolean("tension_only", false);
  try {
    if (type == "linear") return fem::BarForceLaw::linear(name, t.number("axial_stiffness", Range::positive()), tension_only, rho_l);
    auto strain = t.numbers("strain", {}, 2);
    auto force = t.numbers("force", {}, 2);
    if (strain.size() != force.size()) t.fail("force", "needs as many values as `strain`");
    return fem::BarForceLaw(name, strain, force, tension_only, rho_l);
  } catch (const std::invalid_argument& e) {
    t.fail("strain", e.what());
  }
}

std::array<double, 9> read_axes(const TableReader& t) {
  if (!t.has("material_axis_1") && !t.has("material_axis_2")) return fem::kIdentityAxes;
  auto a = to_v3(t.vec3("material_axis_1"));
  auto b = to_v3(t.vec3_or("material_axis_2", {0, 1, 0}));
  const double na = norm(a);
  if (!(na > 0)) t.fail("material_axis_1", "must not be zero");
  a = (1.0 / na) * a;
  b = b - dot(a, b) * a;
  const double nb = norm(b);
  if (!(nb > 1e-8)) t.fail("material_axis_2", "must not be parallel to material_axis_1");
  b = (1.0 / nb) * b;
  const V3 c = cross(a, b);
  return {a.x, b.x, c.x, a.y, b.y, c.y, a.z, b.z, c.z};
}

void read_tools(const TableReader& root, EngineCase& ec, const std::string& file) {
  for (const auto& t : root.tables("tool")) {
    fem::RigidTool tool;
    tool.name = t.string("name");
    const std::string shape =
        t.choice("shape", {"plane", "sphere", "cylinder", "torus", "plane_with_hole", "stl"}, "");
    auto& s = tool.surface;
    s.point = to_v3(t.vec3_or("point", {0, 0, 0}));
    if (t.has("axis") || shape != "stl") {
      V3 ax = to_v3(t.vec3_or("axis", {0, 0, 1}));
      if (!(norm(ax) > 0)) t.fail("axis", "must not be zero");
      s.axis = (1.0 / norm(ax)) * ax;
    }
    if (shape == "plane") s.shape = fem::ToolShape::Plane;
    if (shape == "sphere" || shape == "cylinder" || shape == "torus" || shape == "plane_with_hole") {
      s.shape = shape == "sphere" ? fem::ToolShape::Sphere
              : shape == "cylinder" ? fem::ToolShape::Cylinder
              : shape == "torus" ? fem::ToolShape::Torus
                                 : fem::ToolShape::PlaneWithHole;
      s.radius = t.number("radius", Range::positive());
    }
    if (shape == "torus") s.minor_radius = t.number("minor_radius", Range::positive());
    if (shape == "sphere" || shape == "cylinder" || shape == "torus") s.body_inside = t.boolean("body_inside", false);
    if (shape == "stl") {
      s.shape = fem::ToolShape::Triangles;
      std::filesystem::path stl = t.string("file");
      if (stl.is_relative()) stl = std::filesystem::path(file).parent_path() / stl;
      const double scale = t.number("scale", 1.0, Range::positive());
      try {
        s.triangles = std::make_shared<fem::TriangleSurface>(fem::TriangleSurface::read_stl(stl.string(), scale));
      } catch (const std::exception& e) {
        t.fail("file", std::string("cannot read STL: ") + e.what());
      }
      s.search_radius = t.number("search_radius", Range::positive());
    }
    const std::string motion = t.choice("motion", {"fixed", "velocity", "force"}, "fixed");
    if (motion == "velocity") {
      tool.motion.kind = fem::ToolMotion::Kind::Velocity;
      tool.motion.velocity = to_v3(t.vec3("velocity"));
      tool.motion.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
    } else if (motion == "force") {
      tool.motion.kind = fem::ToolMotion::Kind::Force;
      V3 ax = to_v3(t.vec3_or("force_axis", {0, 0, -1}));
      if (!(norm(ax) > 0)) t.fail("force_axis", "must not be zero");
      tool.motion.axis = (1.0 / norm(ax)) * ax;
      tool.motion.force = t.number("force", Range::non_negative());
      tool.motion.mass = t.number("mass", Range::positive());
    }
    tool.friction = t.number("friction", 0.0, Range::non_negative());
    tool.penalty_scale = t.number("penalty_scale", 0.1, Range::open_closed(0, 1.0));
    tool.damping = t.number("damping", 0.1, Range::closed(0, 1.0));
    tool.thickness = t.number("thickness", 0.0, Range::non_negative());
    tool.contact_nodes = select_nodes(t, "contact_nodes", ec.model.mesh);
    ec.model.tools.push_back(std::move(tool));
  }
}

std::vector<int> part_indices(const TableReader& t, std::string_view key, const fem::Mesh& mesh) {
  std::vector<int> out;
  for (const auto& name : t.strings(key)) {
    const int p = mesh.find_part(name);
    if (p < 0) t.fail(key, "no part named '" + name + "'");
    out.push_back(p);
  }
  if (out.empty()) t.fail(key, "needs at least one part");
  return out;
}

// Deformable contacts: penalty (groups of parts and pairs with a friction coefficient) and tied.
void read_contacts(const TableReader& root, EngineCase& ec, const std::string& file) {
  const fem::Mesh& mesh = ec.model.mesh;
  for (const auto& t : root.tables("contact")) {
    const std::string type = t.choice("type", {"penalty", "tied"}, "penalty");
    const std::string name = t.string("name");
    try {
      if (type == "penalty") {
        fem::PenaltyContactConfig c;
        c.name = name;
        c.source_file = file;
        c.penalty_scale = t.number("penalty_scale", c.penalty_scale, Range::open_closed(0, 0.5));
        c.thickness = t.number("thickness", 0.0, Range::non_negative());
        c.search_margin = t.number("search_margin", 0.0, Range::non_negative());
        c.edge_tolerance = t.number("edge_tolerance", c.edge_tolerance, Range::closed(0, 0.5));
        c.max_penetration = t.number("max_penetration", c.max_penetration, Range::open_closed(0, 1));
        std::map<std::string, int> groups;
        for (const auto& g : t.tables("group")) {
          fem::ContactGroup cg;
          cg.name = g.string("name");
          if (groups.count(cg.name)) g.fail("name", "duplicate contact group '" + cg.name + "'");
          cg.parts = part_indices(g, "parts", mesh);
          groups[cg.name] = static_cast<int>(c.groups.size());
          c.groups.push_back(std::move(cg));
        }
        if (c.groups.empty()) t.fail("group", "a penalty contact needs at least one [[contact.group]]");
        for (const auto& pr : t.tables("pair")) {
          const auto names = pr.strings("groups");
          if (names.size() != 2) pr.fail("groups", "must name exactly 2 groups (the same twice for self-contact)");
          fem::ContactPair cp;
          for (int k = 0; k < 2; ++k) {
            const auto it = groups.find(names[static_cast<std::size_t>(k)]);
            if (it == groups.end()) pr.fail("groups", "no [[contact.group]] named '" + names[static_cast<std::size_t>(k)] + "'");
            (k == 0 ? cp.first : cp.second) = it->second;
          }
          cp.friction = pr.number("friction", 0.0, Range::non_negative());
          c.pairs.push_back(cp);
        }
        if (c.pairs.empty()) t.fail("pair", "a penalty contact needs at least one [[contact.pair]]");
        ec.model.contacts.push_back(std::make_unique<fem::PenaltyContact>(std::move(c)));
      } else {
        fem::TiedContactConfig c;
        c.name = name;
        c.source_file = file;
        c.slave = {name + "_slave", part_indices(t, "slave_parts", mesh)};
        c.master = {name + "_master", part_indices(t, "master_parts", mesh)};
        c.penalty_scale = t.number("penalty_scale", c.penalty_scale, Range::open_closed(0, 0.5));
        c.search_distance = t.number("search_distance", 0.0, Range::non_negative());
        c.normal_strength = t.number("normal_strength", 0.0, Range::non_negative());
        c.shear_strength = t.number("shear_strength", 0.0, Range::non_negative());
        ec.model.contacts.push_back(std::make_unique<fem::TiedContact>(std::move(c)));
      }
    } catch (const InputError& e) {
      throw;
    } catch (const std::invalid_argument& e) {
      t.fail("type", e.what());
    }
  }
}

}  // namespace

EngineCase load_engine_case(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  CaseDocument doc = CaseDocument::load(file, overrides);
  g_tow_end_pins.clear();
  const std::string fname = file.string();
  TableReader root(doc, doc.root(), "");
  EngineCase ec;
  ec.file = file;

  const TableReader c = root.required_table("case");
  ec.name = c.string("name");
  if (ec.name.empty() || ec.name.find_first_of("/\\ ") != std::string::npos)
    c.fail("name", "must be a non-empty name without spaces or slashes (it names the output folder)");
  ec.kind = c.choice("kind", {"engine"}, "engine");
  ec.description = c.string("description", "");

  // Mesh.
  if (!root.has("mesh"))
    root.fail("mesh", "missing (required section [mesh] with [[mesh.block]] or [[mesh.line]] entries)");
  const TableReader m = root.required_table("mesh");
  ec.resolution = m.choice("resolution", {"coarse", "default", "fine"}, "default");
  const double rf = resolution_factor(ec.resolution);
  fem::Mesh& mesh = ec.model.mesh;
  std::map<std::string, std::string> part_kind;  // part -> "solid" | "bar"
  const auto blocks = m.tables("block");
  const auto lines = m.tables("line");
  if (blocks.empty() && lines.empty() && !m.has("fabric"))
    m.fail("block", "the mesh has no elements: give at least one [[mesh.block]], [[mesh.line]] or [[mesh.fabric]]");
  for (const auto& b : blocks) {
    const std::string part = b.string("part");
    const auto origin = b.vec3_or("origin", {0, 0, 0});
    const auto size = b.vec3("size", Range::positive());
    const auto divv = b.numbers("divisions", Range::closed(1, 1e6), 3);
    if (divv.size() != 3) b.fail("divisions", "must hold exactly 3 integers [nx, ny, nz]");
    std::array<int, 3> div{};
    for (int k = 0; k < 3; ++k) {
      const double d = divv[static_cast<std::size_t>(k)];
      if (d != std::floor(d)) b.fail("divisions", "must be integers");
      div[static_cast<std::size_t>(k)] = d == 1 ? 1 : std::max(1, static_cast<int>(std::lround(d * rf)));
    }
    if (part_kind.count(part) && part_kind[part] != "solid")
      b.fail("part", "'" + part + "' already holds bars");
    part_kind[part] = "solid";
    int p = mesh.find_part(part);
    if (p < 0) p = mesh.add_part(part);
    fem::add_hex_block(mesh, p, origin, size, div);
  }
  for (const auto& l : lines) {
    const std::string part = l.string("part");
    const auto a = l.vec3("start"), bnd = l.vec3("end");
    const int nd = static_cast<int>(l.integer("divisions", 1, 1000000));
    const int n_div = std::max(1, static_cast<int>(std::lround(nd * rf)));
    if (part_kind.count(part) && part_kind[part] != "bar") l.fail("part", "'" + part + "' already holds hexahedra");
    part_kind[part] = "bar";
    int p = mesh.find_part(part);
    if (p < 0) p = mesh.add_part(part);
    const std::int32_t first = static_cast<std::int32_t>(mesh.n_nodes());
    for (int i = 0; i <= n_div; ++i) {
      const double s = static_cast<double>(i) / n_div;
      for (int k = 0; k < 3; ++k)
        mesh.coords.push_back(a[static_cast<std::size_t>(k)] + s * (bnd[static_cast<std::size_t>(k)] - a[static_cast<std::size_t>(k)]));
    }
    for (int i = 0; i < n_div; ++i) {
      mesh.elements(fem::ElementKind::Bar2).add({first + i, first + i + 1}, p);
    }
  }
  struct FabricEntry {
    std::string name, tow_material, law_I, law_Lambda, law_legs;
    std::vector<double> angles;
    int elements_through_thickness = 1;
    drape::FabricModel model;
    drape::StitchConnectionSettings connection;
    std::string path;
  };
  std::vector<FabricEntry> fabrics;
  for (const auto& fb : m.tables("fabric")) {
    FabricEntry fe;
    fe.path = fb.path();
    fe.name = fb.string("name");
    drape::FabricSpec f;
    if (fb.has("ply_angles_deg")) f.ply_angles_deg = fb.numbers("ply_angles_deg", Range::closed(-90, 90));
    f.tow_width = fb.number("tow_width", f.tow_width, Range::positive());
    f.tow_gap = fb.number("tow_gap", f.tow_gap, Range::positive());
    f.areal_weight = fb.number("areal_weight", f.areal_weight, Range::positive());
    f.fibre_density = fb.number("fibre_density", f.fibre_density, Range::positive());
    f.tow_fibre_volume_fraction = fb.number("tow_fibre_volume_fraction", f.tow_fibre_volume_fraction, Range::open_closed(0, 0.9069));
    const std::string stitch = fb.choice("stitch", {"tricot", "chain", "none"}, "tricot");
    f.stitch = stitch == "tricot" ? drape::StitchPattern::Tricot : stitch == "chain" ? drape::StitchPattern::Chain : drape::StitchPattern::None;
    f.stitch_direction_deg = fb.number("stitch_direction_deg", 0.0, Range::closed(-90, 90));
    f.stitch_gauge = fb.number("stitch_gauge", 0.0, Range::non_negative());
    f.stitch_length = fb.number("stitch_length", 0.0, Range::non_negative());
    f.elements_across_tow = static_cast<int>(fb.integer("elements_across_tow", 2, 1, 16));
    f.elements_through_thickness = static_cast<int>(fb.integer("elements_through_thickness", 1, 1, 8));
    f.element_length = fb.number("element_length", 0.0, Range::non_negative());
    if (ec.resolution == "coarse") {
      f.elements_across_tow = std::max(1, f.elements_across_tow / 2);
      f.element_length = 2 * (f.element_length > 0 ? f.element_length : f.tow_pitch());
    } else if (ec.resolution == "fine") {
      f.elements_across_tow *= 2;
      f.element_length = 0.5 * (f.element_length > 0 ? f.element_length : f.tow_pitch());
    }
    drape::BlanketSpec bl;
    const auto origin = fb.vec3_or("origin", {0, 0, 0});
    bl.origin = {origin[0], origin[1]};
    bl.z0 = origin[2];
    const auto size = fb.numbers("size", Range::positive(), 2);
    if (size.size() != 2) fb.fail("size", "must hold 2 numbers [length along x, width along y]");
    bl.size = {size[0], size[1]};
    fe.tow_material = fb.string("tow_material");
    if (f.stitch != drape::StitchPattern::None) {
      fe.law_I = fb.string("stitch_law_I");
      fe.law_Lambda = f.stitch == drape::StitchPattern::Tricot ? fb.string("stitch_law_Lambda") : fe.law_I;
      fe.law_legs = fb.string("stitch_law_legs", fe.law_I);
      fe.connection.sliding_force = fb.number("connection_sliding_force", 0.05, Range::positive());
      fe.connection.transverse_force = fb.number(
          "connection_transverse_force", 3 * fe.connection.sliding_force, Range::non_negative());
      fe.connection.stiffness = fb.number("connection_stiffness", 0.0, Range::non_negative());
    }
    fe.angles = f.ply_angles_deg;
    fe.elements_through_thickness = f.elements_through_thickness;
    drape::validate(f, fname, fb.path());
    if (!(bl.size[0] >= f.tow_pitch() * (1 - 1e-9) && bl.size[1] >= f.tow_pitch() * (1 - 1e-9)))
      fb.fail("size", "the blanket must be at least one tow pitch (" + std::to_string(f.tow_pitch()) + " m) long and wide");
    if (fe.name.empty() || fe.name.find_first_of(" ./\\") != std::string::npos)
      fb.fail("name", "must be a non-empty name without spaces, dots or slashes (it prefixes the part names)");
    fe.model = drape::generate_blanket(mesh, f, bl, fname, fe.name + "_");
    for (int p : fe.model.ply_parts) part_kind[mesh.part_names[static_cast<std::size_t>(p)]] = "fabric";
    for (int p : {fe.model.stitch_I_part, fe.model.stitch_Lambda_part, fe.model.stitch_leg_part})
      if (p >= 0) part_kind[mesh.part_names[static_cast<std::size_t>(p)]] = "fabric";
    fabrics.push_back(std::move(fe));
  }
  const auto new_of_old = fem::renumber_for_locality(mesh);
  for (auto& fe : fabrics) {
    for (auto& c : fe.model.connections)
      for (std::int32_t* nd : {&c.stitch_node, &c.tow_node, &c.tow_axis_node})
        *nd = new_of_old[static_cast<std::size_t>(*nd)];
    for (auto& nd : fe.model.stitch_nodes) nd = new_of_old[static_cast<std::size_t>(nd)];
    for (auto& nd : fe.model.tow_end_pins) nd = new_of_old[static_cast<std::size_t>(nd)];
    g_tow_end_pins[fe.name] = fe.model.tow_end_pins;
  }
  mesh.fill_default_user_ids();

  // Materials and bar laws.
  std::map<std::string, int> materials, bar_laws;
  for (const auto& t : root.tables("material")) {
    const std::string name = t.string("name");
    if (materials.count(name)) t.fail("name", "duplicate material '" + name + "'");
    ec.model.materials.push_back(read_material(t, name));
    materials[name] = static_cast<int>(ec.model.materials.size()) - 1;
  }
  for (const auto& t : root.tables("bar_law")) {
    const std::string name = t.string("name");
    if (bar_laws.count(name)) t.fail("name", "duplicate bar law '" + name + "'");
    ec.model.bar_laws.push_back(read_bar_law(t, name));
    bar_laws[name] = static_cast<int>(ec.model.bar_laws.size()) - 1;
  }

  // Parts.
  ec.model.parts.assign(mesh.part_names.size(), {});
  std::vector<char> defined(mesh.part_names.size(), 0);
  for (const auto& t : root.tables("part")) {
    const std::string name = t.string("name");
    const int p = mesh.find_part(name);
    if (p < 0) t.fail("name", "no mesh block or line uses part '" + name + "'");
    if (part_kind[name] == "fabric") t.fail("name", "part '" + name + "' belongs to a [[mesh.fabric]]: its properties come from there");
    auto& pp = ec.model.parts[static_cast<std::size_t>(p)];
    defined[static_cast<std::size_t>(p)] = 1;
    if (part_kind[name] == "solid") {
      const std::string mat = t.string("material");
      if (!materials.count(mat)) t.fail("material", "no [[material]] named '" + mat + "'");
      pp.material = materials[mat];
      pp.material_axes = read_axes(t);
      pp.hourglass_stiffness = t.number("hourglass_stiffness", 1.0, Range::closed(0, 10));
      pp.hourglass_viscosity = t.number("hourglass_viscosity", 0.05, Range::closed(0, 1));
    } else {
      const std::string law = t.string("bar_law");
      if (!bar_laws.count(law)) t.fail("bar_law", "no [[bar_law]] named '" + law + "'");
      pp.bar_law = bar_laws[law];
    }
  }
  for (const auto& fe : fabrics) {
    auto need = [&](const std::map<std::string, int>& names, const std::string& n, const std::string& key) {
      if (!names.count(n)) throw InputError(fname, fe.path + "." + key, "no such " + (key == "tow_material" ? std::string("[[material]]") : std::string("[[bar_law]]")) + " '" + n + "'");
      return names.at(n);
    };
    const int tow = need(materials, fe.tow_material, "tow_material");
    // E11f_axial leaves bending to E11f through the hourglass moduli, which carry all of the
    // bending only with one hexahedron through the tow: with more, the layers' stretch (E11f_axial)
    // would bend it.
    const auto* tow_law = dynamic_cast<const drape::TowMaterial*>(
        ec.model.materials[static_cast<std::size_t>(tow)].get());
    if (tow_law && tow_law->constants().E11f_axial > 0 && fe.elements_through_thickness > 1)
      throw InputError(fname, fe.path + ".elements_through_thickness",
                       "must be 1 with tow material '" + fe.tow_material +
                           "', which sets E11f_axial (its bending stiffness, E11f, is separate "
                           "from its stretch only with "
                           "one hexahedron through the tow thickness)");
    for (std::size_t q = 0; q < fe.model.ply_parts.size(); ++q) {
      auto& pp = ec.model.parts[static_cast<std::size_t>(fe.model.ply_parts[q])];
      pp.material = tow;
      const double al = fe.angles[q] * M_PI / 180.0;
      pp.material_axes = {std::cos(al), -std::sin(al), 0, std::sin(al), std::cos(al), 0, 0, 0, 1};
      defined[static_cast<std::size_t>(fe.model.ply_parts[q])] = 1;
    }
    const std::pair<int, std::string> bar_parts[] = {{fe.model.stitch_I_part, fe.law_I}, {fe.model.stitch_Lambda_part, fe.law_Lambda},
                                                     {fe.model.stitch_leg_part, fe.law_legs}};
    for (const auto& [p, law] : bar_parts) {
      if (p < 0) continue;
      auto& pp = ec.model.parts[static_cast<std::size_t>(p)];
      pp.bar_law = need(bar_laws, law, law == fe.law_I ? "stitch_law_I" : law == fe.law_Lambda ? "stitch_law_Lambda" : "stitch_law_legs");
      defined[static_cast<std::size_t>(p)] = 1;
    }
    int connection_contact = -1;
    if (!fe.model.connections.empty()) {
      connection_contact = static_cast<int>(ec.model.contacts.size());
      ec.model.contacts.push_back(std::make_unique<drape::StitchToTowConnection>(fe.name + "_stitch_tow", fe.model.connections, fe.connection));
    }
    ec.fabric_summaries.push_back({fe.name, fe.model.n_tows, fe.model.n_dropped_tows,
                                   fe.model.n_penetrations, fe.model.connections.size(),
                                   fe.model.tow_thickness, connection_contact});
  }
  for (std::size_t p = 0; p < defined.size(); ++p)
    if (!defined[p]) root.fail("part", "part '" + mesh.part_names[p] + "' has no [[part]] entry (material)");

  // Boundary conditions, loads, initial conditions.
  if (auto bc = root.table("boundary")) {
    for (const auto& t : bc->tables("fixed")) {
      fem::FixedDofs fx;
      fx.name = t.string("name");
      fx.nodes = select_nodes(t, "nodes", mesh);
      fx.dofs = read_dofs(t, "dofs", {true, true, true});
      ec.reactions.push_back({fx.name, fx.nodes});
      ec.model.fixed.push_back(std::move(fx));
    }
    for (const auto& t : bc->tables("velocity")) {
      fem::PrescribedVelocity pv;
      pv.name = t.string("name");
      pv.nodes = select_nodes(t, "nodes", mesh);
      pv.velocity = to_v3(t.vec3("velocity"));
      pv.dofs = read_dofs(t, "dofs", {true, true, true});
      pv.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
      pv.start_time = t.number("start_time", 0.0, Range::non_negative());
      ec.reactions.push_back({pv.name, pv.nodes});
      ec.model.velocities.push_back(std::move(pv));
    }
  }
  std::vector<double> frame_final_angles;
  if (auto bc = root.table("boundary"))
    for (const auto& t : bc->tables("picture_frame")) {
      fem::PictureFrame pf;
      pf.name = t.string("name");
      pf.nodes = select_nodes(t, "nodes", mesh);
      pf.corner = to_v3(t.vec3("corner"));
      V3 a1 = to_v3(t.vec3_or("arm1", {1, 0, 0})), a2 = to_v3(t.vec3_or("arm2", {0, 1, 0}));
      if (!(norm(a1) > 0) || !(norm(a2) > 0)) t.fail("arm1", "arms must not be zero");
      a1 = normalized(a1), a2 = normalized(a2);
      if (std::abs(dot(a1, a2)) > 1e-6) t.fail("arm2", "must be orthogonal to arm1");
      pf.arm1 = a1, pf.arm2 = a2;
      pf.arm_length = t.number("arm_length", Range::positive());
      pf.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
      if (t.has("wall_nodes_arm1")) pf.walls[0] = select_nodes(t, "wall_nodes_arm1", mesh);
      if (t.has("wall_nodes_arm2")) pf.walls[1] = select_nodes(t, "wall_nodes_arm2", mesh);
      pf.wall_penalty_scale = t.number("wall_penalty_scale", 0.1, Range::open_closed(0, 1));
      frame_final_angles.push_back(t.number("final_shear_angle_deg", Range::open_closed(0, 80)) * M_PI / 180.0);
      ec.frame_fabric_length.push_back(t.number("fabric_length", pf.arm_length, Range::positive()));
      ec.model.picture_frames.push_back(std::move(pf));
    }
  if (auto ld = root.table("load")) {
    ec.model.gravity = to_v3(ld->vec3_or("gravity", {0, 0, 0}));
    ec.model.gravity_ramp_time = ld->number("gravity_ramp_time", 0.0, Range::non_negative());
    for (const auto& t : ld->tables("nodal_force")) {
      fem::NodalLoad l;
      l.name = t.string("name");
      l.nodes = select_nodes(t, "nodes", mesh);
      l.force_per_node = (1.0 / static_cast<double>(l.nodes.size())) * to_v3(t.vec3("total_force"));
      l.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
      ec.model.loads.push_back(std::move(l));
    }
  }
  if (auto d = root.table("damping")) {
    ec.model.mass_damping = d->number("mass_proportional", 0.0, Range::non_negative());
    ec.model.mass_damping_end_time = d->number("end_time", 0.0, Range::non_negative());
  }
  if (auto init = root.table("initial"))
    for (const auto& t : init->tables("velocity"))
      ec.model.initial_velocities.push_back({select_nodes(t, "nodes", mesh), to_v3(t.vec3("velocity"))});

  read_tools(root, ec, fname);
  read_contacts(root, ec, fname);

  // Time controls.
  const TableReader tc = root.required_table("time");
  auto& time = ec.model.time;
  time.end_time = tc.number("end_time", Range::positive());
  time.safety_factor = tc.number("safety_factor", 0.9, Range::open_closed(0, 1));
  time.mass_scaling_dt = tc.number("mass_scaling_dt", 0.0, Range::non_negative());
  time.history_interval = tc.number("history_interval", time.end_time / 200, Range::positive());
  time.frame_interval = tc.number("frame_interval", time.end_time / 20, Range::positive());
  time.max_cycles = tc.integer("max_cycles", 0, 0, std::int64_t{1} << 50);
  time.energy_balance_limit = tc.number("energy_balance_limit", 0.05, Range::open_closed(0, 1));
  time.erosion_step_ratio = tc.number("erosion_step_ratio", 0.0, Range{0, 1, false, true});
  if (time.erosion_step_ratio > 0 && time.erosion_step_ratio <= time.min_step_ratio)
    tc.fail("erosion_step_ratio", "must be 0 (off) or above " +
                                      std::to_string(time.min_step_ratio) +
                                      ", the share of the initial step at which a run stops");
  for (std::size_t k = 0; k < ec.model.picture_frames.size(); ++k) {  // constant rate to the final angle at end_time
    auto& pf = ec.model.picture_frames[k];
    if (!(time.end_time > pf.ramp_time)) tc.fail("end_time", "must exceed the picture frame's ramp_time");
    pf.shear_rate = frame_final_angles[k] / (time.end_time - 0.5 * pf.ramp_time);
  }

  // Output.
  if (auto o = root.table("output")) {
    const std::string frames = o->choice("frames", {"xdmf", "vtu", "both", "none"}, "xdmf");
    ec.output.xdmf = frames == "xdmf" || frames == "both";
    ec.output.vtu = frames == "vtu" || frames == "both";
    ec.output.figures = o->boolean("figures", true);
    ec.output.report = o->boolean("report", false);
    for (const auto& t : o->tables("probe")) ec.probes.push_back({t.string("name"), select_nodes(t, "nodes", mesh)});
    for (const auto& t : o->tables("shear_probe")) {
      ShearProbe sp;
      sp.name = t.string("name");
      const auto parts = t.strings("parts");
      if (parts.size() != 2) t.fail("parts", "must name exactly 2 parts (the two plies)");
      sp.part_a = mesh.find_part(parts[0]);
      sp.part_b = mesh.find_part(parts[1]);
      if (sp.part_a < 0 || sp.part_b < 0) t.fail("parts", "no part named '" + parts[sp.part_a < 0 ? 0 : 1] + "'");
      sp.box_min = t.vec3("box_min");
      sp.box_max = t.vec3("box_max");
      ec.shear_probes.push_back(sp);
    }
    for (const auto& t : o->tables("mean")) {
      SummaryMean sm;
      sm.name = t.string("name");
      sm.column = t.string("column");
      sm.from_time = t.number("from_time", Range::non_negative());
      sm.to_time = t.number("to_time", Range::positive());
      if (!(sm.to_time > sm.from_time)) t.fail("to_time", "must be after from_time");
      sm.scale = t.number("scale", 1.0, {});
      sm.per_column = t.string("per_column", "");
      ec.means.push_back(sm);
    }
    for (const auto& t : o->tables("bending_length")) {
      BendingLengthProbe bp;
      bp.name = t.string("name");
      bp.part = mesh.find_part(t.string("part"));
      if (bp.part < 0) t.fail("part", "no such part");
      bp.root = select_nodes(t, "root", mesh);
      bp.tip = select_nodes(t, "tip", mesh);
      ec.bending.push_back(std::move(bp));
    }
    for (const auto& t : o->tables("sample")) {
      SummarySamples ss;
      ss.x = t.string("x");
      ss.x_display_scale = t.number("x_display_scale", 1e3, Range::positive());
      ss.x_unit = t.string("x_unit", "mm");
      ss.at = t.numbers("at", {}, 1);
      if (auto cols = t.table("columns")) {
        for (const auto& [k, v] : doc.root().at_path(cols->path()).as_table() ? *doc.root().at_path(cols->path()).as_table() : toml::table{})
          ss.columns.emplace_back(std::string(k.str()), cols->string(k.str()));
      }
      const std::string analytic = t.choice("analytic", {"none", "bias_extension"}, "none");
      if (analytic == "bias_extension") {
        ss.bias_extension_analytic = true;
        ss.coupon_length = t.number("coupon_length", Range::positive());
        ss.coupon_width = t.number("coupon_width", Range::positive());
        if (!(ss.coupon_length > ss.coupon_width)) t.fail("coupon_length", "must exceed coupon_width");
      }
      ec.samples.push_back(std::move(ss));
    }
  }
  if (auto f = root.table("figures")) {
    for (const auto& t : f->tables("plot")) {
      PlotSpec p;
      p.name = t.string("name");
      p.title = t.string("title", p.name);
      p.x = t.string("x", "time");
      p.y = t.strings("y");
      p.x_scale = t.number("x_scale", 1.0, {});
      p.y_scale = t.number("y_scale", 1.0, {});
      p.x_label = t.string("x_label", p.x);
      p.y_label = t.string("y_label", p.y.empty() ? "" : p.y.front());
      for (const auto& it : t.tables("import")) {
        ImportedSeries is;
        is.file = it.string("file");
        if (is.file.is_relative()) is.file = std::filesystem::absolute(file.parent_path() / is.file);
        if (!std::filesystem::exists(is.file)) it.fail("file", "no such file: " + is.file.string());
        is.x = it.string("x");
        is.y = it.string("y");
        is.label = it.string("label", is.file.stem().string());
        is.x_scale = it.number("x_scale", 1.0, {});
        is.y_scale = it.number("y_scale", 1.0, {});
        p.imports.push_back(std::move(is));
      }
      for (const auto& rt : t.tables("reference"))
        p.references.push_back({rt.string("label"), rt.number("y", {})});
      ec.plots.push_back(std::move(p));
    }
    for (const auto& t : f->tables("picture")) {
      PictureSpec p;
      p.name = t.string("name");
      p.field = t.choice("field",
                         {"displacement_magnitude", "displacement", "velocity", "stress", "von_mises_stress",
                          "fibre_direction", "axial_force", "axial_strain", "none"},
                         "displacement_magnitude");
      p.component = static_cast<int>(t.integer("component", -1, -1, 5));
      p.camera = t.choice("camera", {"iso", "top", "front"}, "iso");
      p.title = t.string("title", "");
      p.follow_part = t.string("follow_part", "");
      if (!p.follow_part.empty() && mesh.find_part(p.follow_part) < 0)
        t.fail("follow_part", "no part named '" + p.follow_part + "'");
      p.deformation_scale = t.number("deformation_scale", 1.0, Range::non_negative());
      ec.pictures.push_back(std::move(p));
    }
  }

  doc.check_unknown_keys();
  return ec;
}

}  // namespace ncfsim::workflow
