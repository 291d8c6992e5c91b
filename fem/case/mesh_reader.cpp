// [mesh] blocks and lines, the renumbering, node selections.
#include <algorithm>
#include <cmath>

#include "fem/case/fem_case.hpp"
#include "fem/case/model_size.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::fem {

namespace {

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

// The part of a block or line: created on first use; a part holds hexahedra or bars, not both.
int use_part(CaseReadContext& ctx, const TableReader& t, const std::string& part, PartKind kind) {
  const auto it = ctx.part_kind.find(part);
  if (it != ctx.part_kind.end() && it->second != kind) {
    const char* held = it->second == PartKind::Solid ? "hexahedra"
                       : it->second == PartKind::Bar ? "bars"
                                                     : "shells";
    t.fail("part", "'" + part + "' already holds " + held + ": a part holds one element kind");
  }
  ctx.part_kind[part] = kind;
  Mesh& mesh = ctx.model.mesh;
  const int p = mesh.find_part(part);
  return p < 0 ? mesh.add_part(part) : p;
}

void read_block(CaseReadContext& ctx, const TableReader& b) {
  const std::string part = b.string("part");
  const auto origin = b.vec3_or("origin", {0, 0, 0});
  const auto size = b.vec3("size", Range::positive());
  const auto divv = b.numbers("divisions", Range::closed(1, 1e6), 3);
  if (divv.size() != 3) b.fail("divisions", "must hold exactly 3 integers [nx, ny, nz]");
  std::array<int, 3> div{};
  for (std::size_t k = 0; k < 3; ++k) {
    const double d = divv[k];
    if (d != std::floor(d)) b.fail("divisions", "must be integers");
    div[k] = d == 1 ? 1 : std::max(1, static_cast<int>(std::lround(d * ctx.resolution_factor)));
  }
  const Mesh& m = ctx.model.mesh;
  require_model_fits(
      b.file().string(), b.key_path("divisions"),
      static_cast<double>(m.n_nodes()) + (div[0] + 1.0) * (div[1] + 1.0) * (div[2] + 1.0),
      static_cast<double>(m.elements(ElementKind::Hex8).size()) + 1.0 * div[0] * div[1] * div[2],
      static_cast<double>(m.elements(ElementKind::Bar2).size()));
  const int p = use_part(ctx, b, part, PartKind::Solid);
  add_hex_block(ctx.model.mesh, p, origin, size, div);
}

void read_line(CaseReadContext& ctx, const TableReader& l) {
  const std::string part = l.string("part");
  const auto a = l.vec3("start"), bnd = l.vec3("end");
  const int nd = static_cast<int>(l.integer("divisions", 1, 1000000));
  const int n_div = std::max(1, static_cast<int>(std::lround(nd * ctx.resolution_factor)));
  require_model_fits(
      l.file().string(), l.key_path("divisions"),
      static_cast<double>(ctx.model.mesh.n_nodes()) + n_div + 1.0,
      static_cast<double>(ctx.model.mesh.elements(ElementKind::Hex8).size()),
      static_cast<double>(ctx.model.mesh.elements(ElementKind::Bar2).size()) + n_div);
  const int p = use_part(ctx, l, part, PartKind::Bar);
  Mesh& mesh = ctx.model.mesh;
  const auto first = static_cast<std::int32_t>(mesh.n_nodes());
  for (int i = 0; i <= n_div; ++i) {
    const double s = static_cast<double>(i) / n_div;
    for (std::size_t k = 0; k < 3; ++k) mesh.coords.push_back(a[k] + s * (bnd[k] - a[k]));
  }
  for (int i = 0; i < n_div; ++i) append_bar(mesh, first + i, first + i + 1, p);
}

// A flat rectangle of shells: corner `origin`, sides `size` along the two axes of `plane`,
// normal along the third (counter-clockwise about it).
void read_plate(CaseReadContext& ctx, const TableReader& t) {
  const std::string part = t.string("part");
  const auto origin = t.vec3_or("origin", {0, 0, 0});
  const auto size = t.numbers("size", Range::positive(), 2);
  if (size.size() != 2) t.fail("size", "must hold exactly 2 lengths [a, b] (m)");
  const auto divv = t.numbers("divisions", Range::closed(1, 1e6), 2);
  if (divv.size() != 2) t.fail("divisions", "must hold exactly 2 integers [na, nb]");
  std::array<int, 2> div{};
  for (std::size_t k = 0; k < 2; ++k) {
    if (divv[k] != std::floor(divv[k])) t.fail("divisions", "must be integers");
    div[k] = divv[k] == 1 ? 1
                          : std::max(1, static_cast<int>(std::lround(divv[k] * ctx.resolution_factor)));
  }
  const std::string plane = t.choice("plane", {"xy", "yz", "zx"}, "xy");
  const int a0 = plane == "xy" ? 0 : plane == "yz" ? 1 : 2, a1 = (a0 + 1) % 3;
  Mesh& mesh = ctx.model.mesh;
  require_model_fits(t.file().string(), t.key_path("divisions"),
                     static_cast<double>(mesh.n_nodes()) + (div[0] + 1.0) * (div[1] + 1.0),
                     static_cast<double>(mesh.elements(ElementKind::Hex8).size()),
                     static_cast<double>(mesh.elements(ElementKind::Bar2).size()));
  const int p = use_part(ctx, t, part, PartKind::Shell);
  const auto first = static_cast<std::int32_t>(mesh.n_nodes());
  for (int j = 0; j <= div[1]; ++j)
    for (int i = 0; i <= div[0]; ++i) {
      std::array<double, 3> c = origin;
      c[static_cast<std::size_t>(a0)] += size[0] * i / div[0];
      c[static_cast<std::size_t>(a1)] += size[1] * j / div[1];
      for (double v : c) mesh.coords.push_back(v);
    }
  auto id = [&](int i, int j) { return first + i + (div[0] + 1) * j; };
  ElementSet& shells = mesh.elements(ElementKind::Quad4);
  for (int j = 0; j < div[1]; ++j)
    for (int i = 0; i < div[0]; ++i)
      shells.add({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}, p);
}

// Selection criteria, each narrowing `keep`.
void keep_parts(const TableReader& sel, const Mesh& mesh, std::vector<char>& keep) {
  std::vector<std::string> names;
  try {  // a string or an array of strings
    names = {sel.string("part")};
  } catch (const InputError&) {
    names = sel.strings("part");
  }
  std::vector<char> in_part(keep.size(), 0);
  for (const auto& name : names) {
    const int p = mesh.find_part(name);
    if (p < 0) sel.fail("part", "no part named '" + name + "'");
    const auto mask = part_node_mask(mesh, p);
    for (std::size_t i = 0; i < keep.size(); ++i) in_part[i] |= mask[i];
  }
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] &= in_part[i];
}

