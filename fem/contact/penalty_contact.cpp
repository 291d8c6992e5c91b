#include "fem/contact/penalty_contact.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <limits>
#include <numeric>
#include <sstream>
#include <unordered_set>

#include "fem/checkpoint.hpp"
#include "fem/contact/contact_force_kernel.hpp"
#include "fem/errors.hpp"

namespace ncfsim::fem {

namespace {
// Facet normal . segment normal below which a node may touch a segment (opposed within 60 deg).
constexpr double kOpposedNormals = -0.5;
// Adjacent segment normals within 45 deg of a facet's mean normal belong to that facet.
constexpr double kSameFacet = 0.7071;
}  // namespace

PenaltyContact::PenaltyContact(PenaltyContactConfig config) : cfg_(std::move(config)) {
  validate(cfg_);
}

// Counted from the arrays below (docs/performance.md, "Memory"): per surface node its sorted
// position, facets, force slot; per facet (nodes on outer faces, ~1.5 each) the friction states
// and best hit; the candidates (~2 a node, kept at their largest); the nodal masses over the mesh.
// Per segment the arrays hold ~370 bytes (records, frame, box, depth, adjacency, grid share), but
// a dormant inner face (erosion) never touches most of them: 180 is what the hemispheres' resident
// sets after set-up show (CI, coarse, paper density; docs/performance.md).
double PenaltyContact::estimated_bytes(const Mesh& mesh, bool erosion) const {
  const ContactSurfaceSize sz = contact_surface_size(mesh, cfg_.groups, erosion);
  constexpr double kPerSegment = 180, kPerNode = 145, kPerFacet = 140, kPerCandidate = 34;
  return kPerSegment * sz.segments + kPerNode * sz.nodes +
         (1.5 * kPerFacet + 2 * kPerCandidate) * sz.outer_nodes +
         8.0 * static_cast<double>(mesh.n_nodes());
}

void PenaltyContact::initialise(const ContactSetup& setup) {
  const std::string prefix = "contact." + cfg_.name;
  if (!setup.mesh || !setup.x0 || !setup.mass || !(setup.dt > 0))
    throw InputError(cfg_.source_file, prefix, "contact set up without mesh, masses or step");
  surf_ = extract_contact_surface(*setup.mesh, cfg_.groups, setup.x0, cfg_.source_file, prefix,
                                  setup.erosion);
  n_groups_ = cfg_.groups.size();
  const std::size_t ng = n_groups_, n_seg = surf_.n_segments(), n_node = surf_.n_nodes();
  pair_of_.assign(ng * ng, -1);
  mu_of_.assign(ng * ng, 0.0);
  sign_of_.assign(ng * ng, 0.0);
  for (std::size_t p = 0; p < cfg_.pairs.size(); ++p) {
    const auto a = static_cast<std::size_t>(cfg_.pairs[p].first);
    const auto b = static_cast<std::size_t>(cfg_.pairs[p].second);
    for (auto [s, m] : {std::pair{a, b}, std::pair{b, a}}) {
      pair_of_[s * ng + m] = static_cast<std::int32_t>(p);
      mu_of_[s * ng + m] = cfg_.pairs[p].friction;
      sign_of_[s * ng + m] = s == a ? 1.0 : -1.0;  // the slave is the first group, or its reaction
    }
  }
  double t_min = std::numeric_limits<double>::max();
  depth_.resize(n_seg);
  for (std::size_t s = 0; s < n_seg; ++s) {
    const double t = surf_.seg_elem_thickness[s];
    if (!(t > 0))
      throw InputError(cfg_.source_file, prefix,
                       "hexahedron " + std::to_string(surf_.seg_elem_user_id[s]) +
                           " has no thickness normal to one of its faces");
    t_min = std::min(t_min, t);
    depth_[s] = cfg_.max_penetration * t;
  }
  margin_ =
      cfg_.search_margin > 0 ? cfg_.search_margin : cfg_.thickness + 0.5 * (n_seg ? t_min : 1.0);
  inv_dt0_sq_ = 1.0 / (setup.dt * setup.dt);

  seg_eroded_.assign(n_seg, 0);
  seg_dormant_.assign(n_seg, 0);
  seg_in_pair_.assign(n_seg, 0);
  for (std::size_t s = 0; s < n_seg; ++s) {
    const auto g = static_cast<std::size_t>(surf_.seg_group[s]);
    bool in_pair = false;
    for (std::size_t h = 0; h < ng; ++h) in_pair = in_pair || pair_of_[h * ng + g] >= 0;
    seg_in_pair_[s] = in_pair;
    seg_dormant_[s] = surf_.seg_cover_hex[s] >= 0;
  }
  collect_active_segments();
  // Faces of the same hexahedron sharing an edge with each segment (the closest-feature test of
  // the narrow phase; dormant inner faces among them are skipped there until uncovered).
  seg_adjacent_.assign(4 * n_seg, -1);
  {
    std::vector<std::int32_t> by_hex(n_seg);
    std::iota(by_hex.begin(), by_hex.end(), 0);
    std::stable_sort(by_hex.begin(), by_hex.end(), [&](std::int32_t a, std::int32_t b) {
      return surf_.seg_hex[static_cast<std::size_t>(a)] <
             surf_.seg_hex[static_cast<std::size_t>(b)];
    });
    for (std::size_t r = 0; r < n_seg;) {
      std::size_t r_end = r + 1;
      while (r_end < n_seg && surf_.seg_hex[static_cast<std::size_t>(by_hex[r_end])] ==
                                  surf_.seg_hex[static_cast<std::size_t>(by_hex[r])])
        ++r_end;
      for (std::size_t u = r; u < r_end; ++u) {
        const auto a = static_cast<std::size_t>(by_hex[u]);
        int n_adj = 0;
        for (std::size_t w = r; w < r_end; ++w) {
          const auto b = static_cast<std::size_t>(by_hex[w]);
          int shared = 0;
          for (int k = 0; k < 4; ++k)
            for (int m = 0; m < 4; ++m)
              shared += surf_.seg_nodes[4 * a + k] == surf_.seg_nodes[4 * b + m] ? 1 : 0;
          if (a != b && shared == 2 && n_adj < 4)
            seg_adjacent_[4 * a + static_cast<std::size_t>(n_adj++)] = static_cast<std::int32_t>(b);
        }
      }
      r = r_end;
    }
  }
  x_sorted_.assign(3 * n_node, 0.0);
  facet_state_.clear();
  facet_start_.assign(n_node + 1, 0);
  node_mass_.resize(setup.mesh->n_nodes());
  for (std::size_t i = 0; i < node_mass_.size(); ++i) node_mass_[i] = setup.mass[3 * i];
  facet_.assign(3 * kMaxFacets * n_node, 0.0);
  n_facets_.assign(n_node, 0);
  node_seg_start_.assign(n_node + 1, 0);
  for (auto e : surf_.seg_surface_node) ++node_seg_start_[static_cast<std::size_t>(e) + 1];
  for (std::size_t e = 0; e < n_node; ++e) node_seg_start_[e + 1] += node_seg_start_[e];
  node_seg_.resize(surf_.seg_surface_node.size());
  {
    std::vector<std::int32_t> fill(node_seg_start_.begin(), node_seg_start_.end() - 1);
    for (std::size_t q = 0; q < surf_.seg_surface_node.size(); ++q)  // segments in increasing order
      node_seg_[static_cast<std::size_t>(
          fill[static_cast<std::size_t>(surf_.seg_surface_node[q])]++)] =
          static_cast<std::int32_t>(q / 4);
  }
  cand_start_.assign(n_node + 1, 0);
  cand_seg_.clear();
  const std::size_t n_blocks = (n_seg + kFrameLanes - 1) / kFrameLanes;
  frame_.resize(n_blocks * kFrameLanes);
  box_lo_.resize(3 * active_seg_.size());
  box_hi_.resize(3 * active_seg_.size());
  pair_force_.assign(cfg_.pairs.size(), V3{});
  dissipation_ = 0;
  stats_ = {};
  sort_segments(setup.x0);
}

void PenaltyContact::collect_active_segments() {
  active_seg_.clear();
  for (std::size_t s = 0; s < seg_in_pair_.size(); ++s)
    if (seg_in_pair_[s] && !seg_off(s)) active_seg_.push_back(static_cast<std::int32_t>(s));
}

void PenaltyContact::erode(const std::vector<std::int32_t>& mesh_elements) {
  std::vector<std::int32_t> gone(mesh_elements);
  std::sort(gone.begin(), gone.end());
  auto eroded = [&](std::int32_t h) { return std::binary_search(gone.begin(), gone.end(), h); };
  bool any = false;
  for (std::size_t s = 0; s < seg_eroded_.size(); ++s) {
    if (!seg_eroded_[s] && eroded(surf_.seg_hex[s])) seg_eroded_[s] = 1, any = true;
    // An inner face whose covering neighbour is gone is outer now (if its own hexahedron stays).
    if (seg_dormant_[s] && eroded(surf_.seg_cover_hex[s])) seg_dormant_[s] = 0, any = true;
  }
  if (!any) return;
  collect_active_segments();
  box_lo_.resize(3 * active_seg_.size());
  box_hi_.resize(3 * active_seg_.size());
  resort_ = true;
}

void PenaltyContact::block_frames(const double* x, const std::int32_t* seg, std::size_t n,
                                  SegmentFrameBlock& fb) const {
  const std::int32_t* sn = surf_.seg_nodes.data();
  alignas(64) double p[4][3][kFrameLanes];
  alignas(64) double depth[kFrameLanes];
  for (std::size_t l = 0; l < kFrameLanes; ++l) {
    const auto s = static_cast<std::size_t>(seg[std::min(l, n - 1)]);  // pad with the last
    for (std::size_t a = 0; a < 4; ++a) {
      const double* q = x + 3 * static_cast<std::size_t>(sn[4 * s + a]);
      p[a][0][l] = q[0], p[a][1][l] = q[1], p[a][2][l] = q[2];
    }
    depth[l] = depth_[s];
  }
  segment_frames(p, depth, fb);
}

void PenaltyContact::compute_frames(const double* x, std::size_t blk) {
  const std::size_t n_seg = surf_.n_segments(), s0 = blk * kFrameLanes;
  const std::size_t n_lanes = std::min<std::size_t>(kFrameLanes, n_seg - s0);
  std::int32_t seg[kFrameLanes] = {};
  for (std::size_t l = 0; l < n_lanes; ++l) seg[l] = static_cast<std::int32_t>(s0 + l);
  SegmentFrameBlock fb;
  block_frames(x, seg, n_lanes, fb);
  // Lanes to records: the sort reads a frame through a segment index.
  for (std::size_t l = 0; l < n_lanes; ++l) {
    SegmentFrame& f = frame_[s0 + l];
    for (int k = 0; k < 3; ++k)
      f.c[k] = fb.c[k][l], f.n[k] = fb.n[k][l], f.e1[k] = fb.e1[k][l], f.e2[k] = fb.e2[k][l];
    f.hn = fb.hn[l], f.he1 = fb.he1[l], f.he2 = fb.he2[l], f.depth = fb.depth[l];
  }
}

bool PenaltyContact::closer_adjacent_face(const double* x, std::int32_t seg,
                                          const std::int32_t* adj, AdjacentFaces& faces,
                                          const double* fn, int nf, double px, double py, double pz,
                                          double pen, bool in_contact) {
  const double thick = cfg_.thickness;
  // The test runs only on a hit of a segment with outer neighbours in its own hexahedron that
  // beats the node's best so far; the faces' normals (along the cross product of the diagonals,
  // as a1 x a2 = d1 x d2 / 8) are made at the first such hit on the segment in this cycle.
  if (faces.seg != seg) {
    faces.seg = seg;
    for (int a = 0; a < 4; ++a) {
      AdjacentFaces::Face& A = faces.face[a];
      const bool exists = adj[a] >= 0;
      A.off = !exists || seg_off(static_cast<std::size_t>(adj[a]));
      A.framed = false;
      if (A.off) continue;
      double corners[4][3];
      gather_segment(x, &surf_.seg_nodes[4 * static_cast<std::size_t>(adj[a])], corners);
      double d1[3], d2[3];
      for (int k = 0; k < 3; ++k)
        d1[k] = corners[2][k] - corners[0][k], d2[k] = corners[3][k] - corners[1][k];
      A.m[0] = d1[1] * d2[2] - d1[2] * d2[1];
      A.m[1] = d1[2] * d2[0] - d1[0] * d2[2];
      A.m[2] = d1[0] * d2[1] - d1[1] * d2[0];
      A.m_len = std::sqrt(A.m[0] * A.m[0] + A.m[1] * A.m[1] + A.m[2] * A.m[2]);
    }
  }
  for (int a = 0; a < 4 && adj[a] >= 0; ++a) {
    AdjacentFaces::Face& A = faces.face[a];
    if (A.off) continue;  // not a face of the surface (yet, or any more)
    // The normal decides first whether the face matters at all.
    bool facing = false;
    for (int j = 0; j < nf; ++j)
      facing = facing || fn[3 * j] * A.m[0] + fn[3 * j + 1] * A.m[1] + fn[3 * j + 2] * A.m[2] <
                             kOpposedNormals * A.m_len;
    if (!facing) continue;
    const auto q = static_cast<std::size_t>(adj[a]);
    if (!A.framed) {
      double corners[4][3];
      gather_segment(x, &surf_.seg_nodes[4 * q], corners);
      segment_frame(corners, depth_[q], A.frame);
      A.framed = true;
    }
    // o: distance of the node in front of that face's plane (< 0: behind it); band: how far the
    // segment's edge tolerance reaches past the shared edge (the hexahedron's thickness normal
    // to that face times edge_tolerance).
    const double o = project_on_segment(A.frame, px, py, pz).gap - thick;
    const double band = cfg_.edge_tolerance * surf_.seg_elem_thickness[q];
    const bool closest = o <= 0 && pen <= -o;
    const bool kept = in_contact && pen <= band;
    if (!closest && !kept) return true;
  }
  return false;
}

bool PenaltyContact::nodes_to_read(const std::uint8_t* owned, const double* x0, double halo,
                                   std::vector<std::int32_t>& out) const {
  halo_ = halo;
  // Cells of size `halo` holding an owned surface node, and their neighbours: a segment with a
  // corner in one of them is within 2 sqrt(3) halo of an owned node (at least `halo`).
  const auto key = [&](const double* p) {
    std::array<std::int64_t, 3> c;
    for (int k = 0; k < 3; ++k) c[k] = static_cast<std::int64_t>(std::floor(p[k] / halo));
    return c;
  };
  const auto pack = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return ((i & 0x1FFFFF) << 42) | ((j & 0x1FFFFF) << 21) | (k & 0x1FFFFF);
  };
  std::unordered_set<std::int64_t> near;
  for (std::size_t e = 0; e < surf_.n_nodes(); ++e) {
    const auto i = static_cast<std::size_t>(surf_.node[e]);
    if (!owned[i]) continue;
    const auto c = key(x0 + 3 * i);
    for (std::int64_t a = -1; a <= 1; ++a)
      for (std::int64_t b = -1; b <= 1; ++b)
        for (std::int64_t d = -1; d <= 1; ++d) near.insert(pack(c[0] + a, c[1] + b, c[2] + d));
  }
  for (std::size_t s = 0; s < surf_.n_segments(); ++s) {
    bool in = false;
    for (int k = 0; k < 4 && !in; ++k) {
      const auto c = key(x0 + 3 * static_cast<std::size_t>(surf_.seg_nodes[4 * s + k]));
      in = near.count(pack(c[0], c[1], c[2])) > 0;
    }
    if (in)  // the whole hexahedron: the closest-feature test reads its other faces
      out.insert(out.end(), &surf_.seg_elem_nodes[8 * s], &surf_.seg_elem_nodes[8 * s] + 8);
  }
  return true;
}

