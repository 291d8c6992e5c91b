#include "transfer/transfer_model.hpp"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <map>
#include <stdexcept>

#include "fem/contact/bucket_grid.hpp"
#include "fem/elements/element_kind.hpp"

namespace ncfsim::transfer {

using fem::V3;

namespace {

// Natural coordinates of the VTK hexahedron corners; its faces (-z, +z, -y, +x, +y, -x) are the
// engine's.
constexpr double kXi[8][3] = {{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1},
                              {-1, -1, 1},  {1, -1, 1},  {1, 1, 1},  {-1, 1, 1}};

// d(position)/d(natural coordinate) at the element centre, columns xi, eta, zeta.
Eigen::Matrix3d centre_jacobian(const std::array<V3, 8>& x) {
  Eigen::Matrix3d J = Eigen::Matrix3d::Zero();
  for (std::size_t a = 0; a < 8; ++a)
    for (int k = 0; k < 3; ++k) {
      J(0, k) += 0.125 * kXi[a][k] * x[a].x;
      J(1, k) += 0.125 * kXi[a][k] * x[a].y;
      J(2, k) += 0.125 * kXi[a][k] * x[a].z;
    }
  return J;
}

// Fibre stretch at the element centre: the convected unit fibre a = F a0 / |F a0|, so
// lambda = |F a0| = 1 / |F^-1 a|.
double fibre_stretch(const std::array<V3, 8>& X, const std::array<V3, 8>& x, const V3& a) {
  const Eigen::Matrix3d F = centre_jacobian(x) * centre_jacobian(X).inverse();
  const Eigen::Vector3d back = F.inverse() * Eigen::Vector3d(a.x, a.y, a.z);
  return 1.0 / back.norm();
}

// Distance from p to the hexahedron with corners x: its natural coordinates by Newton on the
// trilinear map, clamped to the element (exact above a flat face, close elsewhere).
double distance_to_hex(const std::array<V3, 8>& x, const V3& p) {
  Eigen::Vector3d xi = Eigen::Vector3d::Zero();
  auto at = [&](const Eigen::Vector3d& q, Eigen::Matrix3d* J) {
    V3 r;
    if (J) J->setZero();
    for (std::size_t a = 0; a < 8; ++a) {
      const double f[3] = {1 + kXi[a][0] * q[0], 1 + kXi[a][1] * q[1], 1 + kXi[a][2] * q[2]};
      r += (0.125 * f[0] * f[1] * f[2]) * x[a];
      if (J)
        for (int k = 0; k < 3; ++k) {
          const double dN = 0.125 * kXi[a][k] * f[(k + 1) % 3] * f[(k + 2) % 3];
          (*J)(0, k) += dN * x[a].x;
          (*J)(1, k) += dN * x[a].y;
          (*J)(2, k) += dN * x[a].z;
        }
    }
    return r;
  };
  for (int it = 0; it < 8; ++it) {
    Eigen::Matrix3d J;
    const V3 r = p - at(xi, &J);
    if (!(std::abs(J.determinant()) > 0)) break;
    const Eigen::Vector3d step = J.inverse() * Eigen::Vector3d(r.x, r.y, r.z);
    xi = (xi + step).cwiseMax(-1.5).cwiseMin(1.5);
  }
  return norm(p - at(xi.cwiseMax(-1.0).cwiseMin(1.0), nullptr));
}

struct FaceRef {
  std::int32_t element;
  int face;
  V3 centre, normal;
  double radius;  // largest centre-to-corner distance
};

// The thinnest tow: the smallest distance between a hexahedron's bottom and top face centres.
double thinnest_tow(const ImpregnatedModel& m, const std::vector<V3>& x) {
  double thinnest = 1e300;
  for (const auto& h : m.hex) {
    V3 bottom, top;
    for (std::size_t k = 0; k < 4; ++k)
      bottom +=
          0.25 *
          x[static_cast<std::size_t>(h[static_cast<std::size_t>(fem::kHex8Faces[0].corner[k])])],
          top +=
          0.25 *
          x[static_cast<std::size_t>(h[static_cast<std::size_t>(fem::kHex8Faces[1].corner[k])])];
    thinnest = std::min(thinnest, norm(top - bottom));
  }
  return thinnest;
}

// Tied pairs: outer faces of the model's hexahedra (at positions x) facing each other across the
// resin layer, between the plies and between neighbouring tows of a ply.
std::vector<TiePairs> tie_pairs(const ImpregnatedModel& m, const std::vector<V3>& x,
                                const TieSpec& spec) {
  std::map<std::array<std::int32_t, 4>, std::pair<std::int32_t, int>> face_of;
  std::map<std::array<std::int32_t, 4>, int> count;
  for (std::size_t e = 0; e < m.hex.size(); ++e)
    for (int f = 0; f < 6; ++f) {
      std::array<std::int32_t, 4> key{};
      for (std::size_t k = 0; k < 4; ++k)
        key[k] = m.hex[e][static_cast<std::size_t>(fem::kHex8Faces[f].corner[k])];
      std::sort(key.begin(), key.end());
      ++count[key];
      face_of[key] = {static_cast<std::int32_t>(e), f};
    }
  std::vector<FaceRef> faces;
  for (const auto& [key, n] : count) {
    if (n != 1) continue;
    const auto [e, f] = face_of[key];
    std::array<V3, 4> c;
    for (std::size_t k = 0; k < 4; ++k)
      c[k] = x[static_cast<std::size_t>(m.hex[static_cast<std::size_t>(e)][static_cast<std::size_t>(
          fem::kHex8Faces[f].corner[k])])];
    const V3 centre = 0.25 * (c[0] + c[1] + c[2] + c[3]);
    const V3 normal = normalized(cross(c[2] - c[0], c[3] - c[1]));  // outward for VTK face order
    double radius = 0;
    for (const auto& p : c) radius = std::max(radius, norm(p - centre));
    faces.push_back({e, f, centre, normal, radius});
  }
  const double gap = spec.distance > 0 ? spec.distance : thinnest_tow(m, x);
  std::vector<double> lo(3 * faces.size()), hi(3 * faces.size());
  for (std::size_t k = 0; k < faces.size(); ++k)
    for (int d = 0; d < 3; ++d) {
      const double c = faces[k].centre.arr()[static_cast<std::size_t>(d)],
                   r = faces[k].radius + gap;
      lo[3 * k + static_cast<std::size_t>(d)] = c - r;
      hi[3 * k + static_cast<std::size_t>(d)] = c + r;
    }
  fem::BucketGrid grid;
  if (!faces.empty()) grid.build(faces.size(), lo.data(), hi.data());
  TiePairs inter{"interply", {}, {}}, intra{"intraply", {}, {}};
  for (const auto& s : faces) {
    const auto es = static_cast<std::size_t>(s.element);
    const double q[3] = {s.centre.x, s.centre.y, s.centre.z};
    std::int32_t begin = 0, end = 0;
    if (!grid.cell_of(q, begin, end)) continue;
    double best = 1e300;
    const FaceRef* found = nullptr;
    bool across_plies = false;
    for (std::int32_t it = begin; it < end; ++it) {
      const FaceRef& g = faces[static_cast<std::size_t>(grid.items()[it])];
      const auto eg = static_cast<std::size_t>(g.element);
      const bool other_ply = m.hex_ply[eg] != m.hex_ply[es];
      const bool other_tow = !other_ply && m.hex_tow[eg] != m.hex_tow[es];
      if (!(other_ply ? spec.interply : other_tow && spec.intraply)) continue;
      // Each bond once: the face of the lower (ply, tow) is the slave.
      if (std::make_pair(m.hex_ply[es], m.hex_tow[es]) >
          std::make_pair(m.hex_ply[eg], m.hex_tow[eg]))
        continue;
      if (dot(s.normal, g.normal) > -0.5) continue;  // faces that face each other
      const V3 d = s.centre - g.centre;
      const double normal_gap = std::abs(dot(d, g.normal));
      const double in_plane = norm(d - dot(d, g.normal) * g.normal);
      if (normal_gap > gap || in_plane > g.radius) continue;
      if (in_plane < best) best = in_plane, found = &g, across_plies = other_ply;
    }
    if (!found) continue;
    TiePairs& t = across_plies ? inter : intra;
    t.slave.emplace_back(s.element, s.face);
    t.master.emplace_back(found->element, found->face);
  }
  std::vector<TiePairs> ties;
  if (spec.interply) ties.push_back(std::move(inter));
  if (spec.intraply) ties.push_back(std::move(intra));
  return ties;
}

// Kept stitches: a drape stitch bar whose two end nodes lie within the capture distance of a
// kept tow hexahedron (its box grown by that distance) is kept with its nodes at their draped
// positions; the crush ties those nodes to the nearest tow face (the yarn cured in place).
void capture_stitches(ImpregnatedModel& m, const fem::io::StageFrame& frame,
                      const std::vector<V3>& x, const StitchSpec& spec) {
  const auto& mesh = frame.mesh;
  m.stitch_capture = spec.capture_distance > 0 ? spec.capture_distance : thinnest_tow(m, x);
  const double reach = m.stitch_capture;
  std::vector<double> lo(3 * m.hex.size(), 1e300), hi(3 * m.hex.size(), -1e300);
  for (std::size_t e = 0; e < m.hex.size(); ++e)
    for (auto n : m.hex[e])
      for (std::size_t d = 0; d < 3; ++d) {
        const double c = x[static_cast<std::size_t>(n)].arr()[d];
        lo[3 * e + d] = std::min(lo[3 * e + d], c - reach);
        hi[3 * e + d] = std::max(hi[3 * e + d], c + reach);
      }
  fem::BucketGrid grid;
  grid.build(m.hex.size(), lo.data(), hi.data());
  std::vector<std::int8_t> beside(mesh.n_points(), -1);  // -1: not looked up yet
  auto captured = [&](std::size_t node) {
    if (beside[node] >= 0) return beside[node] == 1;
    const double* q = &frame.coordinates[3 * node];
    const V3 p{q[0], q[1], q[2]};
    std::int32_t begin = 0, end = 0;
    bool in = false;
    if (grid.cell_of(q, begin, end))
      for (std::int32_t it = begin; it < end && !in; ++it) {
        const auto e = static_cast<std::size_t>(grid.items()[it]);
        if (q[0] < lo[3 * e] || q[0] > hi[3 * e] || q[1] < lo[3 * e + 1] || q[1] > hi[3 * e + 1] ||
            q[2] < lo[3 * e + 2] || q[2] > hi[3 * e + 2])
          continue;
        std::array<V3, 8> corners;
        for (std::size_t a = 0; a < 8; ++a) corners[a] = x[static_cast<std::size_t>(m.hex[e][a])];
        in = distance_to_hex(corners, p) <= reach;
      }
    beside[node] = in ? 1 : 0;
    return in;
  };
  std::vector<std::int32_t> point_of(mesh.n_points(), -1);
  auto point = [&](std::size_t node) {
    if (point_of[node] < 0) {
      point_of[node] = static_cast<std::int32_t>(m.points.size() / 3);
      m.points.insert(m.points.end(), {frame.coordinates[3 * node], frame.coordinates[3 * node + 1],
                                       frame.coordinates[3 * node + 2]});
      m.point_user_id.push_back(mesh.node_user_id.empty() ? static_cast<std::int64_t>(node + 1)
                                                          : mesh.node_user_id[node]);
      ++m.n_stitch_nodes;
    }
    return point_of[node];
  };
  for (std::size_t b = 0; b < mesh.n_bar(); ++b) {
    const auto i = static_cast<std::size_t>(mesh.bars().conn[2 * b]),
               j = static_cast<std::size_t>(mesh.bars().conn[2 * b + 1]);
    if (!captured(i) || !captured(j)) {
      ++m.n_stitches_uncaptured;
      continue;
    }
    m.stitch.push_back({point(i), point(j)});
    m.stitch_user_id.push_back(mesh.bars().user_id.empty() ? static_cast<std::int64_t>(b + 1)
                                                           : mesh.bars().user_id[b]);
    m.stitch_part.push_back(mesh.bars().part.empty() ? 0 : mesh.bars().part[b]);
  }
}

}  // namespace

std::size_t ImpregnatedModel::n_tie_pairs() const {
  std::size_t n = 0;
  for (const auto& t : ties) n += t.slave.size();
  return n;
}

ImpregnatedModel build_impregnated_model(const fem::io::StageFrame& frame,
                                         const TransferSpec& spec) {
  spec.mapping.validate();
  validate(spec.fibre);
  validate(spec.resin);
  const auto& mesh = frame.mesh;
  const std::size_t n_hex = mesh.n_hex();
  const fem::io::FrameField* fibre_field = frame.field("fibre_direction");
  if (!fibre_field || fibre_field->n_components != 3)
    throw std::runtime_error(frame.file.string() + ": the frame has no fibre_direction field");
  // Hexahedra the drape eroded are no longer part of the fabric.
  const fem::io::FrameField* eroded = frame.field("eroded");
  const auto& X0 = mesh.points;
  const auto& x1 = frame.coordinates;
  auto at = [](const std::vector<double>& v, std::int64_t i) {
    return V3{v[3 * static_cast<std::size_t>(i)], v[3 * static_cast<std::size_t>(i) + 1],
              v[3 * static_cast<std::size_t>(i) + 2]};
  };

  ImpregnatedModel m;
  m.part_names = mesh.part_names;
  m.n_stitches = mesh.n_bar();
  const V3 axis = normalized(spec.trim.axis);
  std::vector<std::size_t> kept;  // source hexahedra
  DrapedTows tows;
  std::vector<std::int32_t> node_of(mesh.n_points(), -1);
  for (std::size_t e = 0; e < n_hex; ++e) {
    if (!mesh.hex_tow.empty() && mesh.hex_tow[e] < 0) continue;
    if (!spec.parts.empty() &&
        std::find(spec.parts.begin(), spec.parts.end(), mesh.hex().part[e]) == spec.parts.end())
      continue;
    ++m.n_candidates;
    if (eroded && eroded->n_components == 1 && eroded->values[e] > 0.5) {
      ++m.n_lost;
      ++m.n_eroded;
      continue;
    }
    std::array<V3, 8> X, x;
    V3 centre;
    for (std::size_t a = 0; a < 8; ++a) {
      X[a] = at(X0, mesh.hex().conn[8 * e + a]);
      x[a] = at(x1, mesh.hex().conn[8 * e + a]);
      centre += 0.125 * x[a];
    }
    if (spec.trim.radius > 0) {
      const V3 r = centre - spec.trim.centre;
      if (norm(r - dot(r, axis) * axis) > spec.trim.radius) {
        ++m.n_trimmed;
        continue;
      }
    }
    const V3 a{fibre_field->values[3 * e], fibre_field->values[3 * e + 1],
               fibre_field->values[3 * e + 2]};
    V3 bottom, top;
    for (std::size_t k = 0; k < 4; ++k) bottom += 0.25 * x[k], top += 0.25 * x[k + 4];
    const V3 through = normalized(top - bottom);
    const bool mappable = hex_volume(X) > 0 && hex_volume(x) > 0 && std::isfinite(a.x) &&
                          norm(a) > 0.5 && std::abs(dot(normalized(a), through)) < 0.99;
    if (!mappable) {
      ++m.n_lost;
      continue;
    }
    if (spec.min_corner_jacobian > 0 && min_scaled_corner_jacobian(x) < spec.min_corner_jacobian) {
      ++m.n_lost;
      ++m.n_distorted;
      continue;
    }
    kept.push_back(e);
    std::array<std::int32_t, 8> h{};
    for (std::size_t k = 0; k < 8; ++k) {
      const auto node = static_cast<std::size_t>(mesh.hex().conn[8 * e + k]);
      if (node_of[node] < 0) {
        node_of[node] = static_cast<std::int32_t>(tows.current.size());
        tows.current.push_back(at(x1, static_cast<std::int64_t>(node)));
        tows.reference.push_back(at(X0, static_cast<std::int64_t>(node)));
        m.point_user_id.push_back(mesh.node_user_id.empty() ? static_cast<std::int64_t>(node + 1)
                                                            : mesh.node_user_id[node]);
      }
      h[k] = node_of[node];
    }
    tows.hex.push_back(h);
    tows.fibre.push_back(normalized(a));
    tows.fibre_stretch.push_back(fibre_stretch(X, x, normalized(a)));
  }
  if (m.n_candidates == 0)
    throw std::runtime_error(frame.file.string() + ": the frame holds no tow hexahedra" +
                             (spec.parts.empty() ? "" : " in the chosen parts"));
  if (tows.hex.empty()) return m;  // everything trimmed or lost: the stage says which

  const ImpregnatedMapping map = map_impregnated(tows, spec.mapping);
  m.hex = tows.hex;
  for (const auto& p : tows.current) m.points.insert(m.points.end(), {p.x, p.y, p.z});
  m.frame = map.frame;
  m.vf = map.vf;
  m.volume_ratio = map.volume_ratio;
  m.vf_class = map.vf_class;
  m.n_capped = map.n_capped;
  m.n_floored = map.n_floored;
  for (double vf : map.class_vf)
    m.classes.push_back(impregnated_tow(spec.fibre, spec.resin, vf, spec.compressive_ratio));
  for (auto e : kept) {
    m.hex_user_id.push_back(mesh.hex().user_id.empty() ? static_cast<std::int64_t>(e + 1)
                                                       : mesh.hex().user_id[e]);
    m.hex_part.push_back(mesh.hex().part[e]);
    m.hex_ply.push_back(mesh.hex_ply.empty() ? 0 : mesh.hex_ply[e]);
    m.hex_tow.push_back(mesh.hex_tow.empty() ? static_cast<std::int32_t>(e) : mesh.hex_tow[e]);
  }

  m.ties = tie_pairs(m, tows.current, spec.ties);
  if (spec.stitches.keep) capture_stitches(m, frame, tows.current, spec.stitches);
  return m;
}

}  // namespace ncfsim::transfer
