#include "transfer/impregnation.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>
#include <string>

#include "transfer/micromechanics.hpp"

namespace ncfsim::transfer {

using fem::V3;

void MappingSpec::validate() const {
  if (!(vf_undeformed > 0 && vf_undeformed <= kMaxFibreVolumeFraction))
    throw std::invalid_argument("vf_undeformed: must be in (0, 0.9069] (got " +
                                std::to_string(vf_undeformed) + ")");
  if (!(vf_locking >= vf_undeformed && vf_locking <= kMaxFibreVolumeFraction))
    throw std::invalid_argument("vf_locking: must be in [vf_undeformed, 0.9069] (got " +
                                std::to_string(vf_locking) + ")");
  if (!(vf_bin > 0 && vf_bin <= 0.1))
    throw std::invalid_argument("vf_bin: must be in (0, 0.1] (got " + std::to_string(vf_bin) + ")");
}

double min_scaled_corner_jacobian(const std::array<V3, 8>& x) {
  // The three edges leaving each corner, right-handed (bottom face 0-3, top 4-7 above them).
  static constexpr int kEdges[8][3] = {{1, 3, 4}, {2, 0, 5}, {3, 1, 6}, {0, 2, 7},
                                       {7, 5, 0}, {4, 6, 1}, {5, 7, 2}, {6, 4, 3}};
  double q = 1.0;
  for (std::size_t c = 0; c < 8; ++c) {
    const V3 a = x[static_cast<std::size_t>(kEdges[c][0])] - x[c],
             b = x[static_cast<std::size_t>(kEdges[c][1])] - x[c],
             d = x[static_cast<std::size_t>(kEdges[c][2])] - x[c];
    const double l = norm(a) * norm(b) * norm(d);
    q = std::min(q, l > 0 ? dot(cross(a, b), d) / l : -1.0);
  }
  return q;
}

double hex_volume(const std::array<V3, 8>& x) {
  // Natural coordinates of the VTK corners.
  static constexpr double kXi[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                                       {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};
  const double g = 1.0 / std::sqrt(3.0);
  double v = 0;
  for (int q = 0; q < 8; ++q) {
    const double p[3] = {kXi[q][0] * g, kXi[q][1] * g, kXi[q][2] * g};
    V3 J[3];
    for (int a = 0; a < 8; ++a) {
      const double s0 = 1 + kXi[a][0] * p[0], s1 = 1 + kXi[a][1] * p[1], s2 = 1 + kXi[a][2] * p[2];
      J[0] += (0.125 * kXi[a][0] * s1 * s2) * x[static_cast<std::size_t>(a)];
      J[1] += (0.125 * kXi[a][1] * s0 * s2) * x[static_cast<std::size_t>(a)];
      J[2] += (0.125 * kXi[a][2] * s0 * s1) * x[static_cast<std::size_t>(a)];
    }
    v += dot(J[0], cross(J[1], J[2]));  // Gauss weights 1
  }
  return v;
}

ImpregnatedMapping map_impregnated(const DrapedTows& t, const MappingSpec& spec) {
  spec.validate();
  const std::size_t n = t.hex.size();
  if (t.fibre.size() != n)
    throw std::invalid_argument("draped tows: one fibre direction per hexahedron expected");
  ImpregnatedMapping m;
  m.frame.resize(n);
  m.volume_ratio.resize(n);
  m.vf.resize(n);
  m.vf_class.resize(n);
  std::map<long, std::int32_t> classes;
  for (std::size_t e = 0; e < n; ++e) {
    std::array<V3, 8> X, x;
    for (int a = 0; a < 8; ++a) {
      const auto node = static_cast<std::size_t>(t.hex[e][static_cast<std::size_t>(a)]);
      X[static_cast<std::size_t>(a)] = t.reference[node];
      x[static_cast<std::size_t>(a)] = t.current[node];
    }
    const double V0 = hex_volume(X), V = hex_volume(x);
    if (!(V0 > 0) || !(V > 0))
      throw std::runtime_error("transfer: hexahedron " + std::to_string(e + 1) +
                               " has a non-positive volume (" + std::to_string(V) + " m^3)");
    V3 bottom, top;
    for (int a = 0; a < 4; ++a) {
      bottom += 0.25 * x[static_cast<std::size_t>(a)];
      top += 0.25 * x[static_cast<std::size_t>(a + 4)];
    }
    const V3 a1 = normalized(t.fibre[e]);
    const V3 through = top - bottom;
    V3 a3 = through - dot(through, a1) * a1;
    if (!(norm(a1) > 0) || !(norm(a3) > 1e-6 * norm(through)))
      throw std::runtime_error("transfer: hexahedron " + std::to_string(e + 1) +
                               " has its fibre direction along its thickness (or none)");
    a3 = normalized(a3);
    const V3 a2 = cross(a3, a1);
    m.frame[e] = {a1.x, a2.x, a3.x, a1.y, a2.y, a3.y, a1.z, a2.z, a3.z};
    const double J = V / V0;
    m.volume_ratio[e] = J;
    const double stretch = t.fibre_stretch.empty() ? 1.0 : t.fibre_stretch[e];
    double vf = compacted_fibre_volume_fraction(spec.vf_undeformed, J, stretch);
    if (vf > spec.vf_locking) {
      vf = spec.vf_locking;
      ++m.n_capped;
    } else if (vf < spec.vf_undeformed) {
      vf = spec.vf_undeformed;
      ++m.n_floored;
    }
    m.vf[e] = vf;
    const long bin = std::lround(vf / spec.vf_bin);
    auto [it, fresh] = classes.try_emplace(bin, static_cast<std::int32_t>(m.class_vf.size()));
    if (fresh)
      m.class_vf.push_back(
          std::min(static_cast<double>(bin) * spec.vf_bin, kMaxFibreVolumeFraction));
    m.vf_class[e] = it->second;
  }
  return m;
}

}  // namespace ncfsim::transfer
