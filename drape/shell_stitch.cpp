#include "drape/shell_stitch.hpp"

#include <algorithm>
#include <cmath>

#include "fem/errors.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::drape {

namespace {

using fem::V3;

// A quadrilateral in the plane's coordinates (along the wale, across it).
struct PlaneQuad {
  std::array<std::int32_t, 4> nodes;
  std::array<double, 4> s, c;
};

// (xi, eta) of the point (s, c) in the bilinear map of q (Newton from the centre); false when
// the point is outside (beyond a tolerance).
bool inverse_bilinear(const PlaneQuad& q, double s, double c, double& xi, double& eta,
                      std::array<double, 2>& dxi_ds) {
  static constexpr double kXi[4] = {-1, 1, 1, -1}, kEta[4] = {-1, -1, 1, 1};
  xi = 0, eta = 0;
  for (int it = 0; it < 30; ++it) {
    double rs = -s, rc = -c, a = 0, b = 0, d = 0, e = 0;  // residual and Jacobian [a b; d e]
    for (int k = 0; k < 4; ++k) {
      const double n = 0.25 * (1 + kXi[k] * xi) * (1 + kEta[k] * eta);
      const double nx = 0.25 * kXi[k] * (1 + kEta[k] * eta),
                   ne = 0.25 * kEta[k] * (1 + kXi[k] * xi);
      rs += n * q.s[k], rc += n * q.c[k];
      a += nx * q.s[k], b += ne * q.s[k], d += nx * q.c[k], e += ne * q.c[k];
    }
    const double det = a * e - b * d;
    if (!(std::abs(det) > 0)) return false;
    dxi_ds = {e / det, -d / det};  // J^-1 (1, 0): along the line
    const double dx = (e * rs - b * rc) / det, de = (-d * rs + a * rc) / det;
    xi -= dx, eta -= de;
    if (std::abs(dx) + std::abs(de) < 1e-13) break;
  }
  constexpr double kTol = 1e-6;
  if (std::abs(xi) > 1 + kTol || std::abs(eta) > 1 + kTol) return false;
  xi = std::clamp(xi, -1.0, 1.0), eta = std::clamp(eta, -1.0, 1.0);
  return true;
}

// The parameter interval along the line c = c0 inside the (convex) quadrilateral, if any.
bool clip_line(const PlaneQuad& q, double c0, double& lo, double& hi) {
  lo = 1e300, hi = -1e300;
  for (int k = 0; k < 4; ++k) {
    const int m = (k + 1) % 4;
    const double ck = q.c[k] - c0, cm = q.c[m] - c0;
    if (ck == 0 && cm == 0) {  // an edge on the line
      lo = std::min({lo, q.s[k], q.s[m]}), hi = std::max({hi, q.s[k], q.s[m]});
    } else if ((ck <= 0 && cm >= 0) || (ck >= 0 && cm <= 0)) {
      const double s = q.s[k] + (q.s[m] - q.s[k]) * ck / (ck - cm);
      lo = std::min(lo, s), hi = std::max(hi, s);
    }
  }
  return hi >= lo;
}

}  // namespace