void keep_box(const TableReader& sel, const Mesh& mesh, double tol, std::vector<char>& keep) {
  const auto lo = sel.vec3("box_min"), hi = sel.vec3("box_max");
  for (std::size_t i = 0; i < keep.size(); ++i)
    for (std::size_t c = 0; c < 3; ++c) {
      const double v = mesh.coords[3 * i + c];
      if (v < lo[c] - tol || v > hi[c] + tol) keep[i] = 0;
    }
}

void keep_plane(const TableReader& sel, const Mesh& mesh, double tol, std::vector<char>& keep) {
  const auto a = static_cast<std::size_t>(axis_index(sel, "axis", sel.string("axis")));
  const double value = sel.number("value", {});
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (std::abs(mesh.coords[3 * i + a] - value) > tol) keep[i] = 0;
}

// On the x-y outline of the bounding box of the selection so far.
void keep_outline(const TableReader& sel, const Mesh& mesh, double tol, std::vector<char>& keep) {
  if (!sel.boolean("outline", false)) sel.fail("outline", "only `outline = true` is meaningful");
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (keep[i])
      for (std::size_t c = 0; c < 2; ++c) {
        lo[c] = std::min(lo[c], mesh.coords[3 * i + c]);
        hi[c] = std::max(hi[c], mesh.coords[3 * i + c]);
      }
  for (std::size_t i = 0; i < keep.size(); ++i) {
    bool on = false;
    for (std::size_t c = 0; c < 2; ++c) {
      const double v = mesh.coords[3 * i + c];
      on = on || std::abs(v - lo[c]) <= tol || std::abs(v - hi[c]) <= tol;
    }
    if (!on) keep[i] = 0;
  }
}

void keep_named_set(const TableReader& sel, const std::string& key, const NamedNodeSets& sets,
                    std::vector<char>& keep) {
  const std::string name = sel.string(key);
  const auto it = sets.sets.find(name);
  if (it == sets.sets.end()) sel.fail(key, "no " + sets.owner + " named '" + name + "'");
  std::vector<char> in_set(keep.size(), 0);
  for (auto nd : it->second) in_set[static_cast<std::size_t>(nd)] = 1;
  for (std::size_t i = 0; i < keep.size(); ++i) keep[i] &= in_set[i];
}

}  // namespace

