#include "drape/probes/ring_shear_probe.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numeric>

#include "drape/fabric_measures.hpp"
#include "fem/elements/element_fields.hpp"
#include "fem/elements/hex8_block.hpp"
#include "fem/elements/shell4_block.hpp"
#include "fem/io/atomic_file.hpp"

namespace ncfsim::drape {

using fem::V3;

namespace {

// The ring CSV with the kinematic drape's column appended (when the spec has one).
std::string ring_csv_with_kinematic(const std::vector<RingSample>& ring, const std::string& column,
                                    const RingShearProbe& spec) {
  std::string csv = ring_csv(ring, column);
  if (!spec.kinematic.empty()) {  // the kinematic drape's shear at the same azimuths, last column
    std::string out;
    std::size_t row = 0, pos = 0;
    for (std::size_t nl; (nl = csv.find('\n', pos)) != std::string::npos; pos = nl + 1, ++row) {
      out += csv.substr(pos, nl - pos);
      if (row == 0) {
        out += ",kinematic_shear_deg\n";
      } else {
        const auto& k = spec.kinematic[row - 1];
        out += fmt::format(",{:.9g}\n", k.hit ? k.shear_deg : std::nan(""));
      }
    }
    csv = std::move(out);
  }
  return csv;
}

// The kinematic drape's quadrant maxima for the log (when the spec has one).
void add_kinematic_line(const RingShearProbe& spec, std::vector<std::string>& lines) {
  if (spec.kinematic.empty()) return;
  const auto q = quadrant_maxima(spec.kinematic);
  lines.push_back(fmt::format(
      "ring shear, kinematic drape of {}: max q1 {:.2f}, q2 {:.2f}, q3 {:.2f}, q4 {:.2f} deg",
      spec.kinematic_case, q.max_shear_deg[0], q.max_shear_deg[1], q.max_shear_deg[2],
      q.max_shear_deg[3]));
}

void add_ring_summary(const std::vector<RingSample>& ring, const std::string& prefix,
                      const RingShearProbe& spec, nlohmann::json& summary) {
  const auto q = quadrant_maxima(ring);
  for (std::size_t k = 0; k < 4; ++k)
    summary[fmt::format("{}max_shear_deg_q{}", prefix, k + 1)] =
        q.samples[k] > 0 ? fem::json_number(q.max_shear_deg[k]) : nullptr;
  if (spec.kinematic.empty()) return;
  const auto qk = quadrant_maxima(spec.kinematic);
  for (std::size_t k = 0; k < 4; ++k)
    summary[fmt::format("kinematic_max_shear_deg_q{}", k + 1)] =
        qk.samples[k] > 0 ? fem::json_number(qk.max_shear_deg[k]) : nullptr;
}

}  // namespace

RingShearMeasure::RingShearMeasure(const RingShearProbe& spec, const fem::ExplicitSolver& s)
    : spec_(spec), plies_(s, spec.part_a, spec.part_b) {
  std::vector<std::int32_t> all(plies_.conn.size());
  std::iota(all.begin(), all.end(), 0);
  faces_ = outer_face_triangles(plies_.conn, all);
  // The nearest element of the other ply lies within one element diagonal (plies stacked).
  reach_ = 1.5 * plies_.longest;
}

std::vector<std::string> RingShearMeasure::setup_lines() const {
  std::vector<std::string> lines{fmt::format(
      "ring shear: {} + {} tow elements, {} outer-face triangles, ring {:.4g} m above the plane",
      plies_.n_a, plies_.elements.size() - plies_.n_a, faces_.size(), spec_.ring.height)};
  add_kinematic_line(spec_, lines);
  return lines;
}

std::vector<RingSample> RingShearMeasure::ring(const fem::ExplicitSolver& s) const {
  auto X = s.x.view();
  const std::size_t n = plies_.elements.size();
  const PlyElements::State st = plies_.current(s);
  const auto& centroid = st.centroid;
  const auto& fibre = st.fibre;
  const auto& a = st.a;
  const auto& b = st.b;
  std::vector<double> shear(n, std::nan(""));
  interply_shear_deg(centroid, fibre, a, b, reach_, shear);
  interply_shear_deg(centroid, fibre, b, a, reach_, shear);
  // Node values over the plies' elements, then the ring on their outer faces (mesh node ids).
  std::vector<std::int32_t> all(a);
  all.insert(all.end(), b.begin(), b.end());
  const std::size_t n_nodes = s.model().mesh.n_nodes();
  const auto node_shear = element_to_node_mean(plies_.conn, all, shear, n_nodes);
  std::vector<V3> x(n_nodes);
  for (std::size_t i = 0; i < n_nodes; ++i) x[i] = V3::at(X.data() + 3 * i);
  return ring_shear(x, faces_, node_shear, spec_.ring);
}

void RingShearMeasure::add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const {
  add_ring_summary(ring(s), "", spec_, summary);
}

std::vector<std::string> RingShearMeasure::write_files(const fem::ExplicitSolver& s,
                                                       const std::filesystem::path& dir) const {
  fem::io::atomic_write_text(dir / "ring_shear.csv",
                             ring_csv_with_kinematic(ring(s), "shear_deg", spec_));
  return {"ring_shear.csv"};
}

ShellRingShearMeasure::ShellRingShearMeasure(const RingShearProbe& spec,
                                             const fem::ExplicitSolver& s)
    : spec_(spec) {
  for (const auto& b : s.blocks<fem::Shell4Block>()) {
    if (b.part != spec.shell_part) continue;
    n_shells_ += b.n;
    for (std::size_t e = 0; e < b.n; ++e) {
      const std::int32_t c[4] = {b.conn[e], b.conn[b.n + e], b.conn[2 * b.n + e],
                                 b.conn[3 * b.n + e]};
      faces_.push_back({c[0], c[1], c[2]});
      faces_.push_back({c[0], c[2], c[3]});
    }
  }
}

std::vector<std::string> ShellRingShearMeasure::setup_lines() const {
  std::vector<std::string> lines{
      fmt::format("ring shear (macro): {} shells, ring {:.4g} m above the plane", n_shells_,
                  spec_.ring.height)};
  add_kinematic_line(spec_, lines);
  return lines;
}

std::vector<RingSample> ShellRingShearMeasure::ring(const fem::ExplicitSolver& s) const {
  auto X = s.x.view();
  const std::size_t n_nodes = s.model().mesh.n_nodes();
  std::vector<double> sum(n_nodes, 0.0), count(n_nodes, 0.0);
  for (const auto& b : s.blocks<fem::Shell4Block>()) {
    if (b.part != spec_.shell_part) continue;
    std::vector<double> g(b.n);
    fem::shell4_output_fields(b, X.data(), g.data(), nullptr, nullptr, nullptr);
    // The magnitude, as the meso and the kinematic rings read it (the sign tells positive from
    // negative shear: the element field keeps it).
    for (std::size_t e = 0; e < b.n; ++e)
      if (std::isfinite(g[e]))
        for (std::size_t I = 0; I < 4; ++I) {
          const auto node = static_cast<std::size_t>(b.conn[I * b.n + e]);
          sum[node] += std::abs(g[e]), count[node] += 1;
        }
  }
  std::vector<double> node_shear(n_nodes, std::nan(""));
  for (std::size_t i = 0; i < n_nodes; ++i)
    if (count[i] > 0) node_shear[i] = sum[i] / count[i];
  std::vector<V3> x(n_nodes);
  for (std::size_t i = 0; i < n_nodes; ++i) x[i] = V3::at(X.data() + 3 * i);
  return ring_shear(x, faces_, node_shear, spec_.ring);
}

void ShellRingShearMeasure::add_summary(const fem::ExplicitSolver& s,
                                        nlohmann::json& summary) const {
  add_ring_summary(ring(s), "macro_", spec_, summary);
}

std::vector<std::string> ShellRingShearMeasure::write_files(
    const fem::ExplicitSolver& s, const std::filesystem::path& dir) const {
  fem::io::atomic_write_text(dir / "ring_shear.csv",
                             ring_csv_with_kinematic(ring(s), "macro_shear_deg", spec_));
  return {"ring_shear.csv"};
}

}  // namespace ncfsim::drape
