#include <cmath>
#include <filesystem>
// The fabric-test probes of [output] and the bias-extension sample's coupon.
#include <tuple>

#include "drape/case/drape_case.hpp"
#include "drape/case/kinematic_case.hpp"
#include "drape/kinematic_drape.hpp"
#include "fem/case/fem_case.hpp"

namespace ncfsim::drape {

using fem::TableReader;

namespace {

// `parts = [ply_a, ply_b]`: the two plies a probe compares, as part indices.
std::pair<int, int> two_plies(const TableReader& t, const fem::Mesh& mesh) {
  const auto parts = t.strings("parts");
  if (parts.size() != 2)
    t.fail("parts", "must name exactly 2 parts (the two plies), or one shell part (a macro drape)");
  const int a = mesh.find_part(parts[0]), b = mesh.find_part(parts[1]);
  if (a < 0 || b < 0) t.fail("parts", "no part named '" + parts[a < 0 ? 0 : 1] + "'");
  return {a, b};
}

}  // namespace

std::vector<ShearProbe> read_shear_probes(const fem::CaseReadContext& ctx, const TableReader& o) {
  const fem::Mesh& mesh = ctx.model.mesh;
  std::vector<ShearProbe> out;
  for (const auto& t : o.tables("shear_probe")) {
    ShearProbe sp;
    sp.name = t.string("name");
    std::tie(sp.part_a, sp.part_b) = two_plies(t, mesh);
    sp.box_min = t.vec3("box_min");
    sp.box_max = t.vec3("box_max");
    out.push_back(sp);
  }
  return out;
}

void read_ring(const TableReader& t, RingSpec& ring) {
  ring.centre = fem::V3::from(t.vec3_or("centre", {0, 0, 0}));
  ring.axis = fem::read_unit_vector(t, "axis", {0, 0, 1});
  ring.zero_direction = fem::read_unit_vector(t, "zero_direction", {1, 0, 0});
  if (norm(cross(ring.axis, ring.zero_direction)) < 1e-6)
    t.fail("zero_direction", "must not be along the ring axis");
  ring.height = t.number("height", 0.04, Range::closed(-10, 10));
  ring.step_deg = t.number("step_deg", 1.0, Range::open_closed(0, 90));
}

std::vector<RingShearProbe> read_ring_shear_probes(const fem::CaseReadContext& ctx,
                                                   const TableReader& o) {
  const fem::Mesh& mesh = ctx.model.mesh;
  std::vector<RingShearProbe> out;
  const auto tables = o.tables("ring_shear");
  if (tables.size() > 1)
    o.fail("ring_shear",
           "give at most one [[output.ring_shear]] (its keys are max_shear_deg_q1..q4)");
  for (const auto& t : tables) {
    RingShearProbe rp;
    const auto parts = t.strings("parts");
    const int p0 = parts.size() == 1 ? mesh.find_part(parts[0]) : -1;
    bool shells = false;
    if (p0 >= 0)
      for (std::size_t e = 0; e < mesh.elements(fem::ElementKind::Quad4).size(); ++e)
        if (mesh.elements(fem::ElementKind::Quad4).part[e] == p0) {
          shells = true;
          break;
        }
    if (shells)
      rp.shell_part = p0;
    else
      std::tie(rp.part_a, rp.part_b) = two_plies(t, mesh);
    read_ring(t, rp.ring);
    if (t.has("kinematic_case")) {
      std::filesystem::path kf = t.string("kinematic_case");
      if (kf.is_relative()) kf = t.file().parent_path() / kf;
      if (!std::filesystem::is_regular_file(kf))
        t.fail("kinematic_case", "no such case file: " + kf.string());
      const KinematicDrapeCase kc = load_kinematic_drape_case(kf, {});
      if (std::abs(kc.ring.height - rp.ring.height) > 1e-9)
        t.fail("kinematic_case", "its ring height (" + std::to_string(kc.ring.height) +
                                     " m) differs from this ring's (" + std::to_string(rp.ring.height) + " m)");
      const KinematicNet net = kinematic_drape(kc.surface, kc.net);
      rp.kinematic_case = kf.string();
      rp.kinematic = ring_shear(net.x, net.triangles(), net.shear_deg, rp.ring);
    }
    out.push_back(rp);
  }
  return out;
}

std::vector<BendingLengthProbe> read_bending_probes(const fem::CaseReadContext& ctx,
                                                    const TableReader& o) {
  std::vector<BendingLengthProbe> out;
  for (const auto& t : o.tables("bending_length")) {
    BendingLengthProbe bp;
    bp.name = t.string("name");
    bp.part = ctx.model.mesh.find_part(t.string("part"));
    if (bp.part < 0) t.fail("part", "no such part");
    bp.root = fem::select_nodes(ctx, t, "root");
    bp.tip = fem::select_nodes(ctx, t, "tip");
    out.push_back(std::move(bp));
  }
  return out;
}

std::optional<BiasExtensionCoupon> read_bias_extension_analytic(const TableReader& t) {
  if (t.choice("analytic", {"none", "bias_extension"}, "none") != "bias_extension")
    return std::nullopt;
  BiasExtensionCoupon c;
  c.length = t.number("coupon_length", Range::positive());
  c.width = t.number("coupon_width", Range::positive());
  if (!(c.length > c.width)) t.fail("coupon_length", "must exceed coupon_width");
  return c;
}

}  // namespace ncfsim::drape
