#pragma once
// Helpers of the deformable-contact tests: node sets of parts, momentum, ramped gravity.
#include <algorithm>
#include <map>

#include "fem/contact/penalty_contact.hpp"
#include "fem/contact/tied_contact.hpp"
#include "tests/test_support.hpp"

namespace ncfsim::test {

/// Nodes of the hexahedra of part p, sorted.
inline std::vector<std::int32_t> part_nodes(const fem::Mesh& m, int p) {
  std::vector<std::int32_t> out;
  const fem::ElementSet& hexes = m.elements(fem::ElementKind::Hex8);
  for (std::size_t e = 0; e < hexes.size(); ++e)
    if (hexes.part[e] == p) out.insert(out.end(), hexes.nodes(e).begin(), hexes.nodes(e).end());
  std::sort(out.begin(), out.end());
  out.erase(std::unique(out.begin(), out.end()), out.end());
  return out;
}

/// Nodes of part p whose coordinate `axis` equals `value` (reference configuration).
inline std::vector<std::int32_t> part_nodes_at(const fem::Mesh& m, int p, int axis, double value,
                                               double tol = 1e-9) {
  std::vector<std::int32_t> out;
  for (auto i : part_nodes(m, p))
    if (std::abs(m.coords[3 * static_cast<std::size_t>(i) + axis] - value) <= tol) out.push_back(i);
  return out;
}

/// Total momentum sum m v over all nodes (v at the last half step).
inline fem::V3 momentum(const fem::ExplicitSolver& s) {
  auto V = s.v.view();
  auto M = s.mass.view();
  fem::V3 P;
  for (std::size_t i = 0; i < s.model().mesh.n_nodes(); ++i)
    P += fem::V3{M[3 * i] * V[3 * i], M[3 * i + 1] * V[3 * i + 1], M[3 * i + 2] * V[3 * i + 2]};
  return P;
}

/// Mass-weighted mean of position (what = 0) or velocity (what = 1) component c over nodes.
inline double mean_of(const fem::ExplicitSolver& s, const std::vector<std::int32_t>& nodes, int c,
                      int what) {
  auto X = s.x.view();
  auto V = s.v.view();
  auto M = s.mass.view();
  double sm = 0, sx = 0;
  for (auto n : nodes) {
    const auto i = 3 * static_cast<std::size_t>(n) + static_cast<std::size_t>(c);
    sm += M[i];
    sx += M[i] * (what == 0 ? X[i] : V[i]);
  }
  return sx / sm;
}

/// Gravity g applied as nodal loads m_i g ramped smoothly from 0 over `ramp` (the solver's
/// gravity has no ramp); call after the solver is built (it reads the lumped masses), before the
/// first step. Loads are grouped by nodal mass.
inline void add_ramped_gravity(fem::ExplicitSolver& s, fem::V3 g, double ramp) {
  auto M = s.mass.view();
  std::map<double, std::vector<std::int32_t>> by_mass;
  for (std::size_t i = 0; i < s.model().mesh.n_nodes(); ++i)
    by_mass[M[3 * i]].push_back(static_cast<std::int32_t>(i));
  for (auto& [m, nodes] : by_mass) {
    fem::NodalLoad ld;
    ld.name = "gravity";
    ld.nodes = std::move(nodes);
    ld.force_per_node = m * g;
    ld.ramp_time = ramp;
    s.model().loads.push_back(std::move(ld));
  }
}

/// Adds a contact to the model and returns a borrowed pointer to it.
template <class T, class Config>
T* add_contact(fem::Model& model, Config cfg) {
  auto c = std::make_unique<T>(std::move(cfg));
  T* raw = c.get();
  model.contacts.push_back(std::move(c));
  return raw;
}

}  // namespace ncfsim::test
