#include "fem/contact/tied_contact.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "fem/checkpoint.hpp"
#include "fem/contact/bucket_grid.hpp"
#include "fem/contact/contact_surface.hpp"
#include "fem/contact/segment_frame.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::fem {

namespace {

// Orthonormal frame (t1 along a1, t2, n) of a segment with corners p, and the point at (xi, eta)
// with its shape functions N.
struct TieFrame {
  double t1[3], t2[3], n[3], x[3], N[4];
};

// The point, its shape functions and the unit normal; with `tangents`, t1 and t2 too (a cohesive
// tie reads the normal only: the tangents were a third of its frame's cost, the frame a fifth of
// a crush cycle).
template <bool tangents>
inline void tie_frame(const double (&p)[4][3], double xi, double eta, TieFrame& f) {
  double a1[3], a2[3];
  segment_shape(xi, eta, f.N);
  for (int k = 0; k < 3; ++k) {
    a1[k] = 0.25 * (-p[0][k] + p[1][k] + p[2][k] - p[3][k]);
    a2[k] = 0.25 * (-p[0][k] - p[1][k] + p[2][k] + p[3][k]);
    f.x[k] = f.N[0] * p[0][k] + f.N[1] * p[1][k] + f.N[2] * p[2][k] + f.N[3] * p[3][k];
  }
  double n[3] = {a1[1] * a2[2] - a1[2] * a2[1], a1[2] * a2[0] - a1[0] * a2[2],
                 a1[0] * a2[1] - a1[1] * a2[0]};
  const double ln = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  const double in = ln > 0 ? 1.0 / ln : 0.0;
  for (int k = 0; k < 3; ++k) f.n[k] = n[k] * in;
  if constexpr (tangents) {
    const double la = std::sqrt(a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2]);
    const double ia = la > 0 ? 1.0 / la : 0.0;
    for (int k = 0; k < 3; ++k) f.t1[k] = a1[k] * ia;
    f.t2[0] = f.n[1] * f.t1[2] - f.n[2] * f.t1[1];
    f.t2[1] = f.n[2] * f.t1[0] - f.n[0] * f.t1[2];
    f.t2[2] = f.n[0] * f.t1[1] - f.n[1] * f.t1[0];
  }
}

// Squared distance from p to the nearest point of the segment with corners c (reference
// positions x0), its local coordinates clamped to the segment.
inline double closest_on_segment(const double* x0, const std::int32_t* c, const double* p,
                                 double& xi, double& eta) {
  double q[4][3];
  gather_segment(x0, c, q);
  SegmentFrame f;
  segment_frame(q, 0, f);
  const SegmentProjection pr = project_on_segment(f, p[0], p[1], p[2]);
  xi = std::clamp(pr.xi, -1.0, 1.0), eta = std::clamp(pr.eta, -1.0, 1.0);
  TieFrame tf;
  tie_frame<false>(q, xi, eta, tf);
  double d2 = 0;
  for (int k = 0; k < 3; ++k) d2 += (p[k] - tf.x[k]) * (p[k] - tf.x[k]);
  return d2;
}

}  // namespace

TiedContact::TiedContact(TiedContactConfig config) : cfg_(std::move(config)) { validate(cfg_); }

void TiedContact::add_tie(std::int32_t node, const std::int32_t* corners, double xi, double eta,
                          std::int32_t seg_hex, double area, const double* x0, const double* mass,
                          double inv_dt0_sq) {
  double q[4][3];
  gather_segment(x0, corners, q);
  TieFrame tf;
  tie_frame<true>(q, xi, eta, tf);
  const double* p = x0 + 3 * static_cast<std::size_t>(node);
  double off[3] = {0, 0, 0}, m_m = 0;
  for (int k = 0; k < 3; ++k) {
    const double d = p[k] - tf.x[k];
    off[0] += d * tf.t1[k], off[1] += d * tf.t2[k], off[2] += d * tf.n[k];
  }
  for (int a = 0; a < 4; ++a) m_m += tf.N[a] * mass[3 * static_cast<std::size_t>(corners[a])];
  const double m_s = mass[3 * static_cast<std::size_t>(node)];
  node_.push_back(node);
  for (int a = 0; a < 4; ++a) corner_.push_back(corners[a]);
  seg_hex_.push_back(seg_hex);
  slave_hex_.push_back(-1);
  xi_.push_back(xi);
  eta_.push_back(eta);
  offset_.insert(offset_.end(), off, off + 3);
  for (int k = 0; k < 3; ++k) offset_global_.push_back(p[k] - tf.x[k]);
  stiffness_.push_back(cfg_.penalty_scale * m_s * m_m / (m_s + m_m) * inv_dt0_sq);
  normal_cap_.push_back(cfg_.normal_strength * area);
  shear_cap_.push_back(cfg_.shear_strength * area);
  area_.push_back(area);
}

