#include "drape/probes/ply_elements.hpp"

#include <algorithm>

#include "fem/elements/element_fields.hpp"
#include "fem/elements/hex8_block.hpp"

namespace ncfsim::drape {

using fem::V3;

PlyElements::PlyElements(const fem::ExplicitSolver& s, int ply_a, int ply_b) {
  auto X0 = s.x0.view();
  const auto& blocks = s.blocks<fem::Hex8Block>();
  for (int side = 0; side < 2; ++side) {
    const int part = side == 0 ? ply_a : ply_b;
    std::size_t offset = 0;  // hexahedra come first in the results files, block after block
    for (std::size_t k = 0; k < blocks.size(); offset += blocks[k].n, ++k) {
      const auto& b = blocks[k];
      if (b.part != part) continue;
      for (std::size_t e = 0; e < b.n; ++e) {
        elements.emplace_back(k, e);
        cell.push_back(offset + e);
        std::array<std::int32_t, 8> c{};
        V3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
        for (std::size_t I = 0; I < 8; ++I) {
          c[I] = b.conn[I * b.n + e];
          const V3 p = V3::at(X0.data() + 3 * static_cast<std::size_t>(c[I]));
          lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
          hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
        }
        longest = std::max(longest, norm(hi - lo));
        conn.push_back(c);
      }
    }
    if (side == 0) n_a = elements.size();
  }
}

PlyElements::State PlyElements::current(const fem::ExplicitSolver& s) const {
  auto X = s.x.view();
  const std::size_t n = elements.size();
  State st{std::vector<V3>(n), std::vector<V3>(n), {}, {}};
  for (std::size_t i = 0; i < n; ++i) {
    const auto& [k, e] = elements[i];
    const auto& blk = s.blocks<fem::Hex8Block>()[k];
    if (blk.n_eroded && blk.eroded[e]) continue;  // no longer part of the fabric
    for (auto node : conn[i])
      st.centroid[i] += 0.125 * V3::at(X.data() + 3 * static_cast<std::size_t>(node));
    double d[3];
    fem::hex8_fibre_direction(blk, X.data(), e, d);
    st.fibre[i] = {d[0], d[1], d[2]};
    (i < n_a ? st.a : st.b).push_back(static_cast<std::int32_t>(i));
  }
  return st;
}

}  // namespace ncfsim::drape
