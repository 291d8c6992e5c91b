// [[tool]] (rigid tools) and [[contact]] (deformable contacts).
#include <limits>
#include <map>
#include <sstream>
#include <stdexcept>

#include "fem/case/fem_case.hpp"
#include "fem/contact/penalty_contact.hpp"
#include "fem/contact/tied_contact.hpp"

namespace ncfsim::fem {

namespace {

void read_tool_stl(const TableReader& t, RigidSurface& s) {
  s.shape = ToolShape::Triangles;
  std::filesystem::path stl = t.string("file");
  if (stl.is_relative()) stl = t.file().parent_path() / stl;
  const double scale = t.number("scale", 1.0, Range::positive());
  // Before VTK's reader, which prints a dozen error lines of its own for a missing file.
  if (!std::filesystem::is_regular_file(stl)) t.fail("file", "no such STL file: " + stl.string());
  try {
    s.triangles = std::make_shared<TriangleSurface>(TriangleSurface::read_stl(stl.string(), scale));
  } catch (const std::exception& e) {
    t.fail("file", std::string("cannot read STL: ") + e.what());
  }
  s.search_radius = t.number("search_radius", Range::positive());
}

}  // namespace

void read_rigid_surface(const TableReader& t, RigidSurface& s) {
  const std::string shape =
      t.choice("shape", {"plane", "sphere", "cylinder", "torus", "plane_with_hole", "stl"}, "");
  s.point = V3::from(t.vec3_or("point", {0, 0, 0}));
  if (t.has("axis") || shape != "stl") s.axis = read_unit_vector(t, "axis", {0, 0, 1});
  if (shape == "plane") s.shape = ToolShape::Plane;
  if (shape == "sphere" || shape == "cylinder" || shape == "torus" || shape == "plane_with_hole") {
    s.shape = shape == "sphere"     ? ToolShape::Sphere
              : shape == "cylinder" ? ToolShape::Cylinder
              : shape == "torus"    ? ToolShape::Torus
                                    : ToolShape::PlaneWithHole;
    s.radius = t.number("radius", Range::positive());
  }
  if (shape == "torus") s.minor_radius = t.number("minor_radius", Range::positive());
  if (shape == "sphere" || shape == "cylinder" || shape == "torus")
    s.body_inside = t.boolean("body_inside", false);
  if (shape == "stl") read_tool_stl(t, s);
}

namespace {

// The speed profile of a Velocity tool: times strictly increasing from 0, scales >= 0.
void read_velocity_curve(const TableReader& t, ToolMotion& m) {
  if (!t.has("velocity_curve_time") && !t.has("velocity_curve_scale")) return;
  if (!t.has("velocity_curve_time"))
    t.fail("velocity_curve_scale", "needs velocity_curve_time beside it (the times, s)");
  if (!t.has("velocity_curve_scale"))
    t.fail("velocity_curve_time", "needs velocity_curve_scale beside it (the scales of velocity)");
  m.curve_time = t.numbers("velocity_curve_time", Range::non_negative(), 2);
  m.curve_scale = t.numbers("velocity_curve_scale", Range::closed(0, 1e3), 2);
  if (m.curve_scale.size() != m.curve_time.size())
    t.fail("velocity_curve_scale", "has " + std::to_string(m.curve_scale.size()) + " values for " +
                                       std::to_string(m.curve_time.size()) +
                                       " times in velocity_curve_time");
  for (std::size_t k = 1; k < m.curve_time.size(); ++k)
    if (!(m.curve_time[k] > m.curve_time[k - 1]))
      t.fail("velocity_curve_time", "must increase strictly (value " + std::to_string(k + 1) +
                                        " is not after value " + std::to_string(k) + ")");
}

void read_tool_motion(const TableReader& t, ToolMotion& m) {
  const std::string motion = t.choice("motion", {"fixed", "velocity", "force"}, "fixed");
  if (motion == "velocity") {
    m.kind = ToolMotion::Kind::Velocity;
    m.velocity = V3::from(t.vec3("velocity"));
    m.ramp_time = t.number("ramp_time", 0.0, Range::non_negative());
    read_velocity_curve(t, m);
  } else if (motion == "force") {
    m.kind = ToolMotion::Kind::Force;
    m.axis = read_unit_vector(t, "force_axis", {0, 0, -1});
    if (t.has("force") && t.has("pressure"))
      t.fail("pressure", "give either force or pressure, not both");
    if (!t.has("pressure")) m.force = t.number("force", Range::non_negative());
    m.mass = t.number("mass", Range::positive());
  }
}

// A blankholder given by its pressure: the force is the pressure over the blank area the tool
// covers, taken as the rectangle its contact nodes span in the tool's plane less the hole (exact
// for a rectangular blank, as the generator makes, whose corners the hole does not reach).
double covered_area(const TableReader& t, const RigidTool& tool, const Mesh& mesh) {
  const V3 n = tool.surface.axis;
  V3 e1 = cross(n, std::abs(n.x) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0});
  e1 = normalized(e1);
  const V3 e2 = cross(n, e1);
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (auto node : tool.contact_nodes) {
    const auto p = mesh.node(static_cast<std::size_t>(node));
    const V3 r = V3{p[0], p[1], p[2]} - tool.surface.point;
    const double u[2] = {dot(r, e1), dot(r, e2)};
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], u[k]), hi[k] = std::max(hi[k], u[k]);
  }
  double area = (hi[0] - lo[0]) * (hi[1] - lo[1]);
  if (tool.surface.shape == ToolShape::PlaneWithHole) {
    const double R = tool.surface.radius;
    if (lo[0] > -R || hi[0] < R || lo[1] > -R || hi[1] < R)
      t.fail("radius", "the hole (radius " + std::to_string(R) +
                           " m) is not inside the blank it presses: the blank "
                           "must be larger than the die opening");
    area -= 3.14159265358979323846 * R * R;
  }
  if (!(area > 0)) t.fail("pressure", "the tool covers no blank area");
  return area;
}