void TiedContact::initialise_face_pairs(const ContactSetup& setup) {
  const std::string prefix = cfg_.key_path.empty() ? "contact." + cfg_.name : cfg_.key_path;
  const ElementSet& hexes = setup.mesh->elements(ElementKind::Hex8);
  const std::size_t offset = setup.mesh->element_offset(ElementKind::Hex8);
  const double* x0 = setup.x0;
  auto face_nodes = [&](std::int32_t h, int f, std::int32_t(&c)[4]) {
    if (static_cast<std::size_t>(h) >= hexes.size())
      throw InputError(cfg_.source_file, prefix + ".face_pairs",
                       "names hexahedron index " + std::to_string(h) + " outside the mesh");
    const auto nodes = hexes.nodes(static_cast<std::size_t>(h));
    for (int a = 0; a < 4; ++a)
      c[a] = nodes[static_cast<std::size_t>(
          kHex8Faces[static_cast<std::size_t>(f)].corner[static_cast<std::size_t>(a)])];
  };
  // Slave faces (each once) give their nodes a quarter of their area; each slave node collects
  // the master faces paired with its faces.
  std::vector<std::pair<std::int64_t, std::size_t>> slave_faces;  // key -> first pair
  for (std::size_t k = 0; k < cfg_.face_pairs.size(); ++k)
    slave_faces.emplace_back(
        6 * static_cast<std::int64_t>(cfg_.face_pairs[k].slave_hex) + cfg_.face_pairs[k].slave_face,
        k);
  std::sort(slave_faces.begin(), slave_faces.end());
  struct Candidate {
    std::int32_t node;
    std::size_t pair;
  };
  std::vector<Candidate> cand;
  std::vector<double> area(setup.mesh->n_nodes(), 0.0);
  std::vector<std::int32_t> hex_of(setup.mesh->n_nodes(), -1);
  for (std::size_t i = 0; i < slave_faces.size(); ++i) {
    const auto& p = cfg_.face_pairs[slave_faces[i].second];
    std::int32_t c[4];
    face_nodes(p.slave_hex, p.slave_face, c);
    if (i == 0 || slave_faces[i].first != slave_faces[i - 1].first) {
      double q[4][3];
      gather_segment(x0, c, q);
      double d1[3], d2[3];
      for (int k = 0; k < 3; ++k) d1[k] = q[2][k] - q[0][k], d2[k] = q[3][k] - q[1][k];
      const double cx = d1[1] * d2[2] - d1[2] * d2[1], cy = d1[2] * d2[0] - d1[0] * d2[2],
                   cz = d1[0] * d2[1] - d1[1] * d2[0];
      const double a = 0.5 * std::sqrt(cx * cx + cy * cy + cz * cz);
      for (auto nd : c)
        area[static_cast<std::size_t>(nd)] += 0.25 * a,
            hex_of[static_cast<std::size_t>(nd)] = p.slave_hex;
    }
    for (auto nd : c) cand.push_back({nd, slave_faces[i].second});
  }
  std::sort(cand.begin(), cand.end(), [](const Candidate& a, const Candidate& b) {
    return a.node != b.node ? a.node < b.node : a.pair < b.pair;
  });
  const double inv_dt0_sq = 1.0 / (setup.dt * setup.dt);
  const double r = cfg_.search_distance;  // 0: the pairs are trusted
  search_distance_ = r;
  for (std::size_t i = 0; i < cand.size();) {
    const std::int32_t node = cand[i].node;
    const double* p = x0 + 3 * static_cast<std::size_t>(node);
    double best_d2 = r > 0 ? r * r : std::numeric_limits<double>::max();
    std::int32_t best_c[4] = {0, 0, 0, 0};
    std::int32_t best_hex = -1;
    double bxi = 0, beta = 0;
    for (; i < cand.size() && cand[i].node == node; ++i) {
      const auto& pr = cfg_.face_pairs[cand[i].pair];
      std::int32_t c[4];
      face_nodes(pr.master_hex, pr.master_face, c);
      if (std::find(c, c + 4, node) != c + 4) continue;
      double xi = 0, eta = 0;
      const double d2 = closest_on_segment(x0, c, p, xi, eta);
      if (d2 <= best_d2) {
        best_d2 = d2, bxi = xi, beta = eta, best_hex = pr.master_hex;
        std::copy(c, c + 4, best_c);
      }
    }
    if (best_hex < 0) continue;
    add_tie(node, best_c, bxi, beta, static_cast<std::int32_t>(offset) + best_hex,
            area[static_cast<std::size_t>(node)], x0, setup.mass, inv_dt0_sq);
    slave_hex_.back() = static_cast<std::int32_t>(offset) + hex_of[static_cast<std::size_t>(node)];
  }
}