void PenaltyContact::restrict_to_rank(const std::uint8_t* owned, const std::uint8_t* readable) {
  node_mine_.assign(surf_.n_nodes(), 0);
  for (std::size_t e = 0; e < surf_.n_nodes(); ++e)
    node_mine_[e] = owned[static_cast<std::size_t>(surf_.node[e])];
  n_mine_ = static_cast<std::size_t>(std::count(node_mine_.begin(), node_mine_.end(), 1));
  node_readable_.clear();
  for (std::size_t e = 0; e < surf_.n_nodes(); ++e)
    if (readable[static_cast<std::size_t>(surf_.node[e])])
      node_readable_.push_back(static_cast<std::int32_t>(e));
  seg_remote_.assign(surf_.n_segments(), 0);
  frame_blocks_.clear();
  for (std::size_t s = 0; s < surf_.n_segments(); ++s) {
    for (int k = 0; k < 8; ++k)
      if (!readable[static_cast<std::size_t>(surf_.seg_elem_nodes[8 * s + k])]) seg_remote_[s] = 1;
    const std::size_t blk = s / kFrameLanes;
    if (!seg_remote_[s] && (frame_blocks_.empty() || frame_blocks_.back() != blk))
      frame_blocks_.push_back(blk);
  }
  seg_halo_edge_.assign(surf_.n_segments(), 0);
  for (std::size_t e = 0; e < surf_.n_nodes(); ++e) {
    bool edge = false;
    for (std::int32_t r = node_seg_start_[e]; r < node_seg_start_[e + 1]; ++r)
      edge = edge || seg_remote_[static_cast<std::size_t>(node_seg_[static_cast<std::size_t>(r)])];
    for (std::int32_t r = node_seg_start_[e]; edge && r < node_seg_start_[e + 1]; ++r) {
      const auto q = static_cast<std::size_t>(node_seg_[static_cast<std::size_t>(r)]);
      if (!seg_remote_[q]) seg_halo_edge_[q] = 1;
    }
  }
  collect_active_segments();
  box_lo_.resize(3 * active_seg_.size());
  box_hi_.resize(3 * active_seg_.size());
  resort_ = true;
}

