#pragma once
// Node-to-segment penalty contact between deformable hexahedral surfaces, with self-contact and
// regularised Coulomb friction (an elastic tangential spring capped at mu times the normal force,
// as for the rigid tools).
//
// Each cycle:
//  1. Broad phase, only when needed: the largest nodal displacement since the last bucket sort
//     is checked; when 2 d_max > search_margin - thickness the segments (boxes grown by the
//     margin) are sorted into a uniform grid and each surface node gets its candidate segments
//     (CSR): pair active, node not far behind the segment, segment not a face of an element
//     holding the node, and the segment facing one of the node's facets. A node's facets are
//     the directions of its own surface around it (adjacent segment normals clustered within
//     45 deg): one on a flat or gently curved surface, two on an edge, three at a corner. A
//     candidate faces facet j when n_facet_j . n_segment < -0.5 (opposed within 60 deg).
//  2. Narrow phase, segment by segment (the candidates are also kept grouped by segment): the
//     frames (centre, normal, dual tangents; SegmentFrame) of kFrameLanes segments that have
//     candidates are made in SIMD lanes, and every node listed under them is projected while
//     the frames are in registers. Each cycle reads positions and the candidate lists only; no
//     frame is stored, so nothing is fetched twice from memory.
//  3. Per surface node and facet the contact is the segment the node projects into (with
//     edge_tolerance) with the largest gap below `thickness` and above -depth (the facet's
//     segment of the last cycle ranked 1e-4 depth higher, so ties do not flip), and that passes
//     the closest-feature test against the other faces of its hexahedron (closer_adjacent_face:
//     a node on a thin tow's top face is not pushed out through the tow's side). One contact per
//     facet: a node on the edge of one tow, pinched between the next tow's side and the ply
//     above, is pushed by both; a node on a flat surface over a seam between two segments is
//     pushed once.
//  4. Forces of the active contacts in batches (contact_forces, a branch-free SIMD kernel):
//     normal k (thickness - gap - offset) plus damping that never pulls, friction from the
//     relative tangential velocity with an elastic spring per node facet; the force goes on the
//     node and, weighted by the shape functions, on the segment corners (they sum to zero:
//     momentum is conserved). The offset keeps the force continuous: it is the penetration at
//     which a facet's contact began (a node found already behind a surface, having come round a
//     tow edge or through a seam, starts from zero force), it is reset at a switch of segment so
//     that the elastic penetration carries over, and it only shrinks while the contact lasts. So
//     the penalty stores energy and never creates it (k fixed from dt0); what friction and
//     damping take is reported by friction_dissipation().
// Cost is linear in the number of surface nodes; nothing is allocated per cycle (the sort reuses
// its arrays). Masses are read once in initialise() (they do not change after assembly), so the
// `mass` argument of add_forces is not used.
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include "fem/contact/bucket_grid.hpp"
#include "fem/contact/contact_config.hpp"
#include "fem/contact/contact_force_kernel.hpp"
#include "fem/contact/contact_surface.hpp"
#include "fem/contact/segment_frame.hpp"
#include "fem/contact_interface.hpp"

namespace ncfsim::fem {

/// Counters of a penalty contact (diagnostics, benchmarks).
struct PenaltyContactStats {
  std::int64_t n_cycles = 0;
  std::int64_t n_sorts = 0;                // bucket sorts (broad-phase rebuilds), incl. the first
  std::int64_t n_candidates = 0;           // node-segment candidates after the last sort
  std::int64_t n_active = 0;               // contacts in the last cycle
  double max_penetration = 0;              // largest (thickness - gap) in the last cycle, m
  double run_max_penetration = 0;          // ... over every cycle so far, m
  std::int32_t max_penetration_node = -1;  // mesh node where it occurs
  double sort_seconds = 0;                 // time in bucket sorts (broad phase)
  double check_seconds = 0;                // time in the displacement checks
  std::int64_t n_checks = 0;  // displacement checks made since this process started (the others
                              // were skipped on the solver's travel bound: set_node_travel)
  double narrow_seconds = 0;  // time in the narrow phase (incl. segment frames) and forces
  // Since the start (or the resume) of the run: contacts summed over cycles, and how many of them
  // moved to another segment than the cycle before (a vibrating interface near facet corners
  // changes often, and costs more per node: docs/performance.md).
  std::int64_t n_contact_cycles = 0;
  std::int64_t n_segment_changes = 0;
};

class PenaltyContact final : public ContactAlgorithm {
 public:
  static constexpr int kMaxFacets = 3;

