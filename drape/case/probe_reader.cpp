// The fabric-test probes of [output] and the bias-extension sample's coupon.
#include "drape/case/drape_case.hpp"
#include "fem/case/fem_case.hpp"

namespace ncfsim::drape {

using fem::TableReader;

std::vector<ShearProbe> read_shear_probes(const fem::CaseReadContext& ctx, const TableReader& o) {
  const fem::Mesh& mesh = ctx.model.mesh;
  std::vector<ShearProbe> out;
  for (const auto& t : o.tables("shear_probe")) {
    ShearProbe sp;
    sp.name = t.string("name");
    const auto parts = t.strings("parts");
    if (parts.size() != 2) t.fail("parts", "must name exactly 2 parts (the two plies)");
    sp.part_a = mesh.find_part(parts[0]);
    sp.part_b = mesh.find_part(parts[1]);
    if (sp.part_a < 0 || sp.part_b < 0) t.fail("parts", "no part named '" + parts[sp.part_a < 0 ? 0 : 1] + "'");
    sp.box_min = t.vec3("box_min");
    sp.box_max = t.vec3("box_max");
    out.push_back(sp);
  }
  return out;
}

std::vector<BendingLengthProbe> read_bending_probes(const fem::CaseReadContext& ctx, const TableReader& o) {
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
  if (t.choice("analytic", {"none", "bias_extension"}, "none") != "bias_extension") return std::nullopt;
  BiasExtensionCoupon c;
  c.length = t.number("coupon_length", Range::positive());
  c.width = t.number("coupon_width", Range::positive());
  if (!(c.length > c.width)) t.fail("coupon_length", "must exceed coupon_width");
  return c;
}

}  // namespace ncfsim::drape
