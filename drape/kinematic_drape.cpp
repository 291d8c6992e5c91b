#include "drape/kinematic_drape.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace ncfsim::drape {

using fem::V3;

namespace {

constexpr double kPi = 3.14159265358979323846;

/// Solves J dx = -r for the 3x3 system whose rows are u, v, w (Cramer's rule); false when
/// the rows are (nearly) dependent.
bool solve_rows(const V3& u, const V3& v, const V3& w, const std::array<double, 3>& r, V3& dx) {
  const V3 vw = cross(v, w), wu = cross(w, u), uv = cross(u, v);
  const double det = dot(u, vw);
  const double scale = norm(u) * norm(v) * norm(w);
  if (!(std::abs(det) > 1e-12 * scale)) return false;
  dx = (-1.0 / det) * (r[0] * vw + r[1] * wu + r[2] * uv);
  return true;
}

/// Newton iteration on three scalar conditions: |X - a|^2 = s^2, a second condition given by
/// `second` (value and gradient), and the surface gap = 0. Returns false when it does not
/// converge to within 1e-10 s.
template <typename Second>
bool place_on_surface(const DrapeSurface& surf, const V3& a, double s, Second second, V3& x) {
  for (int it = 0; it < 40; ++it) {
    double gap = 0;
    V3 nrm;
    if (!surf.gap_at(x, gap, nrm)) return false;
    const V3 da = x - a;
    double r2 = 0;
    V3 g2;
    second(x, r2, g2);
    const std::array<double, 3> r{(dot(da, da) - s * s) / (2 * s), r2, gap};
    V3 dx;
    if (!solve_rows((1.0 / s) * da, g2, nrm, r, dx)) return false;
    // Damp steps longer than the spacing: the parallelogram guess is always closer than that.
    const double len = norm(dx);
    if (len > 0.5 * s) dx = (0.5 * s / len) * dx;
    x += dx;
    if (len < 1e-11 * s) return true;
  }
  double gap = 0;
  V3 nrm;
  return surf.gap_at(x, gap, nrm) && std::abs(gap) < 1e-9 * s &&
         std::abs(norm(x - a) - s) < 1e-9 * s;
}

}  // namespace

bool DrapeSurface::gap_at(const V3& p, double& gap, V3& normal) const {
  bool any = false;
  for (const auto& b : bodies) {
    double g = 0;
    V3 n;
    if (!b.gap_at(p, g, n)) continue;
    if (!any || g < gap) {
      gap = g;
      normal = n;
      any = true;
    }
  }
  return any;
}

V3 DrapeSurface::project(const V3& p, V3* normal) const {
  V3 x = p;
  for (int it = 0; it < 50; ++it) {
    double gap = 0;
    V3 n;
    if (!gap_at(x, gap, n))
      throw std::runtime_error("kinematic drape: no tool surface answers at (" +
                               std::to_string(x.x) + ", " + std::to_string(x.y) + ", " +
                               std::to_string(x.z) + ") m");
    x -= gap * n;
    if (normal) *normal = n;
    if (std::abs(gap) < 1e-13) break;
  }
  return x;
}

void KinematicDrapeSpec::validate() const {
  if (!(spacing > 0) || !std::isfinite(spacing))
    throw std::invalid_argument("spacing: must be > 0 m (got " + std::to_string(spacing) + ")");
  if (half_nodes < 1 || half_nodes > 5000)
    throw std::invalid_argument("half_nodes: must be in [1, 5000] (got " +
                                std::to_string(half_nodes) + ")");
  const double c = dot(normalized(fibre1), normalized(fibre2));
  if (!(norm(fibre1) > 0) || !(norm(fibre2) > 0) || std::abs(c) > 0.999)
    throw std::invalid_argument("fibre directions: must be non-zero and not parallel");
}

std::vector<std::array<std::int32_t, 3>> KinematicNet::triangles() const {
  std::vector<std::array<std::int32_t, 3>> t;
  for (int j = -n; j < n; ++j)
    for (int i = -n; i < n; ++i) {
      if (!has(i, j) || !has(i + 1, j) || !has(i + 1, j + 1) || !has(i, j + 1)) continue;
      const auto a = static_cast<std::int32_t>(index(i, j)),
                 b = static_cast<std::int32_t>(index(i + 1, j));
      const auto c = static_cast<std::int32_t>(index(i + 1, j + 1)),
                 d = static_cast<std::int32_t>(index(i, j + 1));
      t.push_back({a, b, c});
      t.push_back({a, c, d});
    }
  return t;
}