// Per tie (a slave node) ~200 bytes of state, with push_back slack ~300; the master surface is
// built for the set-up only (records, frames, grid: ~250 bytes a segment); face pairs also take
// two arrays over the mesh's nodes while they are matched.
double TiedContact::estimated_bytes(const Mesh& mesh, bool erosion) const {
  (void)erosion;
  constexpr double kPerTie = 300, kPerMasterSegment = 250;
  if (!cfg_.face_pairs.empty())
    return kPerTie * static_cast<double>(cfg_.face_pairs.size()) +
           12.0 * static_cast<double>(mesh.n_nodes()) +
           kPerMasterSegment * static_cast<double>(cfg_.face_pairs.size());
  const ContactSurfaceSize master = contact_surface_size(mesh, {cfg_.master}, false);
  const double ties = cfg_.slave_nodes.empty()
                          ? contact_surface_size(mesh, {cfg_.slave}, false).nodes
                          : static_cast<double>(cfg_.slave_nodes.size());
  return kPerTie * ties + kPerMasterSegment * master.segments;
}

void TiedContact::initialise(const ContactSetup& setup) {
  const std::string prefix = "contact." + cfg_.name;
  if (!setup.mesh || !setup.x0 || !setup.mass || !(setup.dt > 0))
    throw InputError(cfg_.source_file, prefix, "contact set up without mesh, masses or step");
  node_.clear(), corner_.clear(), xi_.clear(), eta_.clear(), offset_.clear(), stiffness_.clear();
  offset_global_.clear();
  normal_cap_.clear(), shear_cap_.clear(), seg_hex_.clear(), slave_hex_.clear(), area_.clear();
  cohesive_ = cfg_.mode_i_energy > 0;
  if (!cfg_.face_pairs.empty()) {
    initialise_face_pairs(setup);
    if (node_.empty())
      throw InputError(cfg_.source_file, prefix + ".face_pairs",
                       "no slave node lies within the search distance of its paired master faces");
    reset_tie_state();
    return;
  }
  // Explicit slave nodes need no slave surface: the master is then the only group.
  const bool explicit_nodes = !cfg_.slave_nodes.empty();
  ContactGroup slave = cfg_.slave, master = cfg_.master;
  if (slave.name.empty()) slave.name = "slave";
  if (master.name.empty()) master.name = "master";
  const int master_group = explicit_nodes ? 0 : 1;
  const ContactSurface surf = extract_contact_surface(
      *setup.mesh,
      explicit_nodes ? std::vector<ContactGroup>{master} : std::vector<ContactGroup>{slave, master},
      setup.x0, cfg_.source_file, prefix);
  const double* x0 = setup.x0;
  const double* mass = setup.mass;
  std::vector<std::int32_t> master_seg;
  double t_min = std::numeric_limits<double>::max();
  for (std::size_t s = 0; s < surf.n_segments(); ++s)
    if (surf.seg_group[s] == master_group) {
      master_seg.push_back(static_cast<std::int32_t>(s));
      t_min = std::min(t_min, surf.seg_elem_thickness[s]);
    }
  search_distance_ =
      cfg_.search_distance > 0 ? cfg_.search_distance : (explicit_nodes ? 1.0 : 0.1) * t_min;
  const double r = search_distance_;

  // Master segments in a grid, boxes grown by the search distance.
  const std::size_t n_m = master_seg.size();
  std::vector<double> lo(3 * n_m), hi(3 * n_m);
  for (std::size_t a = 0; a < n_m; ++a) {
    double p[4][3];
    gather_segment(x0, &surf.seg_nodes[4 * static_cast<std::size_t>(master_seg[a])], p);
    for (int k = 0; k < 3; ++k) {
      lo[3 * a + k] = std::min({p[0][k], p[1][k], p[2][k], p[3][k]}) - r;
      hi[3 * a + k] = std::max({p[0][k], p[1][k], p[2][k], p[3][k]}) + r;
    }
  }
  BucketGrid grid;
  grid.build(n_m, lo.data(), hi.data());

  const double inv_dt0_sq = 1.0 / (setup.dt * setup.dt);
  // The slave nodes: the explicit ones (no tributary area: the strengths give their ties no
  // limit) or the slave surface's.
  std::vector<std::int32_t> slave_nodes;
  std::vector<double> slave_area;
  if (explicit_nodes) {
    for (const std::int32_t node : cfg_.slave_nodes) {
      if (node < 0 || static_cast<std::size_t>(node) >= setup.mesh->n_nodes())
        throw InputError(cfg_.source_file, prefix + ".slave_nodes",
                         "names node " + std::to_string(node) + " outside the mesh");
      slave_nodes.push_back(node), slave_area.push_back(0.0);
    }
  } else {
    for (std::size_t e = 0; e < surf.n_nodes(); ++e)
      if (surf.node_group[e] == 0)
        slave_nodes.push_back(surf.node[e]), slave_area.push_back(surf.node_area[e]);
  }
  untied_ = 0;
  for (std::size_t e = 0; e < slave_nodes.size(); ++e) {
    const std::int32_t node = slave_nodes[e];
    const double* p = x0 + 3 * static_cast<std::size_t>(node);
    std::int32_t b = 0, end = 0;
    if (!grid.cell_of(p, b, end)) {
      ++untied_;
      continue;
    }
    double best_d2 = r * r;
    std::int32_t best = -1;
    double bxi = 0, beta = 0;
    for (std::int32_t it = b; it < end; ++it) {
      const auto a = static_cast<std::size_t>(grid.items()[it]);
      if (p[0] < lo[3 * a] || p[0] > hi[3 * a] || p[1] < lo[3 * a + 1] || p[1] > hi[3 * a + 1] ||
          p[2] < lo[3 * a + 2] || p[2] > hi[3 * a + 2])
        continue;
      const auto s = static_cast<std::size_t>(master_seg[a]);
      const std::int32_t* cn = &surf.seg_nodes[4 * s];
      if (std::find(cn, cn + 4, node) != cn + 4) continue;  // shares the node: already joined
      double xi = 0, eta = 0;
      const double d2 = closest_on_segment(x0, cn, p, xi, eta);
      if (d2 <= best_d2) best_d2 = d2, best = static_cast<std::int32_t>(s), bxi = xi, beta = eta;
    }
    if (best < 0) {
      ++untied_;
      continue;
    }
    add_tie(node, &surf.seg_nodes[4 * static_cast<std::size_t>(best)], bxi, beta,
            surf.seg_hex[static_cast<std::size_t>(best)], slave_area[e], x0, mass, inv_dt0_sq);
  }
  if (node_.empty())
    throw InputError(cfg_.source_file, prefix + ".search_distance",
                     "no slave node lies within " + std::to_string(r) + " m of the master surface");
  reset_tie_state();
}