// `seat_clearance`: a plane placed along its normal this far from the nearest of its contact nodes
// (a support plate under a part whose formed shape the case cannot know: a draped dome handed on
// by a transfer). The point then fixes only the plane's in-plane position.
void seat_plane(const TableReader& t, RigidTool& tool, const Mesh& mesh) {
  if (!t.has("seat_clearance")) return;
  const double clearance = t.number("seat_clearance", Range::non_negative());
  if (tool.surface.shape != ToolShape::Plane && tool.surface.shape != ToolShape::PlaneWithHole)
    t.fail("seat_clearance",
           "only a plane or plane_with_hole tool is seated (it moves along its normal); place a "
           "curved tool by its point");
  double nearest = std::numeric_limits<double>::infinity();
  const V3& n = tool.surface.axis;
  for (auto node : tool.contact_nodes) {
    const auto p = mesh.node(static_cast<std::size_t>(node));
    nearest = std::min(nearest, dot(V3{p[0], p[1], p[2]} - tool.surface.point, n));
  }
  tool.surface.point += (nearest - tool.thickness - clearance) * n;
}

// A tool must start clear of its contact nodes: a node inside it would be thrown out by the
// penalty spring at the first cycle (k = scale m / dt^2 times the depth).
void check_starts_clear(const TableReader& t, const RigidTool& tool, const Mesh& mesh) {
  double deepest = 0;
  std::int32_t worst = -1;
  for (auto node : tool.contact_nodes) {
    const auto p = mesh.node(static_cast<std::size_t>(node));
    double gap = 0;
    V3 nrm;
    if (!tool.surface.gap_at(V3{p[0], p[1], p[2]}, gap, nrm)) continue;
    const double depth = tool.thickness - gap;
    if (depth > deepest) deepest = depth, worst = node;
  }
  // Round-off of nodes laid on the surface is allowed; a thousandth of a millimetre is not that.
  if (worst < 0 || deepest <= 1e-6) return;
  const auto p = mesh.node(static_cast<std::size_t>(worst));
  std::ostringstream os;
  os << "tool '" << tool.name << "' starts inside the body it contacts: node "
     << mesh.node_user_id[static_cast<std::size_t>(worst)] << " at (" << p[0] << ", " << p[1]
     << ", " << p[2] << ") m is " << deepest * 1e3
     << " mm inside it; place the tool (point, radius) clear of its contact nodes";
  t.fail("point", os.str());
}

