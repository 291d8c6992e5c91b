// [[mesh.shell_stitch]]: the stitch of a macro fabric as bars sewn onto its shells.
#include <algorithm>
#include <array>
#include <cmath>

#include "drape/case/drape_case.hpp"
#include "drape/fabric.hpp"
#include "drape/shell_stitch_connection.hpp"
#include "fem/case/model_size.hpp"
#include "fem/errors.hpp"

namespace ncfsim::drape {

using fem::TableReader;

std::vector<ShellStitchEntry> read_shell_stitches(fem::CaseReadContext& ctx, const TableReader& m) {
  std::vector<ShellStitchEntry> out;
  for (const auto& t : m.tables("shell_stitch")) {
    ShellStitchEntry e;
    e.path = t.path();
    e.name = t.string("name");
    if (e.name.empty() || e.name.find_first_of(" ./\\") != std::string::npos)
      t.fail("name",
             "must be a non-empty name without spaces, dots or slashes (it names the "
             "stitch's bar part)");
    if (ctx.model.mesh.find_part(e.name) >= 0)
      t.fail("name", "a part named '" + e.name + "' exists already");
    const std::string shell_part = t.string("part");
    ShellStitchSpec spec;
    spec.shell_part = ctx.model.mesh.find_part(shell_part);
    if (spec.shell_part < 0 || ctx.part_kind[shell_part] != fem::PartKind::Shell)
      t.fail("part", "no shell part '" + shell_part + "' (a [[mesh.plate]] part)");
    spec.direction = t.vec3("direction");
    const FabricSpec fabric;  // its defaults: the NCF of docs/fabric-data.md
    spec.gauge = t.number("gauge", fabric.gauge(), Range::positive());
    spec.stitch_length = t.number("stitch_length", spec.gauge, Range::positive());
    spec.line_spacing = t.number("line_spacing", spec.gauge, Range::positive());
    spec.point_spacing = t.number("point_spacing", spec.stitch_length, Range::positive());
    e.law = t.string("law");
    e.slider.sliding_force = t.number("sliding_force", 0.4, Range::positive());
    e.added_mass_per_area = t.number("added_mass_per_area", 0.0, Range::non_negative());
    {  // before sewing: spacings too fine for the machine are bad input
      const fem::ElementSet& quads = ctx.model.mesh.elements(fem::ElementKind::Quad4);
      std::array<double, 3> lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
      for (std::size_t q = 0; q < quads.size(); ++q)
        if (quads.part[q] == spec.shell_part)
          for (auto nd : quads.nodes(q))
            for (int k = 0; k < 3; ++k) {
              const double c = ctx.model.mesh.coords[3 * static_cast<std::size_t>(nd) + k];
              lo[k] = std::min(lo[k], c), hi[k] = std::max(hi[k], c);
            }
      const double diag = std::hypot(hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]);
      const double n = (diag / spec.line_spacing + 1) * (diag / spec.point_spacing + 1);
      const fem::Mesh& mesh = ctx.model.mesh;
      fem::require_model_fits(
          t.file().string(), t.key_path("line_spacing") + ", " + t.key_path("point_spacing"),
          static_cast<double>(mesh.n_nodes()) + n,
          static_cast<double>(mesh.elements(fem::ElementKind::Hex8).size()),
          static_cast<double>(mesh.elements(fem::ElementKind::Bar2).size()) + n);
    }
    const int bar_part = ctx.model.mesh.add_part(e.name);
    ctx.part_kind[e.name] = fem::PartKind::Bar;
    ctx.generated_parts[e.name] = "[[mesh.shell_stitch]]";
    e.model = sew_shell_stitch(ctx.model.mesh, spec, bar_part, ctx.file, e.path);
    e.bar_part = bar_part;
    out.push_back(std::move(e));
  }
  return out;
}

void renumber_shell_stitches(fem::CaseReadContext& ctx, std::vector<ShellStitchEntry>& stitches,
                             const std::vector<std::int32_t>& new_of_old) {
  auto& ends = ctx.node_sets["shell_stitch_ends"];
  ends.owner = "[[mesh.shell_stitch]]";
  auto renumber = [&](std::int32_t& nd) {
    if (nd >= 0) nd = new_of_old[static_cast<std::size_t>(nd)];
  };
  for (auto& e : stitches)
    for (auto& l : e.model.links) {
      renumber(l.stitch_node), renumber(l.prev), renumber(l.next);
      for (auto& h : l.host) renumber(h);
    }
  for (const auto& e : stitches) {
    auto& set = ends.sets[e.name];
    for (const auto& l : e.model.links)
      if (l.prev < 0 || l.next < 0) set.push_back(l.stitch_node);
  }
}

void assign_shell_stitch_parts(fem::CaseReadContext& ctx,
                               const std::vector<ShellStitchEntry>& stitches) {
  for (const auto& e : stitches) {
    const auto it = ctx.bar_laws.find(e.law);
    if (it == ctx.bar_laws.end())
      throw InputError(ctx.file, e.path + ".law", "no such [[bar_law]] '" + e.law + "'");
    // A line stands for pillar_share pillars: force and mass scaled by that share.
    const fem::BarForceLaw& law = ctx.model.bar_laws[static_cast<std::size_t>(it->second)];
    std::vector<double> force = law.forces();
    for (double& f : force) f *= e.model.pillar_share;
    // The yarn's own mass is tiny: the sliders' stiffness (bounded by the stitch nodes' mass
    // for a stable step) would leave the stitch loose on the fabric without the added mass.
    ctx.model.bar_laws.emplace_back(
        e.name + "_" + law.name(), law.strains(), force, law.tension_only(),
        law.linear_density() * e.model.pillar_share + e.added_mass_per_area * e.model.line_spacing);
    auto& pp = ctx.model.parts[static_cast<std::size_t>(e.bar_part)];
    pp.bar_law = static_cast<int>(ctx.model.bar_laws.size()) - 1;
    ctx.part_defined[static_cast<std::size_t>(e.bar_part)] = 1;
    ctx.model.contacts.push_back(
        std::make_unique<StitchToShellConnection>(e.name + "_slider", e.model.links, e.slider));
  }
}

}  // namespace ncfsim::drape