void TiedContact::reset_tie_state() {
  alive_.assign(node_.size(), 1);
  state_.assign(node_.size(), CohesiveState{});
  tie_work_.assign(node_.size(), 0.0);
  failed_work_ = 0;
  last_sep_.assign(3 * node_.size(), 0.0);
  last_force_.assign(3 * node_.size(), 0.0);
  n_alive_ = static_cast<std::int64_t>(node_.size());
  dissipation_ = 0;
  force_ = {};
}

double TiedContact::tied_area() const {
  double a = 0;
  for (double v : area_) a += v;
  return a;
}

double TiedContact::failed_area() const {
  double a = 0;
  for (std::size_t t = 0; t < area_.size(); ++t)
    if (!alive_[t]) a += area_[t];
  return a;
}

bool TiedContact::nodes_to_read(const std::uint8_t* owned, const double*, double,
                                std::vector<std::int32_t>& out) const {
  for (std::size_t t = 0; t < node_.size(); ++t)
    if (owned[static_cast<std::size_t>(node_[t])])
      out.insert(out.end(), &corner_[4 * t], &corner_[4 * t] + 4);
  return true;
}

void TiedContact::restrict_to_rank(const std::uint8_t* owned, const std::uint8_t*) {
  mine_.assign(node_.size(), 0);
  for (std::size_t t = 0; t < node_.size(); ++t)
    mine_[t] = owned[static_cast<std::size_t>(node_[t])];
}