// The default contact nodes of a tool: every node of a hexahedron or a shell (not the nodes only
// bars hold: a stitch yarn rides on its tows).
std::vector<std::int32_t> solid_and_shell_nodes(const Mesh& mesh) {
  std::vector<char> used(mesh.n_nodes(), 0);
  for (const auto& set : mesh.sets)
    if (set.kind == ElementKind::Hex8 || set.kind == ElementKind::Quad4)
      for (auto v : set.conn) used[static_cast<std::size_t>(v)] = 1;
  std::vector<std::int32_t> out;
  for (std::size_t i = 0; i < used.size(); ++i)
    if (used[i]) out.push_back(static_cast<std::int32_t>(i));
  return out;
}

// Shells touch a tool with their faces: the default contact offset is half the thickness of the
// thickest shell holding one of the tool's contact nodes (0 for nodes of solids only: they touch
// with their surface nodes).
double half_shell_thickness(const Model& model, const std::vector<std::int32_t>& nodes) {
  const ElementSet* shells = model.mesh.find_set(ElementKind::Quad4);
  if (!shells) return 0.0;
  std::vector<char> contact(model.mesh.n_nodes(), 0);
  for (auto v : nodes) contact[static_cast<std::size_t>(v)] = 1;
  double half = 0;
  for (std::size_t e = 0; e < shells->size(); ++e)
    for (auto v : shells->nodes(e))
      if (contact[static_cast<std::size_t>(v)]) {
        const auto p = static_cast<std::size_t>(shells->part[e]);
        half = std::max(half, 0.5 * model.parts[p].shell_thickness);
        break;
      }
  return half;
}

void read_tool(CaseReadContext& ctx, const TableReader& t) {
  RigidTool tool;
  tool.name = t.string("name");
  read_rigid_surface(t, tool.surface);
  read_tool_motion(t, tool.motion);
  tool.friction = t.number("friction", 0.0, Range::non_negative());
  tool.penalty_scale = t.number("penalty_scale", 0.1, Range::open_closed(0, 1.0));
  tool.damping = t.number("damping", 0.1, Range::closed(0, 1.0));
  tool.search_margin = t.number("search_margin", 0.0, Range::non_negative());
  tool.contact_nodes = t.has("contact_nodes") ? select_nodes(ctx, t, "contact_nodes")
                                              : solid_and_shell_nodes(ctx.model.mesh);
  if (tool.contact_nodes.empty())
    t.fail("contact_nodes", "missing, and the model has no solid or shell element to touch");
  tool.thickness = t.number("thickness", half_shell_thickness(ctx.model, tool.contact_nodes),
                            Range::non_negative());
  seat_plane(t, tool, ctx.model.mesh);
  check_starts_clear(t, tool, ctx.model.mesh);
  if (tool.motion.kind == ToolMotion::Kind::Force && t.has("pressure")) {
    if (tool.surface.shape != ToolShape::Plane && tool.surface.shape != ToolShape::PlaneWithHole)
      t.fail("pressure", "only a plane or plane_with_hole tool presses with a pressure");
    const double p = t.number("pressure", Range::positive());
    tool.motion.pressure = p;
    tool.motion.pressed_area = covered_area(t, tool, ctx.model.mesh);
    tool.motion.force = p * tool.motion.pressed_area;
  }
  ctx.model.tools.push_back(std::move(tool));
}