double shear_angle_deg(const V3& a, const V3& b) {
  const double na = norm(a), nb = norm(b);
  if (!(na > 0) || !(nb > 0)) return 0.0;
  const double c = std::min(1.0, std::abs(dot(a, b)) / (na * nb));
  return 90.0 - std::acos(c) * 180.0 / kPi;
}

KinematicNet kinematic_drape(const DrapeSurface& surf, const KinematicDrapeSpec& spec) {
  spec.validate();
  KinematicNet net;
  net.n = spec.half_nodes;
  net.spacing = spec.spacing;
  const int n = net.n;
  const std::size_t total =
      static_cast<std::size_t>(net.side()) * static_cast<std::size_t>(net.side());
  net.x.assign(total, V3{});
  net.placed.assign(total, 0);
  net.shear_deg.assign(total, 0.0);
  const double s = spec.spacing;

  V3 n0;
  const V3 pole = surf.project(spec.pole, &n0);
  net.x[net.index(0, 0)] = pole;
  net.placed[net.index(0, 0)] = 1;

  // Generators: discrete geodesics. The next joint lies in the plane of the last segment and
  // the surface normal at the last joint (a geodesic's osculating plane holds the normal).
  auto generator = [&](V3 dir, auto joint) {
    const V3 t0 = normalized(dir - dot(dir, n0) * n0);
    for (int sign : {1, -1}) {
      V3 prev = pole, t = static_cast<double>(sign) * t0;
      for (int k = 1; k <= n; ++k) {
        double g = 0;
        V3 nk;
        if (!surf.gap_at(prev, g, nk)) break;
        const V3 b = normalized(cross(nk, t));
        V3 x = prev + s * normalized(t);
        auto in_plane = [&](const V3& p, double& r, V3& grad) {
          r = dot(p - prev, b);
          grad = b;
        };
        if (!place_on_surface(surf, prev, s, in_plane, x)) break;
        const std::size_t id = joint(sign * k);
        net.x[id] = x;
        net.placed[id] = 1;
        t = x - prev;
        prev = x;
      }
    }
  };
  generator(spec.fibre1, [&](int k) { return net.index(k, 0); });
  generator(spec.fibre2, [&](int k) { return net.index(0, k); });

  // Cells, quadrant by quadrant, outward from the generators: joint C at one spacing from A (one
  // step nearer the fibre-2 generator) and B (one step nearer the fibre-1 generator), on the far
  // side of the diagonal joint D.
  for (int si : {1, -1})
    for (int sj : {1, -1})
      for (int bj = 1; bj <= n; ++bj)
        for (int ai = 1; ai <= n; ++ai) {
          const int i = si * ai, j = sj * bj;
          const int ia = i - si, jb = j - sj;
          if (!net.has(ia, j) || !net.has(i, jb) || !net.has(ia, jb)) continue;
          const V3 A = net.x[net.index(ia, j)], B = net.x[net.index(i, jb)],
                   D = net.x[net.index(ia, jb)];
          V3 x = A + B - D;
          const V3 ab = B - A;
          const double lab = norm(ab);
          if (!(lab < 2 * s)) continue;  // the net is fully locked here
          auto equal_distance = [&](const V3& p, double& r, V3& grad) {
            // |p - B|^2 - |p - A|^2 = 0, scaled like the first condition
            r = (dot(p - B, p - B) - dot(p - A, p - A)) / (2 * s);
            grad = (1.0 / s) * (A - B);
          };
          if (!place_on_surface(surf, A, s, equal_distance, x)) continue;
          if (dot(x - D, A + B - 2.0 * D) <= 0) continue;  // folded back onto D's side
          net.x[net.index(i, j)] = x;
          net.placed[net.index(i, j)] = 1;
        }

  // Shear at each joint from the fibre tangents (central differences, one-sided at the border).
  auto tangent = [&](int i, int j, int di, int dj, V3& t) {
    const bool fwd = net.has(i + di, j + dj), back = net.has(i - di, j - dj);
    if (fwd && back)
      t = net.x[net.index(i + di, j + dj)] - net.x[net.index(i - di, j - dj)];
    else if (fwd)
      t = net.x[net.index(i + di, j + dj)] - net.x[net.index(i, j)];
    else if (back)
      t = net.x[net.index(i, j)] - net.x[net.index(i - di, j - dj)];
    else
      return false;
    return true;
  };
  for (int j = -n; j <= n; ++j)
    for (int i = -n; i <= n; ++i) {
      if (!net.has(i, j)) {
        ++net.n_locked;
        continue;
      }
      V3 t1, t2;
      if (tangent(i, j, 1, 0, t1) && tangent(i, j, 0, 1, t2))
        net.shear_deg[net.index(i, j)] = shear_angle_deg(t1, t2);
    }
  return net;
}

}  // namespace ncfsim::drape