  /// Checks the configuration's ranges (InputError); the mesh is checked in initialise().
  explicit PenaltyContact(PenaltyContactConfig config);

  const std::string& name() const override { return cfg_.name; }
  void initialise(const ContactSetup& setup) override;
  double estimated_bytes(const Mesh& mesh, bool erosion) const override;
  void add_forces(const double* x, const double* v, const double* mass, double dt,
                  double* f_contact) override;
  double friction_dissipation() const override { return dissipation_; }
  std::vector<ContactResultant> resultants() const override;
  std::int64_t active_contacts() const override { return stats_.n_active; }
  double max_penetration() const override { return stats_.run_max_penetration; }
  /// Faces of eroded hexahedra leave the surface; the faces of their neighbours in the same group
  /// that they covered join it (set up when the solver erodes: ContactSetup::erosion).
  void erode(const std::vector<std::int32_t>& mesh_elements) override;
  /// Saves the facets' friction state, the positions of the last sort and the segment flags;
  /// load_state sorts again at the saved positions (the sort reads nothing else), which rebuilds
  /// the candidates, frames and grid exactly, then overwrites the friction state.
  /// Several ranks: the segments (with their hexahedra) near this rank's surface nodes.
  bool nodes_to_read(const std::uint8_t* owned, const double* x0, double halo,
                     std::vector<std::int32_t>& out) const override;
  /// Several ranks: candidates only for owned surface nodes, among readable segments.
  void restrict_to_rank(const std::uint8_t* owned, const std::uint8_t* readable) override;
  void save_state(CheckpointWriter& w) const override;
  void load_state(CheckpointReader& r) override;

  const PenaltyContactConfig& config() const { return cfg_; }
  const ContactSurface& surface() const { return surf_; }
  const PenaltyContactStats& stats() const { return stats_; }
  double search_margin() const { return margin_; }
  /// The surface nodes this rank searches: all, or those it owns after restrict_to_rank.
  std::size_t n_contact_nodes() const override {
    return node_mine_.empty() ? surf_.n_nodes() : n_mine_;
  }
  std::int64_t n_broad_phase_searches() const override { return stats_.n_sorts; }
  std::string cost_details() const override;
  void set_node_travel(double travel) override { travel_ = travel; }

 private:
  void sort_segments(const double* x);                      // broad phase at positions x
  void compute_frames(const double* x, std::size_t block);  // frames of one block at x (sort)
  /// Frames at x of the n <= kFrameLanes segments seg[0..n) in SIMD lanes (the rest padded).
  void block_frames(const double* x, const std::int32_t* seg, std::size_t n,
                    SegmentFrameBlock& fb) const;
  /// The outer faces adjacent to segment `seg` (adj[4] of it), as closer_adjacent_face reads
  /// them: made at the first hit on the segment in a cycle's narrow phase and kept for its other
  /// candidates (they are listed together), each frame once a node faces that face. The same
  /// arithmetic as making them for each hit: the same results bit for bit.
  struct AdjacentFaces {
    std::int32_t seg = -1;  // the segment they are adjacent to (-1: none yet)
    struct Face {
      bool off = true;  // not a face of the surface (yet, or any more)
      bool framed = false;
      double m[3] = {}, m_len = 0;  // d1 x d2 and its length
      SegmentFrame frame;
    } face[4];
  };
  /// Closest-feature test of a contact of penetration pen on a segment, against the outer faces
  /// adjacent to it in the same hexahedron (adj[4], -1 padded; `faces` made of them) that are
  /// opposed to one of the node's nf facets (fn[nf][3]). True (not the contact) when, for such a
  /// face, the node at p is neither behind its plane by at least pen (then the segment is the
  /// nearest way out) nor holding this contact from the last cycle (in_contact) with pen <=
  /// edge_tolerance * the hexahedron's thickness normal to that face (a node sliding past the
  /// convex edge into the segment's edge-tolerance band keeps its contact; one arriving there from
  /// the side, or deep behind the segment's plane but outside the body, gets none).
  bool closer_adjacent_face(const double* x, std::int32_t seg, const std::int32_t* adj,
                            AdjacentFaces& faces, const double* fn, int nf, double px, double py,
                            double pz, double pen, bool in_contact);

