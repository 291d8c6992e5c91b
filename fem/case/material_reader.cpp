// The registry of material types, fem's own types, [[material]], [[bar_law]], [[part]].
#include <stdexcept>

#include "fem/case/fem_case.hpp"

namespace ncfsim::fem {

namespace {

std::unique_ptr<SolidMaterial> read_elastic_isotropic(const TableReader& t, const std::string& name,
                                                      double rho) {
  const double E = t.number("youngs_modulus", Range::positive());
  const double nu = t.number("poisson_ratio", {-1.0, 0.5, true, true});
  return std::make_unique<ElasticIsotropic>(name, rho, E, nu);
}

std::unique_ptr<SolidMaterial> read_elastic_orthotropic(const TableReader& t,
                                                        const std::string& name, double rho) {
  OrthotropicConstants c{};
  c.E1 = t.number("E1", Range::positive());
  c.E2 = t.number("E2", Range::positive());
  c.E3 = t.number("E3", Range::positive());
  c.nu12 = t.number("nu12", {-1.0, 1.0, true, true});
  c.nu13 = t.number("nu13", {-1.0, 1.0, true, true});
  c.nu23 = t.number("nu23", {-1.0, 1.0, true, true});
  c.G12 = t.number("G12", Range::positive());
  c.G13 = t.number("G13", Range::positive());
  c.G23 = t.number("G23", Range::positive());
  return std::make_unique<ElasticOrthotropic>(name, rho, c);
}

BarForceLaw read_bar_law(const TableReader& t, const std::string& name) {
  const std::string type = t.choice("type", {"linear", "tabulated"}, "");
  const double rho_l = t.number("linear_density", Range::positive());
  const bool tension_only = t.boolean("tension_only", false);
  try {
    if (type == "linear")
      return BarForceLaw::linear(name, t.number("axial_stiffness", Range::positive()), tension_only,
                                 rho_l);
    auto strain = t.numbers("strain", {}, 2);
    auto force = t.numbers("force", {}, 2);
    if (strain.size() != force.size()) t.fail("force", "needs as many values as `strain`");
    return BarForceLaw(name, strain, force, tension_only, rho_l);
  } catch (const std::invalid_argument& e) {
    t.fail("strain", e.what());
  }
}

std::array<double, 9> read_axes(const TableReader& t) {
  if (!t.has("material_axis_1") && !t.has("material_axis_2")) return kIdentityAxes;
  auto a = V3::from(t.vec3("material_axis_1"));
  auto b = V3::from(t.vec3_or("material_axis_2", {0, 1, 0}));
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

void read_part(CaseReadContext& ctx, const TableReader& t) {
  const Mesh& mesh = ctx.model.mesh;
  const std::string name = t.string("name");
  const int p = mesh.find_part(name);
  if (p < 0) t.fail("name", "no mesh block or line uses part '" + name + "'");
  if (const auto g = ctx.generated_parts.find(name); g != ctx.generated_parts.end())
    t.fail("name",
           "part '" + name + "' belongs to a " + g->second + ": its properties come from there");
  auto& pp = ctx.model.parts[static_cast<std::size_t>(p)];
  ctx.part_defined[static_cast<std::size_t>(p)] = 1;
  if (ctx.part_kind[name] == PartKind::Shell) {
    pp.shell_thickness = t.number("thickness", Range::positive());
    pp.shell_integration_points = static_cast<int>(t.integer("integration_points", 2, 1, 5));
    pp.hourglass_stiffness = t.number("hourglass_stiffness", 0.1, Range::closed(0, 1));
    pp.material_axes = read_axes(t);
    const bool has_mat = t.has("material"), has_law = t.has("membrane_law");
    if (has_mat == has_law)
      t.fail(has_mat ? "membrane_law" : "material",
             "a shell part takes either `material` (elastic_isotropic, plane stress) or "
             "`membrane_law` (a [[membrane_law]] name), not both and not neither");
    if (has_mat) {
      const std::string mat = t.string("material");
      if (!ctx.materials.count(mat)) t.fail("material", "no [[material]] named '" + mat + "'");
      pp.material = ctx.materials[mat];
    } else {
      const std::string law = t.string("membrane_law");
      if (!ctx.membrane_laws.count(law))
        t.fail("membrane_law", "no [[membrane_law]] named '" + law + "'");
      pp.membrane_law = ctx.membrane_laws[law];
    }
  } else if (ctx.part_kind[name] == PartKind::Solid) {
    const std::string mat = t.string("material");
    if (!ctx.materials.count(mat)) t.fail("material", "no [[material]] named '" + mat + "'");
    pp.material = ctx.materials[mat];
    pp.material_axes = read_axes(t);
    pp.hourglass_stiffness = t.number("hourglass_stiffness", 1.0, Range::closed(0, 10));
    pp.hourglass_viscosity = t.number("hourglass_viscosity", 0.05, Range::closed(0, 1));
  } else {
    const std::string law = t.string("bar_law");
    if (!ctx.bar_laws.count(law)) t.fail("bar_law", "no [[bar_law]] named '" + law + "'");
    pp.bar_law = ctx.bar_laws[law];
  }
}

}  // namespace

void CaseTypeRegistry::add_material_type(std::string type, MaterialReader reader) {
  for (const auto& [known, r] : materials_)
    if (known == type) throw std::logic_error("material type '" + type + "' registered twice");
  materials_.emplace_back(std::move(type), std::move(reader));
}

std::vector<std::string> CaseTypeRegistry::material_types() const {
  std::vector<std::string> out;
  for (const auto& [type, r] : materials_) out.push_back(type);
  return out;
}

std::unique_ptr<SolidMaterial> CaseTypeRegistry::read_material(const TableReader& t,
                                                               const std::string& name) const {
  const std::string type = t.choice("type", material_types(), "");
  const double rho = t.number("density", Range::positive());
  for (const auto& [known, reader] : materials_)
    if (known == type) try {
        return reader(t, name, rho);
      } catch (const std::invalid_argument& e) {
        t.fail("type", e.what());
      }
  t.fail("type", "no reader for type '" + type + "'");  // not reached: choice() checked it
}

void CaseTypeRegistry::add_membrane_law_type(std::string type, MembraneLawReader reader) {
  for (const auto& [known, r] : membrane_laws_)
    if (known == type) throw std::logic_error("membrane law type '" + type + "' registered twice");
  membrane_laws_.emplace_back(std::move(type), std::move(reader));
}

std::unique_ptr<MembraneLaw> CaseTypeRegistry::read_membrane_law(const TableReader& t,
                                                                 const std::string& name) const {
  std::vector<std::string> types;
  for (const auto& [type, r] : membrane_laws_) types.push_back(type);
  if (types.empty()) t.fail("type", "no membrane law types are registered");
  const std::string type = t.choice("type", types, "");
  for (const auto& [known, reader] : membrane_laws_)
    if (known == type) try {
        return reader(t, name);
      } catch (const std::invalid_argument& e) {
        t.fail("type", e.what());
      }
  t.fail("type", "no reader for type '" + type + "'");
}

void register_fem_case_types(CaseTypeRegistry& registry) {
  registry.add_material_type("elastic_isotropic", read_elastic_isotropic);
  registry.add_material_type("elastic_orthotropic", read_elastic_orthotropic);
}

void read_materials(CaseReadContext& ctx) {
  for (const auto& t : ctx.root.tables("material")) {
    const std::string name = t.string("name");
    if (ctx.materials.count(name)) t.fail("name", "duplicate material '" + name + "'");
    ctx.model.materials.push_back(ctx.types.read_material(t, name));
    ctx.materials[name] = static_cast<int>(ctx.model.materials.size()) - 1;
  }
}

void read_bar_laws(CaseReadContext& ctx) {
  for (const auto& t : ctx.root.tables("bar_law")) {
    const std::string name = t.string("name");
    if (ctx.bar_laws.count(name)) t.fail("name", "duplicate bar law '" + name + "'");
    ctx.model.bar_laws.push_back(read_bar_law(t, name));
    ctx.bar_laws[name] = static_cast<int>(ctx.model.bar_laws.size()) - 1;
  }
}

void read_membrane_laws(CaseReadContext& ctx) {
  for (const auto& t : ctx.root.tables("membrane_law")) {
    const std::string name = t.string("name");
    if (ctx.membrane_laws.count(name)) t.fail("name", "duplicate membrane law '" + name + "'");
    ctx.model.membrane_laws.push_back(ctx.types.read_membrane_law(t, name));
    ctx.membrane_laws[name] = static_cast<int>(ctx.model.membrane_laws.size()) - 1;
  }
}

void read_parts(CaseReadContext& ctx) {
  const std::size_t n_parts = ctx.model.mesh.part_names.size();
  ctx.model.parts.assign(n_parts, {});
  ctx.part_defined.assign(n_parts, 0);
  for (const auto& t : ctx.root.tables("part")) read_part(ctx, t);
}

void check_parts_defined(const CaseReadContext& ctx) {
  for (std::size_t p = 0; p < ctx.part_defined.size(); ++p)
    if (!ctx.part_defined[p])
      ctx.root.fail("part",
                    "part '" + ctx.model.mesh.part_names[p] + "' has no [[part]] entry (material)");
}

}  // namespace ncfsim::fem