// The broad phase, long by design (issue #44): its passes share the bucket arrays and the
// candidates' order, which the narrow phase's prefetching relies on.
void PenaltyContact::sort_segments(const double* x) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::size_t ng = n_groups_, n_node = surf_.n_nodes(), n_act = active_seg_.size();
  const double margin = margin_;
  const double lim = 1.0 + 2.0 * cfg_.edge_tolerance;  // the narrow phase's extended edge
  // Until the next sort each node moves less than reach = (margin - thickness) / 2, and a point
  // of a segment's face extended to lim, a combination of its corners with weights summing to
  // at most lim^2 in absolute value, less than lim^2 reach: a node farther than `far` (10 % over
  // that) from a flat face cannot come within the thickness of it before the next sort.
  const double far = cfg_.thickness + 0.55 * (1.0 + lim * lim) * (margin - cfg_.thickness);
  resort_ = false;
  checked_d_ = 0, travel_checked_ = travel_;
  // Frames of all segments, grown boxes of the active ones.
  if (frame_blocks_.empty()) {
    for (std::size_t blk = 0; blk < frame_.size() / kFrameLanes; ++blk) compute_frames(x, blk);
  } else {  // several ranks: the blocks holding a segment this rank reads
    for (auto blk : frame_blocks_) compute_frames(x, blk);
  }
  for (std::size_t a = 0; a < n_act; ++a) {
    const auto s = static_cast<std::size_t>(active_seg_[a]);
    double p[4][3];
    gather_segment(x, &surf_.seg_nodes[4 * s], p);
    for (int k = 0; k < 3; ++k) {
      const double lo = std::min({p[0][k], p[1][k], p[2][k], p[3][k]});
      const double hi = std::max({p[0][k], p[1][k], p[2][k], p[3][k]});
      box_lo_[3 * a + k] = lo - margin;
      box_hi_[3 * a + k] = hi + margin;
    }
  }
  grid_.build(n_act, box_lo_.data(), box_hi_.data());

  // Facets of every surface node: its adjacent segment normals, clustered (in segment order, so
  // the facet numbering, and with it the friction state, is stable from one sort to the next).
  facet_start_old_.swap(facet_start_);
  facet_state_old_.swap(facet_state_);
  facet_start_.resize(n_node + 1);
  facet_start_[0] = 0;
  for (std::size_t e = 0; e < n_node; ++e) {
    double sum[kMaxFacets][3] = {};
    double unit[kMaxFacets][3] = {};
    int nf = 0;
    const bool mine = node_mine_.empty() || node_mine_[e];  // another rank's node: no facets
    for (std::int32_t r = node_seg_start_[e]; mine && r < node_seg_start_[e + 1]; ++r) {
      const auto q = static_cast<std::size_t>(node_seg_[static_cast<std::size_t>(r)]);
      if (seg_off(q)) continue;  // a node left without segments (or inside) faces nothing
      const double* n = frame_[q].n;
      int best = -1;
      double best_dot = -2;
      for (int j = 0; j < nf; ++j) {
        const double d = unit[j][0] * n[0] + unit[j][1] * n[1] + unit[j][2] * n[2];
        if (d > best_dot) best_dot = d, best = j;
      }
      if (best < 0 || (best_dot < kSameFacet && nf < kMaxFacets)) best = nf++;
      double len = 0;
      for (int k = 0; k < 3; ++k) sum[best][k] += n[k], len += sum[best][k] * sum[best][k];
      len = len > 0 ? 1.0 / std::sqrt(len) : 0.0;
      for (int k = 0; k < 3; ++k) unit[best][k] = sum[best][k] * len;
    }
    n_facets_[e] = static_cast<std::uint8_t>(nf);
    facet_start_[e + 1] = facet_start_[e] + nf;
    for (int j = 0; j < kMaxFacets; ++j)
      for (int k = 0; k < 3; ++k)
        facet_[(kMaxFacets * e + static_cast<std::size_t>(j)) * 3 + static_cast<std::size_t>(k)] =
            unit[j][k];
  }

  force_node_.resize(n_node);
  facet_node_.resize(static_cast<std::size_t>(facet_start_[n_node]));
  for (std::size_t e = 0; e < n_node; ++e) {
    force_node_[e] = {surf_.node[e], surf_.node_group[e], facet_start_[e], n_facets_[e]};
    for (std::int32_t k = facet_start_[e]; k < facet_start_[e + 1]; ++k)
      facet_node_[static_cast<std::size_t>(k)] = static_cast<std::int32_t>(e);
  }

  // Friction state and last contact segment carried over facet by facet.
  facet_state_.assign(static_cast<std::size_t>(facet_start_[n_node]), FacetState{});
  if (!facet_state_old_.empty()) {
    for (std::size_t e = 0; e < n_node; ++e) {
      const auto f_new = static_cast<std::size_t>(facet_start_[e]);
      const auto f_old = static_cast<std::size_t>(facet_start_old_[e]);
      const auto n_keep = static_cast<std::size_t>(std::min(
          facet_start_old_[e + 1] - facet_start_old_[e], facet_start_[e + 1] - facet_start_[e]));
      for (std::size_t k = 0; k < n_keep; ++k)
        facet_state_[f_new + k] = facet_state_old_[f_old + k];
    }
  }

  // Candidates of every surface node.
  cand_seg_.clear();
  cand_facet_.clear();
  const std::int32_t* items = grid_.items();
  for (std::size_t e = 0; e < n_node; ++e) {
    cand_start_[e] = static_cast<std::int32_t>(cand_seg_.size());
    const auto i = static_cast<std::size_t>(surf_.node[e]);
    const double* p = x + 3 * i;
    for (int k = 0; k < 3; ++k) x_sorted_[3 * e + k] = p[k];
    if (!node_mine_.empty() && !node_mine_[e]) continue;  // another rank's node
    const int nf = n_facets_[e];
    const double* fn = &facet_[3 * kMaxFacets * e];
    const std::size_t row = static_cast<std::size_t>(surf_.node_group[e]) * ng;
    std::int32_t b = 0, end = 0;
    if (!grid_.cell_of(p, b, end)) continue;
    for (std::int32_t it = b; it < end; ++it) {
      const auto a = static_cast<std::size_t>(items[it]);
      if (p[0] < box_lo_[3 * a] || p[0] > box_hi_[3 * a] || p[1] < box_lo_[3 * a + 1] ||
          p[1] > box_hi_[3 * a + 1] || p[2] < box_lo_[3 * a + 2] || p[2] > box_hi_[3 * a + 2])
        continue;
      const auto s = static_cast<std::size_t>(active_seg_[a]);
      if (pair_of_[row + static_cast<std::size_t>(surf_.seg_group[s])] < 0) continue;
      const SegmentFrame& f = frame_[s];
      const double* sn = f.n;
      int facet = -1;
      double most_opposed = kOpposedNormals;
      for (int j = 0; j < nf; ++j) {
        const double d = fn[3 * j] * sn[0] + fn[3 * j + 1] * sn[1] + fn[3 * j + 2] * sn[2];
        if (d < most_opposed) most_opposed = d, facet = j;
      }
      if (facet < 0) continue;  // faces none of the node's facets
      const double g = (p[0] - f.c[0]) * sn[0] + (p[1] - f.c[1]) * sn[1] + (p[2] - f.c[2]) * sn[2];
      if (g < -(f.depth + margin))
        continue;  // behind the segment: out of reach until the next sort
      // In front of a flat segment, or beside it, by more than `far`, measured in its own frame:
      // out of reach until the next sort, as the box test says of a face along the axes (a face
      // at 45 deg to them, as a +-45 ply's are, has a box reaching far beside it: a third of the
      // candidates it let through were over 0.1 mm beside their segment). Beside: past the
      // narrow phase's extended edge (lim), the distance to the line |xi| = lim being
      // (|xi| - lim) / |e1|. Warped or skewed faces (a twisted tow in a sheared picture frame),
      // whose projection is not the distance, and degenerate frames are left to the box.
      if (far > 0 && std::abs(f.hn) <= margin && std::abs(f.he1) <= 0.5 && std::abs(f.he2) <= 0.5) {
        const SegmentProjection pr = project_on_segment(f, p[0], p[1], p[2]);
        if (pr.gap > far) continue;
        const double l1 = f.e1[0] * f.e1[0] + f.e1[1] * f.e1[1] + f.e1[2] * f.e1[2];
        const double l2 = f.e2[0] * f.e2[0] + f.e2[1] * f.e2[1] + f.e2[2] * f.e2[2];
        if (std::abs(pr.xi) - lim > far * std::sqrt(l1) && l1 > 0) continue;
        if (std::abs(pr.eta) - lim > far * std::sqrt(l2) && l2 > 0) continue;
      }
      const std::int32_t* en = &surf_.seg_elem_nodes[8 * s];
      bool own = false;
      for (int k = 0; k < 8; ++k) own = own || en[k] == static_cast<std::int32_t>(i);
      if (own) continue;  // a face of an element holding the node
      if (!seg_halo_edge_.empty() && seg_halo_edge_[s])
        throw NumericalError(
            "contact '" + cfg_.name + "': surface node " + std::to_string(i + 1) + " at (" +
            std::to_string(p[0]) + ", " + std::to_string(p[1]) + ", " + std::to_string(p[2]) +
            ") m reached the edge of the segments this rank reads (those within [parallel] "
            "contact_halo = " +
            std::to_string(halo_) +
            " m of its surface nodes when the halo was last built): the surfaces slid about "
            "that far relative to each other across the partition since, or the halo is small "
            "for this mesh, and contacts beyond it would be missed; raise "
            "parallel.contact_halo, lower parallel.contact_halo_refresh (not 0) or run on fewer "
            "ranks");
      cand_seg_.push_back(static_cast<std::int32_t>(s));
      cand_facet_.push_back(static_cast<std::uint8_t>(facet));
    }
  }
  cand_start_[n_node] = static_cast<std::int32_t>(cand_seg_.size());

  // The same candidates segment by segment (a counting sort, stable: nodes in increasing order),
  // for the cycle's narrow phase, which walks the segments once.
  {
    const std::size_t n_seg = surf_.n_segments();
    seg_count_.assign(n_seg + 1, 0);
    for (auto q : cand_seg_) ++seg_count_[static_cast<std::size_t>(q) + 1];
    used_seg_.clear();
    used_cand_start_.clear();
    for (std::size_t q = 0; q < n_seg; ++q)
      if (seg_count_[q + 1] > 0) used_seg_.push_back(static_cast<std::int32_t>(q));
    for (std::size_t q = 0; q < n_seg; ++q) seg_count_[q + 1] += seg_count_[q];
    for (auto q : used_seg_) used_cand_start_.push_back(seg_count_[static_cast<std::size_t>(q)]);
    used_cand_start_.push_back(seg_count_[n_seg]);
    const std::size_t n_cand = cand_seg_.size();
    ucand_node_.resize(n_cand);
    ucand_.resize(n_cand);
    for (std::size_t e = 0; e < n_node; ++e)
      for (std::int32_t c = cand_start_[e]; c < cand_start_[e + 1]; ++c) {
        const auto q = static_cast<std::size_t>(cand_seg_[static_cast<std::size_t>(c)]);
        const auto r = static_cast<std::size_t>(seg_count_[q]++);
        ucand_node_[r] = static_cast<std::int32_t>(e);
        ucand_[r] = {surf_.node[e], facet_start_[e] + cand_facet_[static_cast<std::size_t>(c)]};
      }
    best_.assign(static_cast<std::size_t>(facet_start_[n_node]), BestHit{});
    seed_last_segments();
  }
  ++stats_.n_sorts;
  stats_.n_candidates = static_cast<std::int64_t>(cand_seg_.size());
  stats_.sort_seconds +=
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

