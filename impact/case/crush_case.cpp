#include "impact/case/crush_case.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "fem/case/source_result.hpp"
#include "fem/case/stage_kinds.hpp"
#include "fem/contact/tied_contact.hpp"
#include "fem/elements/hex8_block.hpp"
#include "fem/errors.hpp"
#include "fem/io/stage_handoff.hpp"

namespace ncfsim::impact {

namespace {

using fem::CaseReadContext;
using fem::TableReader;

// [material] tables of type tow_damage, and [model.damage]: the damage keys shared by both.
void read_damage_keys(const TableReader& t, TowDamageConstants& c) {
  const auto fe = t.required_table("fracture_energy");
  for (int m = 0; m < kModes; ++m)
    c.fracture_energy[static_cast<std::size_t>(m)] =
        fe.number(kModeNames[static_cast<std::size_t>(m)], Range::positive());
  c.fracture_energy_key = t.key_path("fracture_energy");
  c.residual_compression = t.number("residual_compression", 0.0, Range{0, 1, false, true});
  c.raise_to_crack_band = t.choice("crack_band", {"refuse", "raise"}, "refuse") == "raise";
  if (t.has("erode_on")) {
    c.erode_on.fill(false);
    for (const auto& name : t.strings("erode_on")) {
      const auto it = std::find(kModeNames.begin(), kModeNames.end(), name);
      if (it == kModeNames.end()) {
        std::string allowed;
        for (const char* n : kModeNames) allowed += (allowed.empty() ? "" : ", ") + std::string(n);
        t.fail("erode_on", "'" + name + "' is not a failure mode; allowed: " + allowed);
      }
      c.erode_on[static_cast<std::size_t>(it - kModeNames.begin())] = true;
    }
  }
}

std::unique_ptr<fem::SolidMaterial> read_tow_damage(const TableReader& t, const std::string& name,
                                                    double rho) {
  TowDamageConstants c;
  c.density = rho;
  auto& e = c.elastic;
  e.E1 = t.number("E1", Range::positive());
  e.E2 = t.number("E2", Range::positive());
  e.E3 = t.number("E3", e.E2, Range::positive());
  e.nu12 = t.number("nu12", {-1.0, 1.0, true, true});
  e.nu13 = t.number("nu13", e.nu12, {-1.0, 1.0, true, true});
  e.nu23 = t.number("nu23", {-1.0, 1.0, true, true});
  e.G12 = t.number("G12", Range::positive());
  e.G13 = t.number("G13", e.G12, Range::positive());
  e.G23 = t.number("G23", Range::positive());
  // Compressive strengths: given, or compressive_ratio of the tensile ones (the paper's ~60 %).
  const double ratio = t.number("compressive_ratio", 0.6, Range::open_closed(0, 1.5));
  auto& s = c.strength;
  s.Xt = t.number("Xt", Range::positive());
  s.Xc = t.number("Xc", ratio * s.Xt, Range::positive());
  s.Yt = t.number("Yt", Range::positive());
  s.Yc = t.number("Yc", ratio * s.Yt, Range::positive());
  s.S12 = t.number("S12", Range::positive());
  s.S23 = t.number("S23", s.S12, Range::positive());
  read_damage_keys(t, c);
  return std::make_unique<TowDamageMaterial>(name, c);
}

// ties.csv of a transfer: interface,slave_element_id,slave_face,master_element_id,master_face.
struct TieRow {
  std::string interface;
  std::int64_t slave_id, master_id;
  int slave_face, master_face;
};

std::vector<TieRow> read_ties_csv(const std::filesystem::path& file) {
  std::ifstream in(file);
  if (!in) throw std::runtime_error("cannot read " + file.string());
  std::vector<TieRow> rows;
  std::string line;
  std::getline(in, line);  // header
  std::size_t number = 1;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty()) continue;
    std::stringstream ss(line);
    std::string cell[5];
    int k = 0;
    while (k < 5 && std::getline(ss, cell[k], ',')) ++k;
    try {
      if (k != 5) throw std::invalid_argument("five columns");
      rows.push_back({cell[0], std::stoll(cell[1]), std::stoll(cell[3]), std::stoi(cell[2]),
                      std::stoi(cell[4])});
    } catch (const std::exception&) {
      throw std::runtime_error(fmt::format(
          "{} line {}: expected interface,slave_element_id,slave_face,master_element_id,"
          "master_face",
          file.string(), number));
    }
  }
  return rows;
}

