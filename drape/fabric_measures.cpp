#include "drape/fabric_measures.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>

#include "drape/kinematic_drape.hpp"
#include "fem/contact/bucket_grid.hpp"
#include "fem/elements/element_kind.hpp"

namespace ncfsim::drape {

using fem::V3;

void nearest_in_other_ply(const std::vector<V3>& centroid, const std::vector<std::int32_t>& ply_a,
                          const std::vector<std::int32_t>& ply_b, double reach,
                          std::vector<std::int32_t>& nearest) {
  if (ply_b.empty()) {
    for (auto e : ply_a) nearest[static_cast<std::size_t>(e)] = -1;
    return;
  }
  // Boxes of the other ply's centroids grown by the reach: a query point finds every element of
  // ply b within `reach` of it (per axis) in its cell.
  std::vector<double> lo(3 * ply_b.size()), hi(3 * ply_b.size());
  for (std::size_t k = 0; k < ply_b.size(); ++k) {
    const auto c = centroid[static_cast<std::size_t>(ply_b[k])].arr();
    for (int d = 0; d < 3; ++d) {
      lo[3 * k + d] = c[static_cast<std::size_t>(d)] - reach;
      hi[3 * k + d] = c[static_cast<std::size_t>(d)] + reach;
    }
  }
  fem::BucketGrid grid;
  grid.build(ply_b.size(), lo.data(), hi.data());
  for (auto e : ply_a) {
    const V3 p = centroid[static_cast<std::size_t>(e)];
    const double q[3] = {p.x, p.y, p.z};
    std::int32_t begin = 0, end = 0;
    double best = reach * reach;
    std::int32_t found = -1;
    if (grid.cell_of(q, begin, end))
      for (std::int32_t it = begin; it < end; ++it) {
        const std::int32_t k = grid.items()[it];
        const V3 d = centroid[static_cast<std::size_t>(ply_b[static_cast<std::size_t>(k)])] - p;
        const double d2 = dot(d, d);
        if (d2 <= best) {
          best = d2;
          found = ply_b[static_cast<std::size_t>(k)];
        }
      }
    nearest[static_cast<std::size_t>(e)] = found;
  }
}

void interply_shear_deg(const std::vector<V3>& centroid, const std::vector<V3>& fibre,
                        const std::vector<std::int32_t>& ply_a,
                        const std::vector<std::int32_t>& ply_b, double reach,
                        std::vector<double>& shear_deg) {
  std::vector<std::int32_t> nearest(centroid.size(), -1);
  nearest_in_other_ply(centroid, ply_a, ply_b, reach, nearest);
  for (auto e : ply_a) {
    const std::int32_t j = nearest[static_cast<std::size_t>(e)];
    shear_deg[static_cast<std::size_t>(e)] =
        j < 0 ? std::numeric_limits<double>::quiet_NaN()
              : shear_angle_deg(fibre[static_cast<std::size_t>(e)], fibre[static_cast<std::size_t>(j)]);
  }
}

std::vector<std::array<std::int32_t, 3>> outer_face_triangles(
    const std::vector<std::array<std::int32_t, 8>>& conn,
    const std::vector<std::int32_t>& elements) {
  std::map<std::array<std::int32_t, 4>, std::pair<int, std::array<std::int32_t, 4>>> faces;
  for (auto e : elements) {
    const auto& h = conn[static_cast<std::size_t>(e)];
    for (const auto& face : fem::kHex8Faces) {
      const auto& f = face.corner;
      std::array<std::int32_t, 4> nodes{
          h[static_cast<std::size_t>(f[0])], h[static_cast<std::size_t>(f[1])],
          h[static_cast<std::size_t>(f[2])], h[static_cast<std::size_t>(f[3])]};
      auto key = nodes;
      std::sort(key.begin(), key.end());
      auto [it, fresh] = faces.try_emplace(key, 0, nodes);
      ++it->second.first;
    }
  }
  std::vector<std::array<std::int32_t, 3>> tri;
  for (const auto& [key, f] : faces) {
    if (f.first != 1) continue;
    const auto& n = f.second;
    tri.push_back({n[0], n[1], n[2]});
    tri.push_back({n[0], n[2], n[3]});
  }
  return tri;
}

std::vector<double> element_to_node_mean(const std::vector<std::array<std::int32_t, 8>>& conn,
                                         const std::vector<std::int32_t>& elements,
                                         const std::vector<double>& value, std::size_t n_nodes) {
  std::vector<double> sum(n_nodes, 0.0);
  std::vector<int> count(n_nodes, 0);
  for (auto e : elements) {
    const double v = value[static_cast<std::size_t>(e)];
    if (!std::isfinite(v)) continue;
    for (auto n : conn[static_cast<std::size_t>(e)]) {
      sum[static_cast<std::size_t>(n)] += v;
      ++count[static_cast<std::size_t>(n)];
    }
  }
  for (std::size_t i = 0; i < n_nodes; ++i)
    if (count[i] > 0) sum[i] /= count[i];
  return sum;
}

}  // namespace ncfsim::drape