V3 read_unit_vector(const TableReader& t, std::string_view key, std::array<double, 3> fallback) {
  const V3 ax = V3::from(t.vec3_or(key, fallback));
  if (!(norm(ax) > 0)) t.fail(key, "must not be zero");
  return (1.0 / norm(ax)) * ax;
}

std::string read_case_name(const TableReader& case_table) {
  std::string name = case_table.string("name");
  if (name.empty() || name.find_first_of("/\\ ") != std::string::npos)
    case_table.fail(
        "name", "must be a non-empty name without spaces or slashes (it names the output folder)");
  return name;
}

StageCaseHeader read_stage_case_header(const TableReader& root, const std::string& kind) {
  const TableReader c = root.required_table("case");
  StageCaseHeader h;
  h.name = read_case_name(c);
  c.choice("kind", {kind}, "");
  h.description = c.string("description", "");
  return h;
}

std::vector<char> part_node_mask(const Mesh& mesh, int part) {
  std::vector<char> in_part(mesh.n_nodes(), 0);
  mesh.for_each_element_node(
      part, [&](std::int32_t node) { in_part[static_cast<std::size_t>(node)] = 1; });
  return in_part;
}

void append_bar(Mesh& mesh, std::int32_t n0, std::int32_t n1, int part) {
  mesh.elements(ElementKind::Bar2).add({n0, n1}, part);
}

void read_mesh_blocks(CaseReadContext& ctx, const TableReader& m) {
  ctx.resolution = m.choice("resolution", {"coarse", "default", "fine"}, "default");
  ctx.resolution_factor = resolution_factor(ctx.resolution);
  const auto blocks = m.tables("block");
  const auto lines = m.tables("line");
  const auto plates = m.tables("plate");
  for (const auto& b : blocks) read_block(ctx, b);
  for (const auto& l : lines) read_line(ctx, l);
  for (const auto& p : plates) read_plate(ctx, p);
}

std::vector<std::int32_t> finish_mesh(CaseReadContext& ctx) {
  auto new_of_old = renumber_for_locality(ctx.model.mesh);
  ctx.model.mesh.fill_default_user_ids();
  return new_of_old;
}

// Node selection: the intersection of the criteria given (part, box, plane, outline, named sets).
std::vector<std::int32_t> select_nodes(const CaseReadContext& ctx, const TableReader& owner,
                                       std::string_view key) {
  auto sel = owner.table(key);
  if (!sel)
    owner.fail(key,
               "missing (required node selection, e.g. { part = \"beam\" } or "
               "{ axis = \"x\", value = 0.0 })");
  const Mesh& mesh = ctx.model.mesh;
  std::vector<char> keep(mesh.n_nodes(), 1);
  bool any = false;
  if (sel->has("part")) any = true, keep_parts(*sel, mesh, keep);
  const double tol = sel->number("tolerance", 1e-9, Range::non_negative());
  if (sel->has("box_min") || sel->has("box_max")) any = true, keep_box(*sel, mesh, tol, keep);
  if (sel->has("axis") || sel->has("value")) any = true, keep_plane(*sel, mesh, tol, keep);
  if (sel->has("outline")) any = true, keep_outline(*sel, mesh, tol, keep);
  for (const auto& [set_key, sets] : ctx.node_sets)
    if (sel->has(set_key)) any = true, keep_named_set(*sel, set_key, sets, keep);
  if (sel->has("all")) {
    any = true;
    if (!sel->boolean("all", false)) sel->fail("all", "only `all = true` is meaningful");
  }
  if (!any)
    owner.fail(key, "selects nothing: give part, box_min/box_max, axis/value or all = true");
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < keep.size(); ++i)
    if (keep[i]) out.push_back(static_cast<std::int32_t>(i));
  if (out.empty()) owner.fail(key, "the selection holds no node (check coordinates and tolerance)");
  return out;
}

std::vector<int> part_indices(const TableReader& t, std::string_view key, const Mesh& mesh) {
  std::vector<int> out;
  for (const auto& name : t.strings(key)) {
    const int p = mesh.find_part(name);
    if (p < 0) t.fail(key, "no part named '" + name + "'");
    out.push_back(p);
  }
  if (out.empty()) t.fail(key, "needs at least one part");
  return out;
}

}  // namespace ncfsim::fem
