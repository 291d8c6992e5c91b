#include "drape/probes/fabric_fields.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "drape/fabric_measures.hpp"
#include "drape/kinematic_drape.hpp"
#include "fem/contact/bucket_grid.hpp"
#include "fem/elements/element_fields.hpp"
#include "fem/elements/hex8_block.hpp"

namespace ncfsim::drape {

using fem::V3;

FabricFields::FabricFields(std::string name, int ply_a, int ply_b, const fem::ExplicitSolver& s)
    : name_(std::move(name)), plies_(s, ply_a, ply_b) {
  auto X0 = s.x0.view();
  const double longest = plies_.longest;
  const auto& conn = plies_.conn;
  reach_ = 1.5 * longest;  // the nearest element of the other ply lies within a diagonal
  wrinkle_radius_ = 3.0 * longest;

  // The blank's outline: nodes of the plies within half an element of its rectangle's edges.
  if (conn.empty()) return;
  const auto& h0 = conn[0];
  auto X0at = [&](std::int32_t node) {
    return V3::at(X0.data() + 3 * static_cast<std::size_t>(node));
  };
  normal_ = normalized(cross(X0at(h0[1]) - X0at(h0[0]), X0at(h0[3]) - X0at(h0[0])));
  V3 e1 = normalized(cross(normal_, std::abs(normal_.x) < 0.9 ? V3{1, 0, 0} : V3{0, 1, 0}));
  if (std::abs(normal_.z) > 0.9) e1 = {1, 0, 0};  // a blank in a horizontal plane: x, y edges
  const V3 e2 = cross(normal_, e1);
  std::vector<std::int32_t> nodes;
  for (const auto& h : conn) nodes.insert(nodes.end(), h.begin(), h.end());
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  double lo[2] = {1e300, 1e300}, hi[2] = {-1e300, -1e300};
  for (auto nd : nodes) {
    const V3 p = X0at(nd);
    const double u[2] = {dot(p, e1), dot(p, e2)};
    for (int k = 0; k < 2; ++k) lo[k] = std::min(lo[k], u[k]), hi[k] = std::max(hi[k], u[k]);
  }
  centre_ = 0.5 * (lo[0] + hi[0]) * e1 + 0.5 * (lo[1] + hi[1]) * e2;
  const double tol = 0.5 * longest;
  const double mids[4][2] = {{hi[0], 0.5 * (lo[1] + hi[1])},
                             {0.5 * (lo[0] + hi[0]), hi[1]},
                             {lo[0], 0.5 * (lo[1] + hi[1])},
                             {0.5 * (lo[0] + hi[0]), lo[1]}};
  const double corners[4][2] = {{hi[0], hi[1]}, {lo[0], hi[1]}, {lo[0], lo[1]}, {hi[0], lo[1]}};
  double best_mid[4], best_corner[4];
  std::fill(best_mid, best_mid + 4, 1e300);
  std::fill(best_corner, best_corner + 4, 1e300);
  for (auto nd : nodes) {
    const V3 p = X0at(nd);
    const double u = dot(p, e1), w = dot(p, e2);
    if (std::min({u - lo[0], hi[0] - u, w - lo[1], hi[1] - w}) > tol) continue;
    outline_.push_back(nd);
    for (std::size_t k = 0; k < 4; ++k) {
      const double dm = std::hypot(u - mids[k][0], w - mids[k][1]);
      const double dc = std::hypot(u - corners[k][0], w - corners[k][1]);
      if (dm < best_mid[k]) best_mid[k] = dm, mid_edge_[k] = nd;
      if (dc < best_corner[k]) best_corner[k] = dc, corner_[k] = nd;
    }
  }
}

namespace {

// Mid-surface of a tow hexahedron (VTK order: 0-3 one face, 4-7 the other): a bilinear quad.
struct MidQuad {
  V3 c[4];
  MidQuad(const std::array<std::int32_t, 8>& h, const double* x) {
    for (std::size_t k = 0; k < 4; ++k)
      c[k] = 0.5 * (V3::at(x + 3 * static_cast<std::size_t>(h[k])) +
                    V3::at(x + 3 * static_cast<std::size_t>(h[k + 4])));
  }
  V3 at(double r, double t) const {
    return 0.25 * ((1 - r) * (1 - t) * c[0] + (1 + r) * (1 - t) * c[1] + (1 + r) * (1 + t) * c[2] +
                   (1 - r) * (1 + t) * c[3]);
  }
  V3 d_r(double t) const { return 0.25 * ((1 - t) * (c[1] - c[0]) + (1 + t) * (c[2] - c[3])); }
  V3 d_t(double r) const { return 0.25 * ((1 - r) * (c[3] - c[0]) + (1 + r) * (c[2] - c[1])); }
};

// Natural coordinates of the point of the quad nearest to p (Gauss-Newton; exact in one step on
// a parallelogram, which an affinely deformed element's mid-surface is).
std::pair<double, double> natural_coordinates(const MidQuad& q, const V3& p) {
  double r = 0, t = 0;
  for (int it = 0; it < 8; ++it) {
    const V3 res = q.at(r, t) - p, a = q.d_r(t), b = q.d_t(r);
    const double aa = dot(a, a), ab = dot(a, b), bb = dot(b, b), det = aa * bb - ab * ab;
    if (!(std::abs(det) > 0)) break;
    const double ga = dot(a, res), gb = dot(b, res);
    const double dr = (bb * ga - ab * gb) / det, dt = (aa * gb - ab * ga) / det;
    r -= dr, t -= dt;
    if (std::abs(dr) + std::abs(dt) < 1e-12) break;
  }
  return {r, t};
}

// Angle (deg) between each element's normal and the mean normal of the elements of its own ply
// with centroids within `radius` (itself included).
void wrinkle_angles(const std::vector<V3>& centroid, const std::vector<V3>& normal,
                    const std::vector<std::int32_t>& ply, double radius, std::vector<double>& out) {
  if (ply.empty()) return;
  std::vector<double> lo(3 * ply.size()), hi(3 * ply.size());
  for (std::size_t k = 0; k < ply.size(); ++k) {
    const auto c = centroid[static_cast<std::size_t>(ply[k])].arr();
    for (std::size_t d = 0; d < 3; ++d)
      lo[3 * k + d] = c[d] - radius, hi[3 * k + d] = c[d] + radius;
  }
  fem::BucketGrid grid;
  grid.build(ply.size(), lo.data(), hi.data());
  for (auto e : ply) {
    const V3 p = centroid[static_cast<std::size_t>(e)], ne = normal[static_cast<std::size_t>(e)];
    const double q[3] = {p.x, p.y, p.z};
    std::int32_t begin = 0, end = 0;
    V3 sum;
    if (grid.cell_of(q, begin, end))
      for (std::int32_t it = begin; it < end; ++it) {
        const auto j = static_cast<std::size_t>(ply[static_cast<std::size_t>(grid.items()[it])]);
        const V3 d = centroid[j] - p;
        if (dot(d, d) > radius * radius) continue;
        sum += dot(normal[j], ne) >= 0 ? normal[j] : -1.0 * normal[j];  // normals of either sense
      }
    const V3 m = normalized(sum);  // atan2: accurate near zero, where acos is not
    out[static_cast<std::size_t>(e)] = std::atan2(norm(cross(m, ne)), dot(m, ne)) * 180.0 / M_PI;
  }
}

}  // namespace

FabricFields::Values FabricFields::values(const fem::ExplicitSolver& s) const {
  auto X = s.x.view();
  auto X0 = s.x0.view();
  const auto& conn = plies_.conn;
  const std::size_t n = conn.size();
  const PlyElements::State st = plies_.current(s);
  const auto& centroid = st.centroid;
  const auto& a = st.a;
  const auto& b = st.b;
  std::vector<V3> normal(n);
  for (const auto& ply : {a, b})
    for (auto i : ply) {
      const MidQuad mid(conn[static_cast<std::size_t>(i)], X.data());
      normal[static_cast<std::size_t>(i)] = normalized(cross(mid.d_r(0), mid.d_t(0)));
    }
  std::vector<std::int32_t> nearest(n, -1);
  nearest_in_other_ply(centroid, a, b, reach_, nearest);
  nearest_in_other_ply(centroid, b, a, reach_, nearest);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  Values v{std::vector<double>(n, nan), std::vector<double>(n, nan), std::vector<double>(n, nan)};
  wrinkle_angles(centroid, normal, a, wrinkle_radius_, v.wrinkle_deg);
  wrinkle_angles(centroid, normal, b, wrinkle_radius_, v.wrinkle_deg);
  for (std::size_t i = 0; i < n; ++i) {
    const std::int32_t j = nearest[i];
    if (j < 0) continue;
    v.shear_deg[i] = shear_angle_deg(st.fibre[i], st.fibre[static_cast<std::size_t>(j)]);
    // The material point of the other ply now under this element's centre, in its reference
    // state, against the one that lay under it: their distance in the ply plane is the slip.
    const auto& hj = conn[static_cast<std::size_t>(j)];
    const MidQuad now_j(hj, X.data()), ref_j(hj, X0.data()), ref_i(conn[i], X0.data());
    const auto [r, t] = natural_coordinates(now_j, centroid[i]);
    const V3 n0 = normalized(cross(ref_j.d_r(0), ref_j.d_t(0)));
    V3 d = ref_j.at(r, t) - ref_i.at(0, 0);
    d -= dot(d, n0) * n0;
    v.slip_m[i] = norm(d);
  }
  return v;
}

void FabricFields::add_frame_fields(const fem::ExplicitSolver& s,
                                    std::vector<fem::MeasureCellField>& fields) const {
  const std::size_t n_cells = s.n_elements(fem::ElementKind::Hex8) +
                              s.n_elements(fem::ElementKind::Bar2) +
                              s.n_elements(fem::ElementKind::Quad4);
  auto field = [&](const char* name) -> std::vector<double>& {
    for (auto& f : fields)
      if (f.name == name) return f.values;
    fields.push_back(
        {name, 1, std::vector<double>(n_cells, std::numeric_limits<double>::quiet_NaN())});
    return fields.back().values;
  };
  const Values v = values(s);
  auto& shear = field("shear_angle_deg");
  const auto& cell = plies_.cell;
  for (std::size_t i = 0; i < cell.size(); ++i) shear[cell[i]] = v.shear_deg[i];
  auto& slip = field("interply_slip_m");
  for (std::size_t i = 0; i < cell.size(); ++i) slip[cell[i]] = v.slip_m[i];
  auto& wrinkle = field("wrinkle_angle_deg");
  for (std::size_t i = 0; i < cell.size(); ++i) wrinkle[cell[i]] = v.wrinkle_deg[i];
}

void FabricFields::add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const {
  const Values v = values(s);
  auto max_of = [](const std::vector<double>& x) {
    double m = std::numeric_limits<double>::quiet_NaN();
    for (double e : x)
      if (std::isfinite(e) && !(e <= m)) m = e;
    return m;
  };
  summary["fabrics"][name_]["max_shear_deg"] = fem::json_number(max_of(v.shear_deg));
  summary["fabrics"][name_]["max_interply_slip_m"] = fem::json_number(max_of(v.slip_m));
  summary["fabrics"][name_]["max_wrinkle_angle_deg"] = fem::json_number(max_of(v.wrinkle_deg));
  if (outline_.empty()) return;
  auto X = s.x.view();
  auto X0 = s.x0.view();
  auto draw_in = [&](std::int32_t nd) {
    const std::size_t o = 3 * static_cast<std::size_t>(nd);
    auto in_plane = [&](V3 p) {
      p -= centre_;
      return norm(p - dot(p, normal_) * normal_);
    };
    return in_plane(V3::at(X0.data() + o)) - in_plane(V3::at(X.data() + o));
  };
  double most = -1e300, mid = 0, corner = 0;
  for (auto nd : outline_) most = std::max(most, draw_in(nd));
  for (std::size_t k = 0; k < 4; ++k)
    mid += 0.25 * draw_in(mid_edge_[k]), corner += 0.25 * draw_in(corner_[k]);
  summary["fabrics"][name_]["draw_in_max_m"] = fem::json_number(most);
  summary["fabrics"][name_]["draw_in_mid_edge_m"] = fem::json_number(mid);
  summary["fabrics"][name_]["draw_in_corner_m"] = fem::json_number(corner);
}

}  // namespace ncfsim::drape
