#include "drape/ring_measure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace ncfsim::drape {

using fem::V3;

namespace {
constexpr double kPi = 3.14159265358979323846;
}

void RingSpec::validate() const {
  if (std::abs(norm(axis) - 1.0) > 1e-9)
    throw std::invalid_argument("ring axis: must be a unit vector");
  if (norm(zero_direction - dot(zero_direction, axis) * axis) < 1e-9)
    throw std::invalid_argument("ring zero_direction: must not be parallel to the axis");
  if (!std::isfinite(height)) throw std::invalid_argument("ring height: must be finite");
  if (!(step_deg > 0 && step_deg <= 90))
    throw std::invalid_argument("ring step_deg: must be in (0, 90] (got " +
                                std::to_string(step_deg) + ")");
}

std::vector<RingSample> ring_shear(const std::vector<V3>& nodes,
                                   const std::vector<std::array<std::int32_t, 3>>& triangles,
                                   const std::vector<double>& value, const RingSpec& ring) {
  ring.validate();
  if (value.size() != nodes.size())
    throw std::invalid_argument("ring_shear: one value per node expected");
  const V3 e1 = normalized(ring.zero_direction - dot(ring.zero_direction, ring.axis) * ring.axis);
  const V3 e2 = cross(ring.axis, e1);
  const V3 origin = ring.centre + ring.height * ring.axis;
  const int n = static_cast<int>(std::lround(360.0 / ring.step_deg));
  std::vector<RingSample> out(static_cast<std::size_t>(n));
  // Only triangles that reach the ring's height can meet its rays (a formed part: a few %).
  std::vector<std::array<std::int32_t, 3>> band;
  for (const auto& t : triangles) {
    double lo = 1e300, hi = -1e300;
    for (auto v : t) {
      const double h = dot(nodes[static_cast<std::size_t>(v)] - ring.centre, ring.axis);
      lo = std::min(lo, h);
      hi = std::max(hi, h);
    }
    if (lo <= ring.height + 1e-12 && hi >= ring.height - 1e-12) band.push_back(t);
  }
  for (int k = 0; k < n; ++k) {
    RingSample& smp = out[static_cast<std::size_t>(k)];
    smp.azimuth_deg = k * ring.step_deg;
    const double phi = smp.azimuth_deg * kPi / 180.0;
    const V3 d = std::cos(phi) * e1 + std::sin(phi) * e2;
    double best = std::numeric_limits<double>::max();
    for (const auto& t : band) {
      // Moller-Trumbore ray-triangle intersection (ray origin + s d, s > 0).
      const V3 p0 = nodes[static_cast<std::size_t>(t[0])],
               p1 = nodes[static_cast<std::size_t>(t[1])],
               p2 = nodes[static_cast<std::size_t>(t[2])];
      const V3 a = p1 - p0, b = p2 - p0, h = cross(d, b);
      const double det = dot(a, h);
      if (std::abs(det) < 1e-300) continue;
      const double inv = 1.0 / det;
      const V3 q = origin - p0;
      const double u = inv * dot(q, h);
      if (u < -1e-12 || u > 1 + 1e-12) continue;
      const V3 qa = cross(q, a);
      const double v = inv * dot(d, qa);
      if (v < -1e-12 || u + v > 1 + 1e-12) continue;
      const double s = inv * dot(b, qa);
      if (s <= 0 || s >= best) continue;
      best = s;
      smp.hit = true;
      smp.point = origin + s * d;
      smp.shear_deg = (1 - u - v) * value[static_cast<std::size_t>(t[0])] +
                      u * value[static_cast<std::size_t>(t[1])] +
                      v * value[static_cast<std::size_t>(t[2])];
    }
  }
  return out;
}

std::string ring_csv(const std::vector<RingSample>& ring, const std::string& shear_column) {
  std::string s = "azimuth_deg," + shear_column + ",hit,x_m,y_m,z_m\n";
  for (const auto& r : ring)
    s += fmt::format("{:.6g},{:.9g},{},{:.9g},{:.9g},{:.9g}\n", r.azimuth_deg,
                     r.hit ? r.shear_deg : std::nan(""), r.hit ? 1 : 0, r.point.x, r.point.y,
                     r.point.z);
  return s;
}

QuadrantMaxima quadrant_maxima(const std::vector<RingSample>& ring) {
  QuadrantMaxima q;
  for (const auto& s : ring) {
    if (!s.hit) continue;
    for (int k = 0; k < 4; ++k) {
      double off = std::fmod(s.azimuth_deg - 90.0 * k, 360.0);
      if (off > 180) off -= 360;
      if (off < -180) off += 360;
      if (std::abs(off) > 45.0 + 1e-9) continue;
      q.max_shear_deg[static_cast<std::size_t>(k)] =
          std::max(q.max_shear_deg[static_cast<std::size_t>(k)], s.shear_deg);
      ++q.samples[static_cast<std::size_t>(k)];
    }
  }
  return q;
}

}  // namespace ncfsim::drape