// A cell field of the frame, hexahedra only (n_hex * components values).
const fem::io::FrameField& cell_field(const fem::io::StageFrame& fr, const std::string& name,
                                      int components, const TableReader& t) {
  const auto* f = fr.field(name);
  if (!f || !f->on_cells || f->n_components != components)
    t.fail("source", fmt::format("{} has no cell field '{}' ({} components): not the results of "
                                 "a transfer (`kind = \"transfer\"`)",
                                 fr.file.string(), name, components));
  return *f;
}

}  // namespace

void register_impact_case_types(fem::CaseTypeRegistry& registry) {
  registry.add_material_type("tow_damage", read_tow_damage);
}

bool has_impregnated_model(const CaseReadContext& ctx) { return ctx.root.has("model"); }

namespace {

// The transfer's results.h5 named by model.source (its own record says so), its last frame.
fem::io::StageFrame read_source_frame(const TableReader& m, ImpregnatedImport& im) {
  im.source = m.string("source");
  if (im.source.is_relative())
    im.source = std::filesystem::absolute(m.file().parent_path() / im.source);
  if (!std::filesystem::exists(im.source))
    m.fail("source", "no such file: " + im.source.string() +
                         " (run the transfer first: ncfsim run cases/hemisphere/transfer.toml)");
  fem::require_result_of(m, "source", im.source, {fem::stage_kind::kTransfer},
                         "a crush needs a transfer's results (ncfsim run "
                         "cases/hemisphere/transfer.toml makes one)");
  fem::io::StageFrame fr;
  try {
    fr = fem::io::read_last_frame(im.source);
  } catch (const std::exception& e) {
    m.fail("source", e.what());
  }
  if (fr.mesh.n_hex() == 0) m.fail("source", im.source.string() + " holds no hexahedra");
  return fr;
}

// The mesh node of a result point, made on first use: the nodes in first-use order (the
// transfer's order is the drape's locality order: kept, no renumbering).
struct NodeImport {
  fem::Mesh& mesh;
  const fem::io::ResultMesh& rm;
  std::vector<std::int32_t> node_of;
  NodeImport(fem::Mesh& m, const fem::io::ResultMesh& r)
      : mesh(m), rm(r), node_of(r.n_points(), -1) {}
  std::int32_t operator()(std::int64_t point) {
    const auto p = static_cast<std::size_t>(point);
    if (node_of[p] < 0) {
      node_of[p] = static_cast<std::int32_t>(mesh.n_nodes());
      for (std::size_t c = 0; c < 3; ++c) mesh.coords.push_back(rm.points[3 * p + c]);
      mesh.node_user_id.push_back(rm.node_user_id.empty() ? static_cast<std::int64_t>(p + 1)
                                                          : rm.node_user_id[p]);
    }
    return node_of[p];
  }
};

// The tow hexahedra with their material frames, and their Vf classes (a class's constants are
// those of its first element).
void import_hexahedra(const TableReader& m, const fem::io::StageFrame& fr, NodeImport& node,
                      ImpregnatedImport& im) {
  const auto& rm = fr.mesh;
  const std::size_t nh = rm.n_hex();
  fem::Mesh& mesh = node.mesh;
  // The transfer's own fields; their absence means another kind of result.
  const auto& f1 = cell_field(fr, "fibre_direction", 3, m);
  const auto& f2 = cell_field(fr, "material_axis_2", 3, m);
  const auto& f3 = cell_field(fr, "material_axis_3", 3, m);
  const auto& cls = cell_field(fr, "vf_class", 1, m);
  auto scalar = [&](const char* name) { return &cell_field(fr, name, 1, m).values; };
  const std::vector<double>* rho = scalar("density_kg_m3");
  const std::vector<double>* E[9] = {scalar("E1_Pa"),  scalar("E2_Pa"),  scalar("E3_Pa"),
                                     scalar("nu12"),   scalar("nu13"),   scalar("nu23"),
                                     scalar("G12_Pa"), scalar("G13_Pa"), scalar("G23_Pa")};
  const std::vector<double>* X[6] = {scalar("Xt_Pa"), scalar("Xc_Pa"),  scalar("Yt_Pa"),
                                     scalar("Yc_Pa"), scalar("S12_Pa"), scalar("S23_Pa")};
  fem::ElementSet& hexes = mesh.elements(fem::ElementKind::Hex8);
  for (const auto& name : rm.part_names) mesh.add_part(name);
  for (std::size_t h = 0; h < nh; ++h) {
    std::int32_t nodes[8];
    for (std::size_t I = 0; I < 8; ++I) nodes[I] = node(rm.hex().conn[8 * h + I]);
    hexes.add(std::span<const std::int32_t>(nodes, 8), rm.hex().part[h]);
    hexes.user_id.push_back(rm.hex().user_id.empty() ? static_cast<std::int64_t>(h + 1)
                                                     : rm.hex().user_id[h]);
    hexes.ply.push_back(rm.hex_ply.empty() ? -1 : rm.hex_ply[h]);
    hexes.tow.push_back(rm.hex_tow.empty() ? -1 : rm.hex_tow[h]);
    for (int r = 0; r < 3; ++r)
      for (const auto* f : {&f1, &f2, &f3})
        hexes.material_axes.push_back(f->values[3 * h + static_cast<std::size_t>(r)]);
    // Vf classes: the class's constants are those of its first element.
    const double c = cls.values[h];
    if (!(c >= 0) || c != std::floor(c))
      m.fail("source", fmt::format("hexahedron {} has no Vf class", hexes.user_id.back()));
    const auto k = static_cast<std::size_t>(c);
    if (k >= im.classes.size()) im.classes.resize(k + 1);
    ImpregnatedClass& ic = im.classes[k];
    if (ic.n_elements++ == 0) {
      ic.name =
          k < rm.material_names.size() ? rm.material_names[k] : fmt::format("tow_class_{}", k);
      ic.density = (*rho)[h];
      auto& el = ic.elastic;
      double* dst[9] = {&el.E1,   &el.E2,  &el.E3,  &el.nu12, &el.nu13,
                        &el.nu23, &el.G12, &el.G13, &el.G23};
      for (int q = 0; q < 9; ++q) *dst[q] = (*E[q])[h];
      auto& s = ic.strength;
      double* sd[6] = {&s.Xt, &s.Xc, &s.Yt, &s.Yc, &s.S12, &s.S23};
      for (int q = 0; q < 6; ++q) *sd[q] = (*X[q])[h];
    }
    im.element_class.push_back(static_cast<std::int32_t>(k));
  }
  for (std::size_t k = 0; k < im.classes.size(); ++k)
    if (im.classes[k].n_elements == 0) im.classes[k].name.clear();  // an empty class
}

// Kept stitches: bars between tow nodes, the cured yarn's constants after the hexahedra.
void import_stitches(const TableReader& m, const fem::io::StageFrame& fr, NodeImport& node,
                     ImpregnatedImport& im) {
  const auto& rm = fr.mesh;
  const std::size_t nh = rm.n_hex();
  fem::Mesh& mesh = node.mesh;
  if (const std::size_t nb = rm.n_bar(); nb > 0) {
    auto bar_value = [&](const char* name) {
      const auto* f = fr.field(name);
      const double v = f && f->on_cells && f->values.size() == nh + nb ? f->values[nh] : 0.0;
      if (!(v > 0))
        m.fail("source", fmt::format("{}: stitch bars without a positive '{}' field",
                                     im.source.string(), name));
      return v;
    };
    const double E = bar_value("stitch_modulus_Pa"), A = bar_value("stitch_area_m2"),
                 rho = bar_value("density_kg_m3");
    im.n_stitches = nb;
    im.stitch_axial_stiffness = E * A;
    im.stitch_linear_density = rho * A;
    im.stitch_capture = bar_value("stitch_capture_m");
    const std::size_t first_stitch_node = mesh.n_nodes();
    fem::ElementSet& bars = mesh.elements(fem::ElementKind::Bar2);
    for (std::size_t b = 0; b < nb; ++b) {
      // Stitch nodes are new nodes, tied to the tows in assign_impregnated_parts.
      const std::int32_t nodes[2] = {node(rm.bars().conn[2 * b]), node(rm.bars().conn[2 * b + 1])};
      bars.add(std::span<const std::int32_t>(nodes, 2), rm.bars().part[b]);
      bars.user_id.push_back(rm.bars().user_id.empty() ? static_cast<std::int64_t>(b + 1)
                                                       : rm.bars().user_id[b]);
    }
    for (std::size_t n = first_stitch_node; n < mesh.n_nodes(); ++n)
      im.stitch_nodes.push_back(static_cast<std::int32_t>(n));
  }
}

// Tied face pairs, by the transfer's element ids (ties.csv beside its results.h5).
void import_ties(const TableReader& m, const fem::Mesh& mesh, std::size_t nh,
                 ImpregnatedImport& im) {
  const auto ties_file = im.source.parent_path() / "ties.csv";
  if (std::filesystem::exists(ties_file)) {
    // Looked up again: adding the bars' set may have moved the hexahedra's.
    const fem::ElementSet& hex_set = mesh.elements(fem::ElementKind::Hex8);
    std::map<std::int64_t, std::int32_t> index_of;
    for (std::size_t h = 0; h < nh; ++h)
      index_of[hex_set.user_id[h]] = static_cast<std::int32_t>(h);
    std::vector<TieRow> rows;
    try {
      rows = read_ties_csv(ties_file);
    } catch (const std::exception& e) {
      m.fail("source", e.what());
    }
    for (const auto& r : rows) {
      const auto a = index_of.find(r.slave_id), b = index_of.find(r.master_id);
      if (a == index_of.end() || b == index_of.end() || r.slave_face < 0 || r.slave_face > 5 ||
          r.master_face < 0 || r.master_face > 5)
        m.fail("source", fmt::format("{}: the pair {}/{} - {}/{} names an element or face the "
                                     "model does not have",
                                     ties_file.string(), r.slave_id, r.slave_face, r.master_id,
                                     r.master_face));
      auto it = std::find(im.interfaces.begin(), im.interfaces.end(), r.interface);
      if (it == im.interfaces.end()) {
        im.interfaces.push_back(r.interface);
        im.ties.emplace_back();
        it = im.interfaces.end() - 1;
      }
      im.ties[static_cast<std::size_t>(it - im.interfaces.begin())].push_back(
          {a->second, b->second, r.slave_face, r.master_face});
    }
  }
}

}  // namespace

