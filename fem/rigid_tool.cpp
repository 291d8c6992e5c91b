#include "fem/rigid_tool.hpp"

#include <vtkCellArray.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkSTLReader.h>
#include <vtkTriangleFilter.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fem/checkpoint.hpp"

namespace ncfsim::fem {

namespace {

// Closest point on triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
V3 closest_on_triangle(const V3& p, const V3& a, const V3& b, const V3& c) {
  const V3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = dot(ab, ap), d2 = dot(ac, ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const V3 bp = p - b;
  const double d3 = dot(ab, bp), d4 = dot(ac, bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const V3 cp = p - c;
  const double d5 = dot(ab, cp), d6 = dot(ac, cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + (vb * denom) * ab + (vc * denom) * ac;
}

}  // namespace

TriangleSurface::TriangleSurface(std::vector<std::array<V3, 3>> triangles)
    : tri_(std::move(triangles)) {
  if (tri_.empty()) throw std::invalid_argument("triangulated surface has no triangles");
  const double big = std::numeric_limits<double>::max();
  lo_ = {big, big, big};
  hi_ = {-big, -big, -big};
  double edge_sum = 0;
  normal_.reserve(tri_.size());
  for (const auto& t : tri_) {
    for (const auto& p : t) {
      lo_ = {std::min(lo_.x, p.x), std::min(lo_.y, p.y), std::min(lo_.z, p.z)};
      hi_ = {std::max(hi_.x, p.x), std::max(hi_.y, p.y), std::max(hi_.z, p.z)};
    }
    edge_sum += norm(t[1] - t[0]) + norm(t[2] - t[1]) + norm(t[0] - t[2]);
    normal_.push_back(normalized(cross(t[1] - t[0], t[2] - t[0])));
  }
  cell_ = std::max(edge_sum / (3.0 * static_cast<double>(tri_.size())), 1e-12);
  const V3 span = hi_ - lo_;
  auto cells = [&](double s) { return std::max(1, static_cast<int>(std::ceil(s / cell_))); };
  while (static_cast<double>(cells(span.x)) * cells(span.y) * cells(span.z) > 4e6) cell_ *= 2;
  dims_ = {cells(span.x), cells(span.y), cells(span.z)};
  const std::size_t n_cells = static_cast<std::size_t>(dims_[0]) * dims_[1] * dims_[2];
  std::vector<std::vector<std::int32_t>> bins(n_cells);
  auto idx = [&](double v, double l, int d) {
    return std::clamp(static_cast<int>((v - l) / cell_), 0, d - 1);
  };
  for (std::size_t t = 0; t < tri_.size(); ++t) {
    V3 a = tri_[t][0], b = a;
    for (const auto& p : tri_[t]) {
      a = {std::min(a.x, p.x), std::min(a.y, p.y), std::min(a.z, p.z)};
      b = {std::max(b.x, p.x), std::max(b.y, p.y), std::max(b.z, p.z)};
    }
    for (int k = idx(a.z, lo_.z, dims_[2]); k <= idx(b.z, lo_.z, dims_[2]); ++k)
      for (int j = idx(a.y, lo_.y, dims_[1]); j <= idx(b.y, lo_.y, dims_[1]); ++j)
        for (int i = idx(a.x, lo_.x, dims_[0]); i <= idx(b.x, lo_.x, dims_[0]); ++i)
          bins[static_cast<std::size_t>(i + dims_[0] * (j + dims_[1] * k))].push_back(
              static_cast<std::int32_t>(t));
  }
  start_.assign(n_cells + 1, 0);
  for (std::size_t c = 0; c < n_cells; ++c)
    start_[c + 1] = start_[c] + static_cast<std::int32_t>(bins[c].size());
  items_.reserve(static_cast<std::size_t>(start_.back()));
  for (auto& b : bins) items_.insert(items_.end(), b.begin(), b.end());
}

TriangleSurface TriangleSurface::read_stl(const std::string& path, double scale) {
  vtkNew<vtkSTLReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkNew<vtkTriangleFilter> tri;
  tri->SetInputConnection(reader->GetOutputPort());
  tri->Update();
  vtkPolyData* pd = tri->GetOutput();
  if (!pd || pd->GetNumberOfPolys() == 0)
    throw std::invalid_argument("could not read triangles from STL file '" + path + "'");
  std::vector<std::array<V3, 3>> tris;
  tris.reserve(static_cast<std::size_t>(pd->GetNumberOfPolys()));
  vtkCellArray* polys = pd->GetPolys();
  polys->InitTraversal();
  vtkIdType npts = 0;
  const vtkIdType* pts = nullptr;
  while (polys->GetNextCell(npts, pts)) {
    if (npts != 3) continue;
    std::array<V3, 3> t;
    for (int k = 0; k < 3; ++k) {
      double p[3];
      pd->GetPoint(pts[k], p);
      t[k] = {scale * p[0], scale * p[1], scale * p[2]};
    }
    tris.push_back(t);
  }
  return TriangleSurface(std::move(tris));
}

bool TriangleSurface::closest(const V3& p, double radius, double& gap, V3& normal) const {
  if (p.x < lo_.x - radius || p.y < lo_.y - radius || p.z < lo_.z - radius ||
      p.x > hi_.x + radius || p.y > hi_.y + radius || p.z > hi_.z + radius)
    return false;
  auto idx = [&](double v, double l, int d) {
    return std::clamp(static_cast<int>((v - l) / cell_), 0, d - 1);
  };
  double best = radius * radius;
  std::int32_t best_t = -1;
  V3 best_q;
  for (int k = idx(p.z - radius, lo_.z, dims_[2]); k <= idx(p.z + radius, lo_.z, dims_[2]); ++k)
    for (int j = idx(p.y - radius, lo_.y, dims_[1]); j <= idx(p.y + radius, lo_.y, dims_[1]); ++j)
      for (int i = idx(p.x - radius, lo_.x, dims_[0]); i <= idx(p.x + radius, lo_.x, dims_[0]);
           ++i) {
        const std::size_t c = static_cast<std::size_t>(i + dims_[0] * (j + dims_[1] * k));
        for (std::int32_t s = start_[c]; s < start_[c + 1]; ++s) {
          const auto t = static_cast<std::size_t>(items_[static_cast<std::size_t>(s)]);
          const V3 q = closest_on_triangle(p, tri_[t][0], tri_[t][1], tri_[t][2]);
          const V3 d = p - q;
          const double d2 = dot(d, d);
          if (d2 < best) best = d2, best_t = static_cast<std::int32_t>(t), best_q = q;
        }
      }
  if (best_t < 0) return false;
  const V3 n = normal_[static_cast<std::size_t>(best_t)];
  const V3 d = p - best_q;
  const double dist = std::sqrt(best);
  const double side = dot(d, n) >= 0 ? 1.0 : -1.0;
  gap = side * dist;
  normal = dist > 1e-14 * (1 + norm(p)) ? (side / dist) * d : n;
  return true;
}

bool RigidSurface::gap_at(const V3& p, double& gap, V3& normal) const {
  const V3 r = p - point;
  switch (shape) {
    case ToolShape::Plane:
      gap = dot(r, axis);
      normal = axis;
      return true;
    case ToolShape::PlaneWithHole: {
      const double h = dot(r, axis);
      const V3 radial = r - h * axis;
      if (dot(radial, radial) < radius * radius) return false;
      gap = h;
      normal = axis;
      return true;
    }
    case ToolShape::Sphere: {
      const double d = norm(r);
      if (d == 0) return false;
      gap = body_inside ? radius - d : d - radius;
      normal = (body_inside ? -1.0 / d : 1.0 / d) * r;
      return true;
    }
    case ToolShape::Cylinder: {
      const V3 radial = r - dot(r, axis) * axis;
      const double d = norm(radial);
      if (d == 0) return false;
      gap = body_inside ? radius - d : d - radius;
      normal = (body_inside ? -1.0 / d : 1.0 / d) * radial;
      return true;
    }
    case ToolShape::Torus: {
      const V3 radial = r - dot(r, axis) * axis;
      const double rho = norm(radial);
      if (rho == 0) return false;
      const V3 ring = point + (radius / rho) * radial;
      const V3 d = p - ring;
      const double dn = norm(d);
      if (dn == 0) return false;
      gap = body_inside ? minor_radius - dn : dn - minor_radius;
      normal = (body_inside ? -1.0 / dn : 1.0 / dn) * d;
      return true;
    }
    case ToolShape::Triangles:
      return triangles->closest(p, search_radius, gap, normal);
  }
  return false;
}

V3 tool_axis(const RigidTool& t) {
  if (t.motion.kind == ToolMotion::Kind::Velocity && norm(t.motion.velocity) > 0)
    return normalized(t.motion.velocity);
  if (t.motion.kind == ToolMotion::Kind::Force) return t.motion.axis;
  return t.surface.axis;
}

double tool_velocity_scale(const ToolMotion& m, double t) {
  const auto& ct = m.curve_time;
  if (ct.empty()) return 1.0;
  if (t <= ct.front()) return m.curve_scale.front();
  if (t >= ct.back()) return m.curve_scale.back();
  const auto k = static_cast<std::size_t>(std::upper_bound(ct.begin(), ct.end(), t) - ct.begin());
  const double w = (t - ct[k - 1]) / (ct[k] - ct[k - 1]);
  return (1 - w) * m.curve_scale[k - 1] + w * m.curve_scale[k];
}

V3 tool_prescribed_velocity(const RigidTool& tool, double t) {
  if (tool.motion.kind != ToolMotion::Kind::Velocity) return {};
  return (smooth_ramp(t, tool.motion.ramp_time) * tool_velocity_scale(tool.motion, t)) *
         tool.motion.velocity;
}

double tool_prescribed_travel(const RigidTool& tool, double t) {
  if (tool.motion.kind != ToolMotion::Kind::Velocity || !(t > 0)) return 0.0;
  // Between the breaks of the ramp and the curve the speed is the ramp's cubic times the curve's
  // linear piece, a quartic: three-point Gauss-Legendre (exact to degree 5) integrates it exactly.
  std::vector<double> breaks{0.0, t};
  if (tool.motion.ramp_time > 0 && tool.motion.ramp_time < t)
    breaks.push_back(tool.motion.ramp_time);
  for (const double c : tool.motion.curve_time)
    if (c > 0 && c < t) breaks.push_back(c);
  std::sort(breaks.begin(), breaks.end());
  const auto v = [&](double s) {
    return smooth_ramp(s, tool.motion.ramp_time) * tool_velocity_scale(tool.motion, s);
  };
  const double g = std::sqrt(0.6);
  double travel = 0;
  for (std::size_t b = 0; b + 1 < breaks.size(); ++b) {
    const double mid = 0.5 * (breaks[b] + breaks[b + 1]), half = 0.5 * (breaks[b + 1] - breaks[b]);
    travel += half * (5.0 * v(mid - g * half) + 8.0 * v(mid) + 5.0 * v(mid + g * half)) / 9.0;
  }
  return norm(tool.motion.velocity) * travel;
}

namespace {

// Penalty force of the tool on contact node s (index into contact_nodes) at gap < thickness:
// added to fc, its reaction to ftool; returns false (and clears the friction spring) when apart.
inline bool tool_node_force(RigidTool& tool, std::size_t s, const double* x, const double* v,
                            const double* mass, double dt, double inv_dt2, double* fc, V3& ftool) {
  const auto i = static_cast<std::size_t>(tool.contact_nodes[s]);
  const V3 p = V3::at(x + 3 * i) - tool.displacement;
  double gap = 0;
  V3 nrm;
  V3* ft = reinterpret_cast<V3*>(&tool.tangential[3 * s]);
  if (!tool.surface.gap_at(p, gap, nrm) || gap - tool.thickness >= 0) {
    *ft = {};
    return false;
  }
  const double m = mass[3 * i];
  const double k = tool.penalty_scale * m * inv_dt2;
  const double fn = -k * (gap - tool.thickness);
  tool.max_penetration = std::max(tool.max_penetration, tool.thickness - gap);
  const V3 vrel = V3::at(v + 3 * i) - tool.velocity;
  const double vn = dot(vrel, nrm);  // > 0: separating
  // c = 2 zeta sqrt(k m) = 2 zeta m sqrt(penalty_scale) / dt
  const double c = 2.0 * tool.damping * m * std::sqrt(tool.penalty_scale) / dt;
  const double f_normal = std::max(fn - c * vn, 0.0);
  tool.friction_dissipation += (fn - f_normal) * vn * dt;
  V3 F = f_normal * nrm;
  if (tool.friction > 0) {
    const V3 vt = vrel - vn * nrm;
    V3 trial = *ft - dot(*ft, nrm) * nrm;
    trial -= (k * dt) * vt;
    const double cap = tool.friction * fn, mag = norm(trial);
    if (mag > cap) {
      tool.friction_dissipation += cap * (mag - cap) / k;
      trial = (cap / mag) * trial;
    }
    *ft = trial;
    F += trial;
  } else {
    *ft = {};
  }
  fc[3 * i] += F.x;
  fc[3 * i + 1] += F.y;
  fc[3 * i + 2] += F.z;
  ftool -= F;
  return true;
}

double automatic_margin(const RigidTool& tool, const double* x) {
  V3 lo{1e300, 1e300, 1e300}, hi{-1e300, -1e300, -1e300};
  for (auto node : tool.contact_nodes) {
    const V3 p = V3::at(x + 3 * static_cast<std::size_t>(node));
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  return std::max(0.01 * norm(hi - lo), 4.0 * tool.thickness);
}

}  // namespace

double RigidSurface::reach_distance(const V3& p, double offset) const {
  double gap = 0;
  V3 nrm;
  if (gap_at(p, gap, nrm)) return gap - offset;
  switch (shape) {
    case ToolShape::PlaneWithHole: {  // in the hole: it must reach the hole's rim first
      const V3 r = p - point;
      const V3 radial = r - dot(r, axis) * axis;
      return radius - norm(radial);
    }
    case ToolShape::Triangles:  // nothing within search_radius
      return search_radius - offset;
    default:  // on a sphere's centre or a torus's axis: no bound
      return 0.0;
  }
}

void tool_contact_forces(RigidTool& tool, const double* x, const double* v, const double* mass,
                         double dt, double* fc, double node_travel) {
  const std::size_t n = tool.contact_nodes.size();
  if (tool.tangential.size() != 3 * n) tool.tangential.assign(3 * n, 0.0);
  const double inv_dt2 = 1.0 / (dt * dt);
  ToolProximity& near = tool.proximity;
  const double tool_moved = near.valid ? norm(tool.displacement - near.tool_ref) : 0.0;
  // The displacement check is needed only when the last one's largest displacement plus the
  // bound on the nodes' travel since could reach the margin (it would pass otherwise).
  const bool check =
      near.valid &&
      (node_travel < 0 || near.checked_travel < 0 ||
       near.checked_d + (node_travel - near.checked_travel) + tool_moved >= near.margin);
  if (check) {  // can a node outside the near list have closed the margin since?
    double d2 = 0;
    const double* xr = near.x_ref.data();
    for (std::size_t s = 0; s < n; ++s) {
      const double* p = x + 3 * static_cast<std::size_t>(tool.contact_nodes[s]);
      const double dx = p[0] - xr[3 * s], dy = p[1] - xr[3 * s + 1], dz = p[2] - xr[3 * s + 2];
      d2 = std::max(d2, dx * dx + dy * dy + dz * dz);
    }
    near.valid = std::sqrt(d2) + tool_moved < near.margin;
    near.checked_d = std::sqrt(d2);
    near.checked_travel = node_travel;
    ++near.n_checks;
  }
  V3 ftool{};
  std::int64_t active = 0;
  if (near.valid) {
    for (const auto s : near.near)
      active +=
          tool_node_force(tool, static_cast<std::size_t>(s), x, v, mass, dt, inv_dt2, fc, ftool);
  } else {  // rebuild: every contact node, and the near list for the cycles that follow
    if (near.margin <= 0)
      near.margin = tool.search_margin > 0 ? tool.search_margin : automatic_margin(tool, x);
    near.near.clear();
    near.x_ref.resize(3 * n);
    for (std::size_t s = 0; s < n; ++s) {
      active += tool_node_force(tool, s, x, v, mass, dt, inv_dt2, fc, ftool);
      const auto i = static_cast<std::size_t>(tool.contact_nodes[s]);
      const V3 p = V3::at(x + 3 * i);
      std::copy(x + 3 * i, x + 3 * i + 3, near.x_ref.data() + 3 * s);
      if (tool.surface.reach_distance(p - tool.displacement, tool.thickness) < near.margin)
        near.near.push_back(static_cast<std::int32_t>(s));
    }
    near.tool_ref = tool.displacement;
    near.checked_d = 0;
    near.checked_travel = node_travel;
    near.valid = true;
    ++near.n_rebuilds;
  }
  tool.force = ftool;
  tool.n_active = active;
}

void remove_tool_contact_nodes(RigidTool& tool, const std::vector<std::uint8_t>& gone) {
  const std::size_t n = tool.contact_nodes.size();
  const bool has_state = tool.tangential.size() == 3 * n;
  std::size_t k = 0;
  for (std::size_t s = 0; s < n; ++s) {
    const std::int32_t node = tool.contact_nodes[s];
    if (gone[static_cast<std::size_t>(node)]) continue;
    tool.contact_nodes[k] = node;
    if (has_state)
      for (int c = 0; c < 3; ++c) tool.tangential[3 * k + c] = tool.tangential[3 * s + c];
    ++k;
  }
  if (k == n) return;
  tool.contact_nodes.resize(k);
  if (has_state) tool.tangential.resize(3 * k);
  tool.proximity.valid = false;
}

namespace {
void save_v3(CheckpointWriter& w, const std::string& name, const V3& v) {
  const double a[3] = {v.x, v.y, v.z};
  w.write_array(name, std::span<const double>(a, 3));
}
V3 load_v3(const CheckpointReader& r, const std::string& name) {
  double a[3];
  r.read_into(name, a, 3);
  return {a[0], a[1], a[2]};
}
}  // namespace

void save_tool_state(const RigidTool& tool, CheckpointWriter& w) {
  save_v3(w, "displacement", tool.displacement);
  save_v3(w, "velocity", tool.velocity);
  save_v3(w, "force", tool.force);
  save_array(w, "contact_nodes", tool.contact_nodes);
  save_array(w, "tangential", tool.tangential);
  w.write_double("friction_dissipation", tool.friction_dissipation);
  w.write_int("n_active", tool.n_active);
  w.write_double("max_penetration", tool.max_penetration);
  const ToolProximity& p = tool.proximity;
  w.write_double("proximity_margin", p.margin);
  save_array(w, "proximity_near", p.near);
  save_array(w, "proximity_x_ref", p.x_ref);
  save_v3(w, "proximity_tool_ref", p.tool_ref);
  w.write_int("proximity_rebuilds", p.n_rebuilds);
  w.write_int("proximity_valid", p.valid ? 1 : 0);
}

void load_tool_state(RigidTool& tool, CheckpointReader& r) {
  tool.displacement = load_v3(r, "displacement");
  tool.velocity = load_v3(r, "velocity");
  tool.force = load_v3(r, "force");
  // Erosion only takes contact nodes out: the saved list is a subsequence of the rebuilt one.
  std::vector<std::int32_t> nodes;
  r.read_array("contact_nodes", nodes);
  if (nodes.size() > tool.contact_nodes.size())
    r.mismatch("contact_nodes", "has " + std::to_string(nodes.size()) +
                                    " nodes, this model's tool has " +
                                    std::to_string(tool.contact_nodes.size()));
  tool.contact_nodes = std::move(nodes);
  r.read_array("tangential", tool.tangential, 3 * tool.contact_nodes.size());
  tool.friction_dissipation = r.read_double("friction_dissipation");
  tool.n_active = r.read_int("n_active");
  tool.max_penetration = r.read_double("max_penetration");
  ToolProximity& p = tool.proximity;
  p.margin = r.read_double("proximity_margin");
  r.read_array("proximity_near", p.near);
  r.read_array("proximity_x_ref", p.x_ref);
  p.tool_ref = load_v3(r, "proximity_tool_ref");
  p.n_rebuilds = r.read_int("proximity_rebuilds");
  p.valid = r.read_int("proximity_valid") != 0;
  for (auto k : p.near)
    if (k < 0 || static_cast<std::size_t>(k) >= tool.contact_nodes.size())
      r.mismatch("proximity_near", "names a contact node the tool does not have");
}

}  // namespace ncfsim::fem