namespace {
constexpr double kStick = 1e-4;
}

// A kernel, long by design (issue #44): the narrow phase and the force pass share the hit
// records and the batch while they are in cache.
void PenaltyContact::add_forces(const double* x, const double* v, const double*, double dt,
                                double* f) {
  const std::size_t n_node = surf_.n_nodes(), ng = n_groups_;
  ++stats_.n_cycles;
  using Clock = std::chrono::steady_clock;
  auto seconds = [](Clock::time_point a, Clock::time_point b) {
    return std::chrono::duration<double>(b - a).count();
  };
  const auto t0 = Clock::now();

  // 1. Broad phase when a node may have come within reach of a segment it does not know. The
  // check measures every node's displacement since the last sort; while the solver's bound on
  // the nodes' travel (set_node_travel) has not grown by what the last check left of `reach`,
  // no node can have got there, and the check is skipped (the same sorts, the same results).
  const double reach = 0.5 * (margin_ - cfg_.thickness);
  if (resort_ || travel_ < 0 || travel_checked_ < 0 ||
      checked_d_ + (travel_ - travel_checked_) >= reach) {
    double d2 = 0;
    const std::int32_t* node = surf_.node.data();
    const double* xs = x_sorted_.data();
    const auto moved = [&](std::size_t e) {
      const double* p = x + 3 * static_cast<std::size_t>(node[e]);
      const double dx = p[0] - xs[3 * e], dy = p[1] - xs[3 * e + 1], dz = p[2] - xs[3 * e + 2];
      d2 = std::max(d2, dx * dx + dy * dy + dz * dz);
    };
    if (node_readable_.empty()) {
      for (std::size_t e = 0; e < n_node; ++e) moved(e);
    } else {  // several ranks: the nodes this rank reads (the others do not move here)
      for (auto e : node_readable_) moved(static_cast<std::size_t>(e));
    }
    stats_.check_seconds += seconds(t0, Clock::now());
    ++stats_.n_checks;
    checked_d_ = std::sqrt(d2), travel_checked_ = travel_;
    if (resort_ || d2 > reach * reach) sort_segments(x);  // then x_sorted_ = x: checked_d_ 0
  }
  const auto t1 = Clock::now();

  // 2. Narrow phase, segment by segment: the frames of kFrameLanes segments that have
  // candidates are made in SIMD lanes and each node listed under them is projected while the
  // frame is in registers; a facet keeps its best hit (largest gap). Then, node by node, the
  // facets' contacts go in batches through the branch-free force kernel (contact_forces) and
  // their forces are scattered.
  for (auto& F : pair_force_) F = {};
  const double thick = cfg_.thickness, lim = 1.0 + 2.0 * cfg_.edge_tolerance;
  const double kscale = cfg_.penalty_scale * inv_dt0_sq_;
  const double damp = 2.0 * cfg_.damping * std::sqrt(kscale);  // 2 zeta sqrt(k m_eff) / m_eff
  const std::uint8_t* n_facets = n_facets_.data();
  const double* m_node = node_mass_.data();
  const std::int32_t* sn = surf_.seg_nodes.data();
  const std::int32_t* sg = surf_.seg_group.data();
  const std::int32_t* seg_adj = seg_adjacent_.data();
  const double* mu_of = mu_of_.data();
  FacetState* state = facet_state_.data();
  BestHit* best = best_.data();  // all reset (seg -1) by the force pass of the last cycle
  {
    std::uint64_t* live = live_.data();
    const std::size_t n_used = used_seg_.size();
    const std::int32_t* used = used_seg_.data();
    const std::int32_t* ustart = used_cand_start_.data();
    const std::int32_t* unode = ucand_node_.data();
    const Candidate* ucand = ucand_.data();
    SegmentFrameBlock fb;
    AdjacentFaces adj_faces;
    // The candidates' positions and hits are scattered over the other plies' nodes: fetched
    // ahead, their misses overlap (at 245k contact nodes they were a third of the cycle).
    const std::int32_t n_cand = ustart[n_used];
    constexpr std::int32_t kAhead = 48;  // candidates
    const double* facet_normals = facet_.data();
    // The segments' corners likewise, a block ahead (their indices two blocks ahead): the frames'
    // gathers waited on them (7 % of the paper model's cycle).
    const auto fetch_corners = [&](std::size_t u, bool positions) {
      for (std::size_t k = u; k < std::min(u + kFrameLanes, n_used); ++k) {
        const std::int32_t* corner = sn + 4 * static_cast<std::size_t>(used[k]);
        if (!positions) {
          __builtin_prefetch(corner);
          continue;
        }
        for (int a = 0; a < 4; ++a) __builtin_prefetch(x + 3 * static_cast<std::size_t>(corner[a]));
      }
    };
    fetch_corners(0, true);
    fetch_corners(kFrameLanes, false);
    for (std::size_t u0 = 0; u0 < n_used; u0 += kFrameLanes) {
      const std::size_t n_lanes = std::min<std::size_t>(kFrameLanes, n_used - u0);
      fetch_corners(u0 + 2 * kFrameLanes, false);
      fetch_corners(u0 + kFrameLanes, true);
      block_frames(x, used + u0, n_lanes, fb);
      for (std::size_t l = 0; l < n_lanes; ++l) {
        const std::int32_t s = used[u0 + l];
        const std::int32_t* adj = seg_adj + 4 * static_cast<std::size_t>(s);
        const double d = fb.depth[l];
        const auto li = static_cast<int>(l);
        for (std::int32_t c = ustart[u0 + l]; c < ustart[u0 + l + 1]; ++c) {
          const std::int32_t ca = std::min(c + kAhead, n_cand - 1);
          __builtin_prefetch(x + 3 * static_cast<std::size_t>(ucand[ca].mesh_node));
          __builtin_prefetch(best + ucand[ca].facet, 1);
          // ... and its facets' normals, which the closest-feature test reads on a hit (their
          // miss was half of that test's time).
          __builtin_prefetch(facet_normals + 3 * kMaxFacets * static_cast<std::size_t>(unode[ca]));
          const auto fi = static_cast<std::size_t>(ucand[c].facet);
          const double* xp = x + 3 * static_cast<std::size_t>(ucand[c].mesh_node);
          const SegmentProjection pr = project_on_segment(fb, li, xp[0], xp[1], xp[2]);
          BestHit& B = best[fi];
          const double rank = pr.gap + (B.last == s ? kStick * d : 0.0);
          bool hit = (std::abs(pr.xi) <= lim) & (std::abs(pr.eta) <= lim) & (pr.gap < thick) &
                     (pr.gap > -d) & (rank > B.gap);
          // Closest feature (see closer_adjacent_face): a tow-end node lying on a thin tow's
          // top face also projects onto the tow's side face (at its top edge), up to half the
          // tow width 'deep', and its end facet faces that side: the top face is the contact,
          // the side is not.
          if (hit && adj[0] >= 0) {
            const auto e = static_cast<std::size_t>(unode[c]);
            hit = !closer_adjacent_face(x, s, adj, adj_faces, &facet_[3 * kMaxFacets * e],
                                        n_facets[e], xp[0], xp[1], xp[2], thick - pr.gap,
                                        B.last == s);
          }
          if (hit) {
            B.gap = rank;
            B.xi = static_cast<float>(pr.xi), B.eta = static_cast<float>(pr.eta);
            for (int k = 0; k < 3; ++k) B.n[k] = static_cast<float>(fb.n[k][l]);
            B.seg = s;
            live[fi >> 6] |= std::uint64_t{1} << (fi & 63);
          }
        }
      }
    }
  }
  ContactBatch& B = batch_;
  B.n = 0;
  std::int64_t n_active = 0, n_changes = 0;
  double max_pen = 0, dissipated = 0;
  std::int32_t max_pen_node = -1;
  auto flush = [&] {
    dissipated += contact_forces(B, kscale, damp, dt);
    for (int l = 0; l < B.n; ++l) {
      const double Fx = B.fx[l], Fy = B.fy[l], Fz = B.fz[l];
      const auto i = 3 * static_cast<std::size_t>(B.slave[l]);
      f[i] += Fx, f[i + 1] += Fy, f[i + 2] += Fz;
      const std::int32_t* corner = sn + 4 * static_cast<std::size_t>(B.seg[l]);
      for (int a = 0; a < 4; ++a) {
        const auto q = 3 * static_cast<std::size_t>(corner[a]);
        f[q] -= B.N[a][l] * Fx, f[q + 1] -= B.N[a][l] * Fy, f[q + 2] -= B.N[a][l] * Fz;
      }
      double* ft = state[B.state[l]].tang;
      ft[0] = B.tx[l], ft[1] = B.ty[l], ft[2] = B.tz[l];
      const auto cell = static_cast<std::size_t>(B.cell[l]);
      const double sgn = sign_of_[cell];
      V3& R = pair_force_[static_cast<std::size_t>(pair_of_[cell])];
      R.x += sgn * Fx, R.y += sgn * Fy, R.z += sgn * Fz;
    }
    B.n = 0;
  };
  // Only the facets in play are visited: those hit in this cycle's narrow phase and those in
  // contact in the last one (to end it). They are taken in increasing facet order, which is
  // surface-node order, so the forces are summed in the same order as a pass over every node.
  // Listed first, so that each one's hit record, its segment's corners and their velocities can
  // be fetched a few facets ahead (the corners' misses were a fifth of this function's time on
  // the paper model); the order, and so every sum, is that of the bits.
  const ForceNode* fnode = force_node_.data();
  const std::int32_t* facet_node = facet_node_.data();
  std::uint64_t* live = live_.data();
  live_list_.clear();
  for (std::size_t w = 0; w < live_.size(); ++w)
    for (std::uint64_t bits = live[w]; bits != 0; bits &= bits - 1)
      live_list_.push_back(static_cast<std::int32_t>(64 * w) + __builtin_ctzll(bits));
  const std::int32_t* lf = live_list_.data();
  const std::size_t n_live = live_list_.size();
  constexpr std::size_t kHitAhead = 16, kCornerAhead = 8, kVelocityAhead = 4;  // facets
  for (std::size_t k = 0; k < n_live; ++k) {
    if (k + kHitAhead < n_live) {
      __builtin_prefetch(best + lf[k + kHitAhead], 1);
      __builtin_prefetch(state + lf[k + kHitAhead], 1);
    }
    if (k + kCornerAhead < n_live)
      if (const std::int32_t q = best[lf[k + kCornerAhead]].seg; q >= 0)
        __builtin_prefetch(sn + 4 * static_cast<std::size_t>(q));
    if (k + kVelocityAhead < n_live)
      if (const std::int32_t q = best[lf[k + kVelocityAhead]].seg; q >= 0)
        for (int a = 0; a < 4; ++a) {
          const auto c = static_cast<std::size_t>(sn[4 * static_cast<std::size_t>(q) + a]);
          __builtin_prefetch(v + 3 * c);
          __builtin_prefetch(m_node + c);
        }
    const auto fi = static_cast<std::size_t>(lf[k]);
    const std::size_t w = fi >> 6;
    const auto bit = static_cast<unsigned>(fi & 63);
    const ForceNode R = fnode[facet_node[fi]];
    const auto i = static_cast<std::size_t>(R.mesh_node);
    FacetState& S = state[fi];
    double* ft = S.tang;
    const std::int32_t was = S.last;
    const BestHit F = best[fi];
    best[fi] = BestHit{};  // ready for the next cycle's narrow phase
    best[fi].last = F.seg;
    S.last = F.seg;
    if (F.seg < 0) {
      if (was >= 0) S = FacetState{};  // else zero
      live[w] &= ~(std::uint64_t{1} << bit);
      continue;
    }
    const double m_s = m_node[i];
    const double vsx = v[3 * i], vsy = v[3 * i + 1], vsz = v[3 * i + 2];
    const std::size_t row = static_cast<std::size_t>(R.group) * ng;
    ++n_active;
    n_changes += (was >= 0) & (was != F.seg);
    const auto s = static_cast<std::size_t>(F.seg);
    const std::int32_t* corner = sn + 4 * s;
    const int l = B.n++;
    double N[4];
    segment_shape(F.xi, F.eta, N);
    double m_m = 0, vmx = 0, vmy = 0, vmz = 0;
    for (int a = 0; a < 4; ++a) {
      const auto q = 3 * static_cast<std::size_t>(corner[a]);
      m_m += N[a] * m_node[corner[a]];
      vmx += N[a] * v[q], vmy += N[a] * v[q + 1], vmz += N[a] * v[q + 2];
      B.N[a][l] = N[a];
    }
    // The spring acts on the penetration past an offset, so that the force never jumps: a node
    // found already behind the surface (it came round a tow edge, or through a seam between
    // tows) starts from zero force, and at a switch to another segment the elastic part of
    // the penetration carries over. The offset only ever shrinks while the contact lasts (the
    // node withdrawing takes it with it), so the law can lose energy but never create it.
    const double gap = F.gap - (F.seg == was ? kStick * depth_[s] : 0.0);
    const double pen_geo = thick - gap;
    double off = was < 0        ? pen_geo
                 : was != F.seg ? std::max(pen_geo - S.elastic, 0.0)
                                : std::min(S.offset, pen_geo);
    off = std::max(off, 0.0);
    S.offset = off;
    const double pen = pen_geo - off;
    S.elastic = pen;
    if (pen_geo > max_pen) max_pen = pen_geo, max_pen_node = static_cast<std::int32_t>(i);
    const std::size_t cell = row + static_cast<std::size_t>(sg[s]);
    B.pen[l] = pen;
    B.nx[l] = F.n[0], B.ny[l] = F.n[1], B.nz[l] = F.n[2];
    B.m_s[l] = m_s, B.m_m[l] = m_m;
    B.rx[l] = vsx - vmx, B.ry[l] = vsy - vmy, B.rz[l] = vsz - vmz;
    B.mu[l] = mu_of[cell];
    B.tx[l] = ft[0], B.ty[l] = ft[1], B.tz[l] = ft[2];
    B.slave[l] = static_cast<std::int32_t>(i);
    B.seg[l] = static_cast<std::int32_t>(s);
    B.state[l] = static_cast<std::int32_t>(fi);
    B.cell[l] = static_cast<std::int32_t>(cell);
    if (B.n == kContactBatch) flush();
  }
  flush();
  dissipation_ += dissipated;
  stats_.n_active = n_active;
  stats_.n_contact_cycles += n_active;
  stats_.n_segment_changes += n_changes;
  stats_.max_penetration = max_pen;
  stats_.run_max_penetration = std::max(stats_.run_max_penetration, max_pen);
  stats_.max_penetration_node = max_pen_node;
  stats_.narrow_seconds += seconds(t1, Clock::now());
}