ShellStitchModel sew_shell_stitch(fem::Mesh& mesh, const ShellStitchSpec& spec, int bar_part,
                                  const std::string& file, const std::string& key) {
  const fem::ElementSet& shells = mesh.elements(fem::ElementKind::Quad4);
  std::vector<std::size_t> quads;
  for (std::size_t e = 0; e < shells.size(); ++e)
    if (shells.part[e] == spec.shell_part) quads.push_back(e);
  if (quads.empty())
    throw InputError(file, key + ".part", "the part has no shells to sew the stitch onto");
  // The plane of the part, from its first shell; every node of the part must lie in it.
  auto X = [&](std::int32_t nd) { return V3::from(mesh.node(static_cast<std::size_t>(nd))); };
  const auto q0 = shells.nodes(quads[0]);
  V3 normal = cross(X(q0[2]) - X(q0[0]), X(q0[3]) - X(q0[1]));
  if (!(norm(normal) > 0)) throw InputError(file, key + ".part", "its first shell is degenerate");
  normal = (1 / norm(normal)) * normal;
  const V3 origin = X(q0[0]);
  V3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (auto e : quads)
    for (auto nd : shells.nodes(e)) {
      const V3 p = X(nd);
      lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
      hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
    }
  const double size = norm(hi - lo);
  for (auto e : quads)
    for (auto nd : shells.nodes(e))
      if (std::abs(dot(X(nd) - origin, normal)) > 1e-6 * size)
        throw InputError(file, key + ".part",
                         "the part must be flat at set-up (a blank): its shells leave the plane of "
                         "its first shell");
  const V3 direction = V3::from(spec.direction);
  V3 t = direction - dot(direction, normal) * normal;
  if (!(norm(t) > 1e-6 * norm(direction)))
    throw InputError(file, key + ".direction", "must not be normal to the part's plane");
  t = (1 / norm(t)) * t;
  const V3 across = cross(normal, t);

  std::vector<PlaneQuad> pq;
  double cmin = 1e300, cmax = -1e300;
  for (auto e : quads) {
    PlaneQuad q;
    for (int k = 0; k < 4; ++k) {
      q.nodes[k] = shells.nodes(e)[static_cast<std::size_t>(k)];
      const V3 d = X(q.nodes[k]) - origin;
      q.s[k] = dot(d, t), q.c[k] = dot(d, across);
      cmin = std::min(cmin, q.c[k]), cmax = std::max(cmax, q.c[k]);
    }
    pq.push_back(q);
  }
  ShellStitchModel out;
  const double width = cmax - cmin;
  out.n_lines = static_cast<std::size_t>(std::max(1.0, std::round(width / spec.line_spacing)));
  out.line_spacing = width / static_cast<double>(out.n_lines);
  out.pillar_share = out.line_spacing / spec.gauge;
  const double tol = 1e-9 * size;
  fem::ElementSet& bars = mesh.elements(fem::ElementKind::Bar2);
  for (std::size_t l = 0; l < out.n_lines; ++l) {
    const double c0 = cmin + (static_cast<double>(l) + 0.5) * out.line_spacing;
    struct Crossing {
      double a, b;
      std::size_t quad;
      bool operator<(const Crossing& o) const { return a < o.a; }
    };
    std::vector<Crossing> iv;  // the quadrilaterals the line crosses and where
    for (std::size_t qi = 0; qi < pq.size(); ++qi) {
      double a, b;
      if (clip_line(pq[qi], c0, a, b)) iv.push_back({a, b, qi});
    }
    std::sort(iv.begin(), iv.end());
    std::vector<std::pair<double, double>> runs;
    for (const auto& cr : iv)
      if (!runs.empty() && cr.a <= runs.back().second + tol)
        runs.back().second = std::max(runs.back().second, cr.b);
      else
        runs.emplace_back(cr.a, cr.b);
    for (const auto& [a, b] : runs) {
      const double len = b - a;
      if (len <= tol) continue;
      const int np = std::max(1, static_cast<int>(std::lround(len / spec.point_spacing)));
      for (int i = 0; i <= np; ++i) {
        const double s = a + len * i / np;
        ShellStitchLink link;
        bool found = false;
        // Only the quadrilaterals whose crossing holds s (sorted by their start).
        const auto last = std::upper_bound(iv.begin(), iv.end(), Crossing{s + tol, 0, 0});
        for (auto it = iv.begin(); it != last; ++it) {
          if (it->b < s - tol) continue;
          const PlaneQuad& q = pq[it->quad];
          double xi, eta;
          std::array<double, 2> dxi{};
          if (!inverse_bilinear(q, s, c0, xi, eta, dxi)) continue;
          static constexpr double kXi[4] = {-1, 1, 1, -1}, kEta[4] = {-1, -1, 1, 1};
          for (int k = 0; k < 4; ++k) {
            link.host[k] = q.nodes[k];
            link.weight[k] = 0.25 * (1 + kXi[k] * xi) * (1 + kEta[k] * eta);
            link.slide[k] = 0.25 * (kXi[k] * (1 + kEta[k] * eta) * dxi[0] +
                                    kEta[k] * (1 + kXi[k] * xi) * dxi[1]);
          }
          found = true;
          break;
        }
        if (!found)
          throw InputError(file, key,
                           "a stitch point of line " + std::to_string(l) +
                               " lies in no shell (is the part convex where it is cut?)");
        V3 p;
        for (int k = 0; k < 4; ++k) p += link.weight[k] * X(link.host[k]);
        link.penetrations =
            out.pillar_share * (i == 0 || i == np ? 0.5 : 1.0) * (len / np) / spec.stitch_length;
        out.penetrations += link.penetrations;
        link.stitch_node = static_cast<std::int32_t>(mesh.n_nodes());
        for (double v : p.arr()) mesh.coords.push_back(v);
        if (i > 0) {
          auto& prev = out.links.back();
          link.prev = prev.stitch_node;
          prev.next = link.stitch_node;
          bars.add({prev.stitch_node, link.stitch_node}, bar_part);
        }
        out.links.push_back(link);
      }
    }
  }
  if (out.links.empty()) throw InputError(file, key, "no stitch line crosses the part");
  return out;
}

}  // namespace ncfsim::drape