void TiedContact::add_forces(const double* x, const double*, const double*, double, double* f) {
  const std::size_t n = node_.size();
  double Rx = 0, Ry = 0, Rz = 0, released = 0, alive_dissipation = 0;
  std::int64_t failed = 0;
  for (std::size_t t = 0; t < n; ++t) {
    if (!alive_[t] || (!mine_.empty() && !mine_[t])) continue;
    double q[4][3];
    gather_segment(x, &corner_[4 * t], q);
    TieFrame tf;
    if (cohesive_)
      tie_frame<false>(q, xi_[t], eta_[t], tf);
    else
      tie_frame<true>(q, xi_[t], eta_[t], tf);
    const double* o = &offset_[3 * t];
    const auto i = 3 * static_cast<std::size_t>(node_[t]);
    double d[3];
    if (cohesive_) {
      // The separation from the tied point's displacement (a spring between the node and the
      // master point, derived from a potential): an offset turned with the segment would pull
      // the master segment round without the moment it makes, and with offsets as large as a
      // tow's side face (the resin gap between tows) that fed energy into the model.
      const double* g0 = &offset_global_[3 * t];
      for (int k = 0; k < 3; ++k) d[k] = x[i + k] - tf.x[k] - g0[k];
    } else {
      for (int k = 0; k < 3; ++k)
        d[k] = x[i + k] - (tf.x[k] + o[0] * tf.t1[k] + o[1] * tf.t2[k] + o[2] * tf.n[k]);
    }
    const double k = stiffness_[t];
    const double dn = d[0] * tf.n[0] + d[1] * tf.n[1] + d[2] * tf.n[2];
    const double d2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
    if (cohesive_) {
      // Tractions from the bilinear law at this node's separations (K = k / area).
      const double A = area_[t];
      const CohesiveLaw law{k / A,
                            cfg_.normal_strength,
                            cfg_.shear_strength,
                            cfg_.mode_i_energy,
                            cfg_.mode_ii_energy,
                            cfg_.bk_exponent};
      const double ds = std::sqrt(std::max(d2 - dn * dn, 0.0));
      CohesiveState& st = state_[t];
      double tn = 0, ts = 0;
      cohesive_tractions(law, dn, ds, st, tn, ts);
      const double dnp = std::max(dn, 0.0);
      // Work on the tie over the last step (force on the slave node, trapezoidal), then what it
      // still holds: the rest of its work is dissipated (damage; all of it once it has failed).
      double* ls = &last_sep_[3 * t];
      double* lf = &last_force_[3 * t];
      double Fv[3];
      const bool failing = alive_[t] == 2 || (st.damage >= 1.0 && dn >= 0);
      const double is = ds > 0 ? ts * A / ds : 0.0;
      for (int c = 0; c < 3; ++c)
        Fv[c] = failing ? 0.0 : -(tn * A * tf.n[c] + is * (d[c] - dn * tf.n[c]));
      for (int c = 0; c < 3; ++c) {
        tie_work_[t] -= 0.5 * (lf[c] + Fv[c]) * (d[c] - ls[c]);
        ls[c] = d[c], lf[c] = Fv[c];
      }
      if (failing) {
        alive_[t] = 0;
        ++failed;
        failed_work_ += tie_work_[t];
        continue;
      }
      // Held: the damaged springs of the opening and sliding, the undamaged one of a closing.
      const double dnc = std::min(dn, 0.0);
      alive_dissipation +=
          tie_work_[t] - 0.5 * A * law.K * ((1 - st.damage) * (dnp * dnp + ds * ds) + dnc * dnc);
      f[i] += Fv[0], f[i + 1] += Fv[1], f[i + 2] += Fv[2];
      for (int a = 0; a < 4; ++a) {
        const auto j = 3 * static_cast<std::size_t>(corner_[4 * t + a]);
        f[j] -= tf.N[a] * Fv[0], f[j + 1] -= tf.N[a] * Fv[1], f[j + 2] -= tf.N[a] * Fv[2];
      }
      Rx += Fv[0], Ry += Fv[1], Rz += Fv[2];
      continue;
    }
    const double tension = dn > 0 ? k * dn : 0.0;
    const double shear = k * std::sqrt(std::max(d2 - dn * dn, 0.0));
    double crit = 0;
    if (normal_cap_[t] > 0) crit += (tension / normal_cap_[t]) * (tension / normal_cap_[t]);
    if (shear_cap_[t] > 0) crit += (shear / shear_cap_[t]) * (shear / shear_cap_[t]);
    if (crit >= 1 || alive_[t] == 2) {
      alive_[t] = 0;
      ++failed;
      released += 0.5 * k * d2;
      continue;
    }
    const double Fx = -k * d[0], Fy = -k * d[1], Fz = -k * d[2];
    f[i] += Fx, f[i + 1] += Fy, f[i + 2] += Fz;
    for (int a = 0; a < 4; ++a) {
      const auto j = 3 * static_cast<std::size_t>(corner_[4 * t + a]);
      f[j] -= tf.N[a] * Fx, f[j + 1] -= tf.N[a] * Fy, f[j + 2] -= tf.N[a] * Fz;
    }
    Rx += Fx, Ry += Fy, Rz += Fz;
  }
  n_alive_ -= failed;
  dissipation_ += released;
  if (cohesive_) dissipation_ = failed_work_ + alive_dissipation;
  force_ = {Rx, Ry, Rz};
}