  PenaltyContactConfig cfg_;
  ContactSurface surf_;
  std::size_t n_groups_ = 0;
  std::vector<std::int32_t> pair_of_;  // [n_groups][n_groups] pair index or -1
  std::vector<double> mu_of_;          // [n_groups][n_groups] friction coefficient
  std::vector<double> sign_of_;        // [n_groups][n_groups] +1: slave group is the pair's first
  double margin_ = 0;                  // search margin, m
  double inv_dt0_sq_ = 0;              // 1 / dt0^2
  std::vector<double> depth_;          // [n_seg] max_penetration * element thickness
  std::vector<std::int32_t> seg_adjacent_;  // [n_seg][4] surface faces of the same hexahedron
                                            // sharing an edge, -1 padded

  // State and work arrays, sized in initialise(), reused every cycle.
  std::vector<double> x_sorted_;  // [n_snode][3] positions at the last sort
  /// Contact state of a node facet carried from cycle to cycle (one record, not four arrays:
  /// the force pass reads and writes it for every facet).
  struct FacetState {
    double tang[3] = {0, 0, 0};  // elastic friction force, N
    double offset = 0;           // penetration offset of the contact (no force jump), m
    double elastic = 0;          // penetration past the offset in the last cycle, m
    std::int32_t last = -1;      // contact segment in the last cycle, -1: none
  };
  /// What the force pass reads of each surface node, in one record (made at the sort).
  struct ForceNode {
    std::int32_t mesh_node, group, facet_start, n_facets;
  };
  std::vector<ForceNode> force_node_;        // [n_snode]
  std::vector<std::int32_t> facet_node_;     // [n_facet] its surface node
  /// [n_facet bits] facets in play: hit in this cycle's narrow phase, or in contact in the last
  /// cycle. The force pass visits only these (on a fabric ~0.1 contacts per node: a pass over
  /// every surface node's records, on every rank over the whole model's, was most of its cost).
  std::vector<std::uint64_t> live_;
  std::vector<std::int32_t> live_list_;  // the facets of live_ in a cycle's force pass, in order
  std::vector<FacetState> facet_state_;      // [n_facet]
  std::vector<FacetState> facet_state_old_;  // before the last sort (carried over)
  std::vector<std::int32_t> facet_start_;    // [n_snode + 1] first facet of each surface node
  std::vector<std::int32_t> facet_start_old_;
  std::vector<double> node_mass_;         // [n_nodes] lumped nodal masses (fixed after set-up), kg
  std::vector<std::int32_t> cand_start_;  // [n_snode + 1] CSR into cand_seg_ (at the sort)
  std::vector<std::int32_t> cand_seg_;    // candidate segments, node by node
  std::vector<std::uint8_t> cand_facet_;  // facet of the node each candidate faces
  // The candidates segment by segment (what the cycle reads): segments with candidates in
  // increasing order, CSR into ucand_ (mesh node and facet of each candidate, one record) and
  // ucand_node_ (its surface node, only for the closest-feature test).
  struct Candidate {
    std::int32_t mesh_node;  // what the projection reads
    std::int32_t facet;      // global index of the node facet it faces
  };
  std::vector<std::int32_t> used_seg_, used_cand_start_, ucand_node_;
  std::vector<Candidate> ucand_;
  std::vector<std::int32_t> seg_count_;  // [n_seg + 1] work array of the counting sort
  /// Best hit of a node facet in the current cycle: one record of 40 bytes per facet (was three
  /// arrays), written by the narrow phase and read, then reset, by the force pass.
  /// Local coordinates and normal in single precision: they only place and orient the force,
  /// the same values on the node and on the segment (momentum stays exact).
  /// The gap is a ranking key: the facet's segment of the last cycle (`last`) gets a head start
  /// of kStick x its depth, so that a node near the corner of facets with equal gaps keeps its
  /// segment instead of changing it with each vibration (the force pass takes the start off).
  struct BestHit {
    double gap = -std::numeric_limits<double>::max();
    std::int32_t last = -1;  // the facet's segment in the last cycle (-1: none)
    std::int32_t seg = -1;   // -1: no contact this cycle
    float xi = 0, eta = 0;   // local coordinates on the segment
    float n[3] = {0, 0, 0};  // the segment's unit normal
  };
  std::vector<BestHit> best_;            // [n_facet]
  void seed_last_segments();             // best_[k].last from facet_state_ (sort, restart)
  std::vector<SegmentFrame> frame_;      // [n_blocks * kFrameLanes] all frames, made at the sort
  std::vector<double> box_lo_, box_hi_;  // [n_seg][3] grown segment boxes at the sort
  std::vector<double> facet_;            // [n_snode][kMaxFacets][3] facet normals at the sort
  std::vector<std::uint8_t> n_facets_;   // [n_snode]
  std::vector<std::int32_t> node_seg_start_, node_seg_;  // segments around each surface node (CSR)
  std::vector<std::int32_t> active_seg_;   // [n_seg] index into segs of the grid (active groups)
  std::vector<std::uint8_t> seg_eroded_;   // [n_seg] 1: its hexahedron was eroded
  std::vector<std::uint8_t> seg_dormant_;  // [n_seg] 1: an inner face still covered (erosion)
  std::vector<std::uint8_t> seg_in_pair_;  // [n_seg] 1: its group is in a pair
  /// Rebuilds active_seg_: segments of paired groups neither eroded nor dormant.
  void collect_active_segments();
  bool seg_off(std::size_t s) const {
    return seg_eroded_[s] || seg_dormant_[s] || (!seg_remote_.empty() && seg_remote_[s]);
  }
  // Several ranks: [n_seg] 1: a segment this rank cannot read (beyond its halo); [n_snode] 1: a
  // surface node this rank owns (empty on one rank: every node).
  std::vector<std::uint8_t> seg_remote_, node_mine_;
  std::size_t n_mine_ = 0;  // surface nodes this rank owns (after restrict_to_rank)
  // Several ranks: segments this rank reads that share a corner with one it does not (the edge
  // of its contact halo). An owned node finding one among its candidates has slid about the
  // halo's width relative to the other surface: the contact beyond would be missed.
  std::vector<std::uint8_t> seg_halo_edge_;
  mutable double halo_ = 0;                  // set by nodes_to_read, for the message
  std::vector<std::int32_t> node_readable_;  // surface nodes this rank reads
  std::vector<std::size_t> frame_blocks_;    // frame blocks holding a segment it reads
  bool resort_ = false;  // the surface changed: sort before the next cycle
  // The solver's bound on the nodes' travel (set_node_travel; < 0: none), and at the last
  // displacement check that bound and the largest displacement since the sort it measured.
  double travel_ = -1, travel_checked_ = -1, checked_d_ = 0;
  BucketGrid grid_;

  ContactBatch batch_;          // active contacts on their way through the force kernel
  std::vector<V3> pair_force_;  // [n_pairs] force on the pair's first group
  double dissipation_ = 0;
  PenaltyContactStats stats_;
};

}  // namespace ncfsim::fem
