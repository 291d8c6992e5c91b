#include "drape/probes/ring_shear_probe.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "drape/fabric_measures.hpp"
#include "fem/elements/element_fields.hpp"
#include "fem/elements/hex8_block.hpp"
#include "fem/io/atomic_file.hpp"

namespace ncfsim::drape {

using fem::V3;

RingShearMeasure::RingShearMeasure(const RingShearProbe& spec, const fem::ExplicitSolver& s)
    : spec_(spec) {
  auto X0 = s.x0.view();
  double longest = 0;
  for (int side = 0; side < 2; ++side) {
    const int part = side == 0 ? spec.part_a : spec.part_b;
    for (std::size_t k = 0; k < s.blocks<fem::Hex8Block>().size(); ++k) {
      const auto& b = s.blocks<fem::Hex8Block>()[k];
      if (b.part != part) continue;
      for (std::size_t e = 0; e < b.n; ++e) {
        elements_.emplace_back(k, e);
        std::array<std::int32_t, 8> c{};
        V3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
        for (int I = 0; I < 8; ++I) {
          c[static_cast<std::size_t>(I)] = b.conn[static_cast<std::size_t>(I) * b.n + e];
          const V3 p =
              V3::at(X0.data() + 3 * static_cast<std::size_t>(c[static_cast<std::size_t>(I)]));
          lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
          hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
        longest = std::max(longest, norm(hi - lo));
        conn_.push_back(c);
      }
    }
    if (side == 0) n_a_ = elements_.size();
  }
  std::vector<std::int32_t> all(conn_.size());
  std::iota(all.begin(), all.end(), 0);
  faces_ = outer_face_triangles(conn_, all);
  // The nearest element of the other ply lies within one element diagonal (plies stacked).
  reach_ = 1.5 * longest;
}

std::vector<std::string> RingShearMeasure::setup_lines() const {
  std::vector<std::string> lines{fmt::format(
      "ring shear: {} + {} tow elements, {} outer-face triangles, ring {:.4g} m above the plane",
      n_a_, elements_.size() - n_a_, faces_.size(), spec_.ring.height)};
  if (!spec_.kinematic.empty()) {
    const auto q = quadrant_maxima(spec_.kinematic);
    lines.push_back(fmt::format("ring shear, kinematic drape of {}: max q1 {:.2f}, q2 {:.2f}, q3 {:.2f}, q4 {:.2f} deg",
                                spec_.kinematic_case, q.max_shear_deg[0], q.max_shear_deg[1],
                                q.max_shear_deg[2], q.max_shear_deg[3]));
  }
  return lines;
}

std::vector<RingSample> RingShearMeasure::ring(const fem::ExplicitSolver& s) const {
  auto X = s.x.view();
  const std::size_t n = elements_.size();
  std::vector<V3> centroid(n), fibre(n);
  std::vector<std::int32_t> a, b;
  for (std::size_t i = 0; i < n; ++i) {
    const auto& [k, e] = elements_[i];
    const auto& blk = s.blocks<fem::Hex8Block>()[k];
    if (blk.n_eroded && blk.eroded[e]) continue;  // no longer part of the fabric
    for (auto node : conn_[i])
      centroid[i] += 0.125 * V3::at(X.data() + 3 * static_cast<std::size_t>(node));
    double d[3];
    fem::hex8_fibre_direction(blk, X.data(), e, d);
    fibre[i] = {d[0], d[1], d[2]};
    (i < n_a_ ? a : b).push_back(static_cast<std::int32_t>(i));
  }
  std::vector<double> shear(n, std::nan(""));
  interply_shear_deg(centroid, fibre, a, b, reach_, shear);
  interply_shear_deg(centroid, fibre, b, a, reach_, shear);
  // Node values over the plies' elements, then the ring on their outer faces (mesh node ids).
  std::vector<std::int32_t> all(a);
  all.insert(all.end(), b.begin(), b.end());
  const std::size_t n_nodes = s.model().mesh.n_nodes();
  const auto node_shear = element_to_node_mean(conn_, all, shear, n_nodes);
  std::vector<V3> x(n_nodes);
  for (std::size_t i = 0; i < n_nodes; ++i) x[i] = V3::at(X.data() + 3 * i);
  return ring_shear(x, faces_, node_shear, spec_.ring);
}

void RingShearMeasure::add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const {
  const auto q = quadrant_maxima(ring(s));
  for (std::size_t k = 0; k < 4; ++k)
    summary[fmt::format("max_shear_deg_q{}", k + 1)] =
        q.samples[k] > 0 ? fem::json_number(q.max_shear_deg[k]) : nullptr;
  if (spec_.kinematic.empty()) return;
  const auto qk = quadrant_maxima(spec_.kinematic);
  for (std::size_t k = 0; k < 4; ++k)
    summary[fmt::format("kinematic_max_shear_deg_q{}", k + 1)] =
        qk.samples[k] > 0 ? fem::json_number(qk.max_shear_deg[k]) : nullptr;
}

std::vector<std::string> RingShearMeasure::write_files(const fem::ExplicitSolver& s,
                                                       const std::filesystem::path& dir) const {
  std::string csv = ring_csv(ring(s), "shear_deg");
  if (!spec_.kinematic.empty()) {  // the kinematic drape's shear at the same azimuths, last column
    std::string out;
    std::size_t row = 0, pos = 0;
    for (std::size_t nl; (nl = csv.find('\n', pos)) != std::string::npos; pos = nl + 1, ++row) {
      out += csv.substr(pos, nl - pos);
      if (row == 0) {
        out += ",kinematic_shear_deg\n";
      } else {
        const auto& k = spec_.kinematic[row - 1];
        out += fmt::format(",{:.9g}\n", k.hit ? k.shear_deg : std::nan(""));
      }
    }
    csv = std::move(out);
  }
  fem::io::atomic_write_text(dir / "ring_shear.csv", csv);
  return {"ring_shear.csv"};
}

}  // namespace ncfsim::drape