void TiedContact::erode(const std::vector<std::int32_t>& mesh_elements) {
  std::vector<std::int32_t> gone(mesh_elements);
  std::sort(gone.begin(), gone.end());
  auto is_gone = [&](std::int32_t h) {
    return h >= 0 && std::binary_search(gone.begin(), gone.end(), h);
  };
  for (std::size_t t = 0; t < node_.size(); ++t)
    if (alive_[t] && (is_gone(seg_hex_[t]) || is_gone(slave_hex_[t]))) alive_[t] = 2;
}

std::vector<ContactResultant> TiedContact::resultants() const {
  const std::string a = cfg_.slave.name.empty() ? "slave" : cfg_.slave.name;
  const std::string b = cfg_.master.name.empty() ? "master" : cfg_.master.name;
  return {{a + "__" + b, force_}};
}

void TiedContact::save_state(CheckpointWriter& w) const {
  w.write_int("n_ties", static_cast<std::int64_t>(node_.size()));
  save_array(w, "alive", alive_);
  std::vector<double> max_sep(state_.size()), damage(state_.size());
  for (std::size_t t = 0; t < state_.size(); ++t)
    max_sep[t] = state_[t].max_separation, damage[t] = state_[t].damage;
  save_array(w, "max_separation", max_sep);
  save_array(w, "damage", damage);
  save_array(w, "tie_work", tie_work_);
  save_array(w, "last_separation", last_sep_);
  save_array(w, "last_force", last_force_);
  w.write_double("failed_work", failed_work_);
  w.write_int("n_alive", n_alive_);
  w.write_double("dissipation", dissipation_);
  const double f[3] = {force_.x, force_.y, force_.z};
  w.write_array("force", std::span<const double>(f, 3));
}

void TiedContact::load_state(CheckpointReader& r) {
  r.check_int("n_ties", static_cast<std::int64_t>(node_.size()));
  load_array(r, "alive", alive_);
  std::vector<double> max_sep, damage;
  r.read_array("max_separation", max_sep, state_.size());
  r.read_array("damage", damage, state_.size());
  for (std::size_t t = 0; t < state_.size(); ++t)
    state_[t].max_separation = max_sep[t], state_[t].damage = damage[t];
  load_array(r, "tie_work", tie_work_);
  load_array(r, "last_separation", last_sep_);
  load_array(r, "last_force", last_force_);
  failed_work_ = r.read_double("failed_work");
  n_alive_ = r.read_int("n_alive");
  dissipation_ = r.read_double("dissipation");
  double f[3];
  r.read_into("force", f, 3);
  force_ = {f[0], f[1], f[2]};
}

}  // namespace ncfsim::fem