// The values of [[contact]] are range-checked once, by fem::validate (fem/contact/contact_config),
// with their case-file keys (key_path): here they are only read (a number, finite).
template <class Config>
Config contact_config(const CaseReadContext& ctx, const TableReader& t, const std::string& name) {
  Config c;
  c.name = name;
  c.source_file = ctx.file;
  c.key_path = t.path();
  return c;
}

std::unique_ptr<ContactAlgorithm> read_penalty_contact(const CaseReadContext& ctx,
                                                       const TableReader& t,
                                                       const std::string& name) {
  auto c = contact_config<PenaltyContactConfig>(ctx, t, name);
  c.penalty_scale = t.number("penalty_scale", c.penalty_scale, {});
  c.thickness = t.number("thickness", 0.0, {});
  c.search_margin = t.number("search_margin", 0.0, {});
  c.edge_tolerance = t.number("edge_tolerance", c.edge_tolerance, {});
  c.max_penetration = t.number("max_penetration", c.max_penetration, {});
  std::map<std::string, int> groups;
  for (const auto& g : t.tables("group")) {
    ContactGroup cg;
    cg.name = g.string("name");
    if (groups.count(cg.name)) g.fail("name", "duplicate contact group '" + cg.name + "'");
    cg.parts = part_indices(g, "parts", ctx.model.mesh);
    groups[cg.name] = static_cast<int>(c.groups.size());
    c.groups.push_back(std::move(cg));
  }
  for (const auto& pr : t.tables("pair")) {
    const auto names = pr.strings("groups");
    if (names.size() != 2)
      pr.fail("groups", "must name exactly 2 groups (the same twice for self-contact)");
    ContactPair cp;
    for (std::size_t k = 0; k < 2; ++k) {
      const auto it = groups.find(names[k]);
      if (it == groups.end()) pr.fail("groups", "no [[contact.group]] named '" + names[k] + "'");
      (k == 0 ? cp.first : cp.second) = it->second;
    }
    cp.friction = pr.number("friction", 0.0, {});
    c.pairs.push_back(cp);
  }
  return std::make_unique<PenaltyContact>(std::move(c));
}

std::unique_ptr<ContactAlgorithm> read_tied_contact(const CaseReadContext& ctx,
                                                    const TableReader& t, const std::string& name) {
  auto c = contact_config<TiedContactConfig>(ctx, t, name);
  c.slave = {name + "_slave", part_indices(t, "slave_parts", ctx.model.mesh)};
  c.master = {name + "_master", part_indices(t, "master_parts", ctx.model.mesh)};
  c.penalty_scale = t.number("penalty_scale", c.penalty_scale, {});
  c.search_distance = t.number("search_distance", 0.0, {});
  c.normal_strength = t.number("normal_strength", 0.0, {});
  c.shear_strength = t.number("shear_strength", 0.0, {});
  c.mode_i_energy = t.number("mode_i_energy", 0.0, {});
  c.mode_ii_energy = t.number("mode_ii_energy", 0.0, {});
  c.bk_exponent = t.number("bk_exponent", c.bk_exponent, {});
  return std::make_unique<TiedContact>(std::move(c));
}

}  // namespace

void read_tools(CaseReadContext& ctx) {
  for (const auto& t : ctx.root.tables("tool")) read_tool(ctx, t);
}

void read_contacts(CaseReadContext& ctx) {
  for (const auto& t : ctx.root.tables("contact")) {
    const std::string type = t.choice("type", {"penalty", "tied"}, "penalty");
    const std::string name = t.string("name");
    try {
      ctx.model.contacts.push_back(type == "penalty" ? read_penalty_contact(ctx, t, name)
                                                     : read_tied_contact(ctx, t, name));
    } catch (const std::invalid_argument& e) {
      t.fail("type", e.what());
    }
  }
}

}  // namespace ncfsim::fem