ImpregnatedImport read_impregnated_model(CaseReadContext& ctx) {
  const TableReader m = ctx.root.required_table("model");
  ImpregnatedImport im;
  const fem::io::StageFrame fr = read_source_frame(m, im);
  const auto& rm = fr.mesh;
  fem::Mesh& mesh = ctx.model.mesh;
  NodeImport node(mesh, rm);
  import_hexahedra(m, fr, node, im);
  import_stitches(m, fr, node, im);
  mesh.fill_default_user_ids();
  for (std::size_t p = 0; p < mesh.part_names.size(); ++p) {
    const auto& name = mesh.part_names[p];
    const bool stitch = std::find(rm.bars().part.begin(), rm.bars().part.end(),
                                  static_cast<std::int32_t>(p)) != rm.bars().part.end();
    ctx.part_kind[name] = stitch ? fem::PartKind::Bar : fem::PartKind::Solid;
    ctx.generated_parts[name] =
        stitch ? "[model] (the transfer's kept stitches)" : "[model] (the transfer's plies)";
  }
  import_ties(m, mesh, rm.n_hex(), im);
  return im;
}

void assign_impregnated_parts(CaseReadContext& ctx, const ImpregnatedImport& im) {
  const TableReader m = ctx.root.required_table("model");
  const TableReader dmg = m.required_table("damage");
  TowDamageConstants base;
  read_damage_keys(dmg, base);
  const bool ratio_given = dmg.has("compressive_ratio");
  const double ratio = dmg.number("compressive_ratio", 0.6, Range::open_closed(0, 1.5));

  // One material per Vf class.
  std::vector<std::int32_t> material_of_class(im.classes.size(), -1);
  for (std::size_t k = 0; k < im.classes.size(); ++k) {
    const ImpregnatedClass& ic = im.classes[k];
    if (ic.name.empty()) continue;
    if (ctx.materials.count(ic.name))
      m.fail("source", "the transfer's material '" + ic.name + "' has the name of a [[material]]");
    TowDamageConstants c = base;
    c.density = ic.density;
    c.elastic = ic.elastic;
    c.strength = ic.strength;
    if (ratio_given) c.strength.Xc = ratio * c.strength.Xt, c.strength.Yc = ratio * c.strength.Yt;
    try {
      ctx.model.materials.push_back(std::make_unique<TowDamageMaterial>(ic.name, c));
    } catch (const std::invalid_argument& e) {
      m.fail("source", "the transfer's class " + ic.name + ": " + e.what());
    }
    material_of_class[k] = static_cast<std::int32_t>(ctx.model.materials.size()) - 1;
    ctx.materials[ic.name] = material_of_class[k];
  }
  fem::ElementSet& hexes = ctx.model.mesh.elements(fem::ElementKind::Hex8);
  hexes.material.resize(hexes.size());
  for (std::size_t h = 0; h < hexes.size(); ++h)
    hexes.material[h] = material_of_class[static_cast<std::size_t>(im.element_class[h])];
  int stitch_law = -1;
  if (im.n_stitches > 0) {
    ctx.model.bar_laws.push_back(fem::BarForceLaw::linear("cured_stitch", im.stitch_axial_stiffness,
                                                          /*tension_only=*/true,
                                                          im.stitch_linear_density));
    stitch_law = static_cast<int>(ctx.model.bar_laws.size()) - 1;
  }
  for (std::size_t p = 0; p < ctx.model.parts.size(); ++p) {
    auto& pp = ctx.model.parts[p];
    if (ctx.part_kind[ctx.model.mesh.part_names[p]] == fem::PartKind::Bar) {
      pp.bar_law = stitch_law;
      ctx.part_defined[p] = 1;
      continue;
    }
    for (std::size_t h = 0; h < hexes.size(); ++h)
      if (static_cast<std::size_t>(hexes.part[h]) == p) {
        pp.material = hexes.material[h];
        break;
      }
    pp.hourglass_stiffness = m.number("hourglass_stiffness", 1.0, Range::closed(0, 10));
    pp.hourglass_viscosity = m.number("hourglass_viscosity", 0.05, Range::closed(0, 1));
    ctx.part_defined[p] = 1;
  }

  // The cured stitch: its nodes tied to the nearest outer face of the tows.
  if (!im.stitch_nodes.empty()) {
    fem::TiedContactConfig c;
    c.name = "tie_stitch";
    c.slave_nodes = im.stitch_nodes;
    c.master.name = "tows";
    for (std::size_t p = 0; p < ctx.model.mesh.part_names.size(); ++p)
      if (ctx.part_kind[ctx.model.mesh.part_names[p]] == fem::PartKind::Solid)
        c.master.parts.push_back(static_cast<int>(p));
    c.search_distance = 1.01 * im.stitch_capture;  // the transfer's capture, with round-off
    c.source_file = ctx.file;
    c.key_path = m.path() + ".source";
    ctx.model.contacts.push_back(std::make_unique<fem::TiedContact>(std::move(c)));
  }

  // Resin bonds: a cohesive tied contact per interface that has its table.
  const auto ties = m.table("ties");
  for (std::size_t i = 0; i < im.interfaces.size(); ++i) {
    const std::string& name = im.interfaces[i];
    const auto t = ties ? ties->table(name) : std::nullopt;
    if (!t) continue;  // not bonded
    fem::TiedContactConfig c;
    c.name = "tie_" + name;
    c.face_pairs = im.ties[i];
    c.normal_strength = t->number("normal_strength", Range::positive());
    c.shear_strength = t->number("shear_strength", Range::positive());
    c.mode_i_energy = t->number("mode_i_energy", Range::positive());
    c.mode_ii_energy = t->number("mode_ii_energy", Range::positive());
    c.bk_exponent = t->number("bk_exponent", 1.45, Range::closed(1, 5));
    c.penalty_scale = t->number("penalty_scale", 0.1, Range::open_closed(0, 0.5));
    c.search_distance = t->number("search_distance", 0.0, Range::non_negative());
    c.source_file = ctx.file;
    c.key_path = t->path();
    ctx.model.contacts.push_back(std::make_unique<fem::TiedContact>(std::move(c)));
  }
  if (ties)
    for (const auto& key : ties->keys())
      if (std::find(im.interfaces.begin(), im.interfaces.end(), key) == im.interfaces.end())
        ties->fail(key, "the transfer bonded no interface '" + key + "' (ties.csv)");
}