std::vector<ContactResultant> PenaltyContact::resultants() const {
  std::vector<ContactResultant> out;
  out.reserve(cfg_.pairs.size());
  for (std::size_t p = 0; p < cfg_.pairs.size(); ++p) {
    const auto& a = cfg_.groups[static_cast<std::size_t>(cfg_.pairs[p].first)].name;
    const auto& b = cfg_.groups[static_cast<std::size_t>(cfg_.pairs[p].second)].name;
    out.push_back({a + "__" + b, pair_force_[p]});
  }
  return out;
}

void PenaltyContact::save_state(CheckpointWriter& w) const {
  const std::size_t nf = facet_state_.size();
  std::vector<double> tang(3 * nf), offset(nf), elastic(nf);
  std::vector<std::int32_t> last(nf);
  for (std::size_t k = 0; k < nf; ++k) {
    const FacetState& f = facet_state_[k];
    for (int c = 0; c < 3; ++c) tang[3 * k + static_cast<std::size_t>(c)] = f.tang[c];
    offset[k] = f.offset, elastic[k] = f.elastic, last[k] = f.last;
  }
  save_array(w, "facet_tangential", tang);
  save_array(w, "facet_offset", offset);
  save_array(w, "facet_elastic", elastic);
  save_array(w, "facet_last", last);
  save_array(w, "facet_start", facet_start_);
  save_array(w, "x_sorted", x_sorted_);
  save_array(w, "seg_eroded", seg_eroded_);
  save_array(w, "seg_dormant", seg_dormant_);
  w.write_int("resort", resort_ ? 1 : 0);
  w.write_double("dissipation", dissipation_);
  std::vector<double> pf;
  for (const V3& f : pair_force_) pf.insert(pf.end(), {f.x, f.y, f.z});
  save_array(w, "pair_force", pf);
  const std::vector<std::int64_t> counts = {stats_.n_cycles, stats_.n_sorts, stats_.n_candidates,
                                            stats_.n_active, stats_.max_penetration_node};
  const std::vector<double> values = {stats_.max_penetration, stats_.run_max_penetration,
                                      stats_.sort_seconds, stats_.check_seconds,
                                      stats_.narrow_seconds};
  save_array(w, "stats_counts", counts);
  save_array(w, "stats_values", values);
}