CrackBandRaise check_crack_band(const CaseReadContext& ctx) {
  const fem::Mesh& mesh = ctx.model.mesh;
  const fem::ElementSet& hexes = mesh.elements(fem::ElementKind::Hex8);
  // Per material: the worst ratio of element length to the crack-band limit, per mode.
  struct Worst {
    double ratio = 0, length = 0;
    std::int64_t element = 0;
  };
  std::map<const TowDamageMaterial*, std::array<Worst, kModes>> worst;
  CrackBandRaise raised;
  for (std::size_t h = 0; h < hexes.size(); ++h) {
    const int mi = !hexes.material.empty() && hexes.material[h] >= 0
                       ? hexes.material[h]
                       : ctx.model.parts[static_cast<std::size_t>(hexes.part[h])].material;
    if (mi < 0) continue;
    const auto* mat = dynamic_cast<const TowDamageMaterial*>(
        ctx.model.materials[static_cast<std::size_t>(mi)].get());
    if (!mat) continue;
    std::array<double, 9> axes =
        ctx.model.parts[static_cast<std::size_t>(hexes.part[h])].material_axes;
    if (!hexes.material_axes.empty())
      std::copy_n(hexes.material_axes.begin() + static_cast<std::ptrdiff_t>(9 * h), 9,
                  axes.begin());
    double x[8][3];
    const auto nodes = hexes.nodes(h);
    for (std::size_t I = 0; I < 8; ++I)
      for (std::size_t c = 0; c < 3; ++c)
        x[I][c] = mesh.coords[3 * static_cast<std::size_t>(nodes[I]) + c];
    const auto L = fem::hex8_axis_lengths(x, axes);
    // The length across each mode's crack, as the law takes it (the larger where it chooses).
    const double across[kModes] = {L[0], L[0], std::max(L[1], L[2]), std::max(L[1], L[2]),
                                   L[1], L[1]};
    ++raised.elements_checked;
    if (mat->constants().raise_to_crack_band) {
      for (int md = 0; md < kModes; ++md) {
        const double f = mat->raised_energy_factor(static_cast<FailureMode>(md), across[md]);
        if (!(f > 1.0)) continue;
        raised.add(md, f, hexes.user_id[h]);
      }
      continue;
    }
    auto& w = worst[mat];
    for (int md = 0; md < kModes; ++md) {
      const double r = across[md] / mat->max_element_length(static_cast<FailureMode>(md));
      if (r > w[static_cast<std::size_t>(md)].ratio)
        w[static_cast<std::size_t>(md)] = {r, across[md], hexes.user_id[h]};
    }
  }
  for (const auto& [mat, w] : worst)
    for (int md = 0; md < kModes; ++md) {
      const auto k = static_cast<std::size_t>(md);
      if (!(w[k].ratio >= 1.0)) continue;
      const double G = mat->constants().fracture_energy[k];
      const std::string key = (mat->constants().fracture_energy_key.empty()
                                   ? "material." + mat->name() + ".fracture_energy"
                                   : mat->constants().fracture_energy_key) +
                              "." + kModeNames[k];
      throw InputError(
          ctx.file, key,
          fmt::format("{} J/m^2 is too small for the mesh (snap-back): element {} of material '{}' "
                      "is {:.4g} mm long across a {} crack, above the crack-band limit 2 G E / "
                      "X^2 = {:.4g} mm; give at least {:.4g} J/m^2, refine the mesh, or let the "
                      "law raise the energy of the elements too long for it (crack_band = "
                      "\"raise\" beside the fracture energies)",
                      G, w[k].element, mat->name(), 1e3 * w[k].length, kModeNames[k],
                      1e3 * mat->max_element_length(static_cast<FailureMode>(md)),
                      G * w[k].ratio * kRaisedFailureRatio));
    }
  return raised;
}

namespace {

// A crush that cannot crush, or whose filtered force would mean nothing, is bad input: a punch at
// rest, a history too coarse for its CFC class, an end time before the punch reaches the part.
void check_crush_process(const CaseReadContext& ctx, const TableReader& crush,
                         const CrushSpec& cs) {
  const auto& tool = ctx.model.tools[static_cast<std::size_t>(cs.punch)];
  const auto tool_tables = ctx.root.tables("tool");
  const double speed = fem::norm(tool.motion.velocity);
  if (!(speed > 0)) {
    const std::string msg = "the punch '" + tool.name +
                            "' does not move (velocity [0, 0, 0]): a crush needs a punch "
                            "velocity, e.g. [0, 0, -1.5] m/s";
    for (const auto& tt : tool_tables)
      if (tt.string("name", "") == tool.name) tt.fail("velocity", msg);
    crush.fail("punch", msg);
  }
  // SAE J211: sample at least 10 x the channel frequency class (CFC 600: 6 kHz) before filtering.
  const auto& time = ctx.model.time;
  const double needed = 1.0 / (10.0 * cs.cfc);
  if (time.history_interval > needed * (1 + 1e-9))
    throw InputError(
        ctx.file, "time.history_interval",
        fmt::format("{:.4g} s samples the punch force at {:.4g} Hz: its CFC {:g} "
                    "filter needs at least 10 x {:g} Hz (SAE J211), an interval of "
                    "at most {:.4g} s",
                    time.history_interval, 1.0 / time.history_interval, cs.cfc, cs.cfc, needed),
        fmt::format("{:g}", time.history_interval), fmt::format("<= {:.4g}", needed));
  // The punch must reach the part: its travel by the end time (ramp and speed curve) against the
  // gap to the nearest of its contact nodes at the start.
  const auto& mesh = ctx.model.mesh;
  double gap_min = std::numeric_limits<double>::infinity();
  const auto gap_of = [&](std::size_t i) {
    double g = 0;
    fem::V3 n;
    const auto x = mesh.node(i);
    if (tool.surface.gap_at(fem::V3{x[0], x[1], x[2]}, g, n)) gap_min = std::min(gap_min, g);
  };
  if (!tool.contact_nodes.empty())
    for (const auto i : tool.contact_nodes) gap_of(static_cast<std::size_t>(i));
  else
    for (std::size_t i = 0; i < mesh.n_nodes(); ++i) gap_of(i);
  const double travel = fem::tool_prescribed_travel(tool, time.end_time);
  if (std::isfinite(gap_min) && gap_min - tool.thickness > travel)
    throw InputError(
        ctx.file, "time.end_time",
        fmt::format("the punch '{}' travels {:.4g} mm by the end time {:.4g} s but "
                    "starts {:.4g} mm from the part: it would crush nothing; give "
                    "an end time of at least {:.4g} s",
                    tool.name, 1e3 * travel, time.end_time, 1e3 * (gap_min - tool.thickness),
                    time.end_time + (gap_min - tool.thickness - travel) / speed),
        fmt::format("{:g}", time.end_time));
}

}  // namespace

CrushSpec read_crush(const CaseReadContext& ctx) {
  CrushSpec cs;
  const auto t = ctx.root.table("crush");  // the [crush] table: not a stage kind
  if (!t) return cs;
  cs.enabled = true;
  const std::string punch = t->string("punch");
  std::string names;
  for (std::size_t i = 0; i < ctx.model.tools.size(); ++i) {
    if (ctx.model.tools[i].name == punch) cs.punch = static_cast<int>(i);
    names += (names.empty() ? "" : ", ") + ctx.model.tools[i].name;
  }
  if (cs.punch < 0) t->fail("punch", "no [[tool]] named '" + punch + "' (tools: " + names + ")");
  if (ctx.model.tools[static_cast<std::size_t>(cs.punch)].motion.kind !=
      fem::ToolMotion::Kind::Velocity)
    t->fail("punch", "the punch '" + punch + "' must move at a prescribed velocity");
  cs.cfc = t->number("cfc_class", 600.0, Range::closed(10, 10000));
  check_crush_process(ctx, *t, cs);
  return cs;
}

}  // namespace ncfsim::impact