void PenaltyContact::seed_last_segments() {
  const std::size_t n = std::min(best_.size(), facet_state_.size());
  live_.assign((best_.size() + 63) / 64, 0);
  live_list_.reserve(best_.size());  // no allocation in the cycles
  for (std::size_t k = 0; k < n; ++k) {
    best_[k].last = facet_state_[k].last;
    if (facet_state_[k].last >= 0) live_[k >> 6] |= std::uint64_t{1} << (k & 63);
  }
}

void PenaltyContact::load_state(CheckpointReader& r) {
  const std::size_t n_node = surf_.n_nodes();
  load_array(r, "seg_eroded", seg_eroded_);
  load_array(r, "seg_dormant", seg_dormant_);
  collect_active_segments();
  box_lo_.resize(3 * active_seg_.size());
  box_hi_.resize(3 * active_seg_.size());
  // The sort at the saved positions of the surface nodes (every segment corner is one; no other
  // position is read) rebuilds what the last sort made. With a sort pending (an erosion since
  // then) the next cycle sorts again from the saved facet layout.
  load_array(r, "x_sorted", x_sorted_);
  {
    std::vector<double> x(3 * node_mass_.size(), 0.0);
    for (std::size_t e = 0; e < n_node; ++e)
      for (std::size_t k = 0; k < 3; ++k)
        x[3 * static_cast<std::size_t>(surf_.node[e]) + k] = x_sorted_[3 * e + k];
    sort_segments(x.data());
  }
  const bool resort = r.read_int("resort") != 0;
  std::vector<std::int32_t> start;
  r.read_array("facet_start", start, n_node + 1);
  if (!resort && start != facet_start_)
    r.mismatch("facet_start", "the surface sorted at the saved positions has other node facets");
  facet_start_ = start;
  const auto nf = static_cast<std::size_t>(facet_start_[n_node]);
  std::vector<double> tang, offset, elastic;
  std::vector<std::int32_t> last;
  r.read_array("facet_tangential", tang, 3 * nf);
  r.read_array("facet_offset", offset, nf);
  r.read_array("facet_elastic", elastic, nf);
  r.read_array("facet_last", last, nf);
  facet_state_.assign(nf, FacetState{});
  for (std::size_t k = 0; k < nf; ++k) {
    FacetState& f = facet_state_[k];
    for (int c = 0; c < 3; ++c) f.tang[c] = tang[3 * k + static_cast<std::size_t>(c)];
    f.offset = offset[k], f.elastic = elastic[k], f.last = last[k];
  }
  seed_last_segments();
  resort_ = resort;
  travel_checked_ = -1;  // the solver's travel bound starts anew: the next cycle checks
  dissipation_ = r.read_double("dissipation");
  std::vector<double> pf;
  r.read_array("pair_force", pf, 3 * pair_force_.size());
  for (std::size_t k = 0; k < pair_force_.size(); ++k)
    pair_force_[k] = {pf[3 * k], pf[3 * k + 1], pf[3 * k + 2]};
  std::vector<std::int64_t> counts;
  std::vector<double> values;
  r.read_array("stats_counts", counts, 5);
  r.read_array("stats_values", values, 5);
  stats_.n_cycles = counts[0], stats_.n_sorts = counts[1], stats_.n_candidates = counts[2];
  stats_.n_active = counts[3], stats_.max_penetration_node = static_cast<std::int32_t>(counts[4]);
  stats_.max_penetration = values[0], stats_.run_max_penetration = values[1];
  stats_.sort_seconds = values[2], stats_.check_seconds = values[3];
  stats_.narrow_seconds = values[4];
}

std::string PenaltyContact::cost_details() const {
  const double n = static_cast<double>(std::max<std::size_t>(n_contact_nodes(), 1));
  std::ostringstream os;
  os.precision(3);
  os << "candidates per node " << static_cast<double>(stats_.n_candidates) / n
     << ", active contacts per node " << static_cast<double>(active_contacts()) / n
     << ", segment changes per contact-cycle "
     << static_cast<double>(stats_.n_segment_changes) /
            static_cast<double>(std::max<std::int64_t>(stats_.n_contact_cycles, 1))
     << "; bucket sorts " << stats_.sort_seconds << " s, displacement checks "
     << stats_.check_seconds << " s (" << stats_.n_checks
     << " made, the others skipped on the travel bound), narrow phase and forces "
     << stats_.narrow_seconds << " s";
  return os.str();
}

}  // namespace ncfsim::fem
