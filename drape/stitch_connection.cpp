#include "drape/stitch_connection.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fem/checkpoint.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::drape {

namespace {

using fem::cross3;
using fem::dot3;

// The smallest rotation R that turns the unit vector t0 into the unit vector t (about t0 x t):
// R v = c v + a x v + (a.v) a / (1 + c), c = t0.t, a = t0 x t.
struct TowTurn {
  double t0[3], t[3], a[3], c, len_u;
  void apply(const double* v, double* out) const {
    double axv[3];
    cross3(a, v, axv);
    const double q = dot3(a, v) / (1 + c);
    for (int k = 0; k < 3; ++k) out[k] = c * v[k] + axv[k] + q * a[k];
  }
  void apply_inverse(const double* v, double* out) const {  // R^T: the turn from t back to t0
    double axv[3];
    cross3(a, v, axv);
    const double q = dot3(a, v) / (1 + c);
    for (int k = 0; k < 3; ++k) out[k] = c * v[k] - axv[k] + q * a[k];
  }
  /// g = sum_j (d(R v_j)/d u)^T h_j, with t = u/|u| (u the tow axis vector the turn was made
  /// from), given M = sum_j h_j (x) v_j (row-major): the expression is bilinear in (v, h).
  void adjoint(const double* M, double* g) const {
    // h . d(R v) = dt . g_t, from dc = t0.dt and da = t0 x dt:
    // g_t = (v.h) t0 + (t0.v) h - (t0.h) v + ((a.h) v x t0 + (a.v) h x t0) / (1 + c)
    //       - (a.v)(a.h) t0 / (1 + c)^2, summed over the joints.
    double Mt0[3], MTt0[3], Ma[3], MTa[3];
    for (int p = 0; p < 3; ++p) {
      Mt0[p] = M[3 * p] * t0[0] + M[3 * p + 1] * t0[1] + M[3 * p + 2] * t0[2];
      MTt0[p] = M[p] * t0[0] + M[3 + p] * t0[1] + M[6 + p] * t0[2];
      Ma[p] = M[3 * p] * a[0] + M[3 * p + 1] * a[1] + M[3 * p + 2] * a[2];
      MTa[p] = M[p] * a[0] + M[3 + p] * a[1] + M[6 + p] * a[2];
    }
    const double trM = M[0] + M[4] + M[8], aMa = dot3(a, Ma);
    double sum_x_t0[3];
    const double s[3] = {MTa[0] + Ma[0], MTa[1] + Ma[1], MTa[2] + Ma[2]};
    cross3(s, t0, sum_x_t0);
    const double inv = 1 / (1 + c);
    double g_t[3];
    for (int k = 0; k < 3; ++k)
      g_t[k] = trM * t0[k] + Mt0[k] - MTt0[k] + sum_x_t0[k] * inv - aMa * inv * inv * t0[k];
    const double gt = dot3(g_t, t);
    for (int k = 0; k < 3; ++k) g[k] = (g_t[k] - gt * t[k]) / len_u;
  }
};

// A turn kept per hexahedron between the passes of a cycle: t, a, c, |u| (t0 is kept apart).
constexpr std::size_t kTurnSize = 8;
inline void store(const TowTurn& r, double* out) {
  for (int k = 0; k < 3; ++k) out[k] = r.t[k], out[3 + k] = r.a[k];
  out[6] = r.c, out[7] = r.len_u;
}

// The turn from t0 to the direction of u.
inline TowTurn tow_turn(const double* u, const double* t0) {
  TowTurn r;
  for (std::size_t k = 0; k < 3; ++k) r.t[k] = u[k], r.t0[k] = t0[k];
  r.len_u = std::sqrt(dot3(r.t, r.t));
  for (double& v : r.t) v /= r.len_u;
  r.c = dot3(t0, r.t);
  cross3(t0, r.t, r.a);
  return r;
}

inline TowTurn load(const double* t0, const double* in) {
  TowTurn r;
  for (int k = 0; k < 3; ++k) r.t0[k] = t0[k], r.t[k] = in[k], r.a[k] = in[3 + k];
  r.c = in[6], r.len_u = in[7];
  return r;
}

}  // namespace

StitchToTowConnection::StitchToTowConnection(std::string name, std::vector<StitchConnection> pairs,
                                             StitchConnectionSettings s)
    : name_(std::move(name)), s_(s) {
  if (!(s.sliding_force > 0)) throw std::invalid_argument("sliding_force must be > 0");
  if (!(s.transverse_force >= 0)) throw std::invalid_argument("transverse_force must be >= 0");
  if (!(s.stiffness >= 0)) throw std::invalid_argument("stiffness must be >= 0");
  if (!(s.stiffness_scale > 0 && s.stiffness_scale <= 1)) throw std::invalid_argument("stiffness_scale must be in (0, 1]");
  for (const auto& p : pairs)
    a_.push_back(p.stitch_node), b_.push_back(p.tow_node), ax_.push_back(p.tow_axis_node);
}

// Per joint ~70 bytes, per axis hexahedron (a few joints share one) 260; the set-up's map from
// every mesh node to its hexahedra (~90 bytes a node) and the slot of each hexahedron.
double StitchToTowConnection::estimated_bytes(const fem::Mesh& mesh, bool erosion) const {
  (void)erosion;
  const double joints = static_cast<double>(a_.size());
  return 70 * joints + 260 * joints / 2 + 90.0 * static_cast<double>(mesh.n_nodes()) +
         4.0 * static_cast<double>(mesh.elements(fem::ElementKind::Hex8).size());
}

void StitchToTowConnection::initialise(const fem::ContactSetup& setup) {
  const std::size_t n = a_.size(), nn = setup.mesh->n_nodes();
  rest_.assign(3 * n, 0.0);
  k_.assign(n, 0.0);
  force_.assign(n, 0.0);
  slip_len_.assign(n, 0.0);
  const double* x0 = setup.x0;
  // The tow's axis at a joint is the axis of a hexahedron holding its tow edge (b, c): the mean
  // of its four edges along the tow, u = sum_I w_I x_I with w_I = +-1/8 at its two ends. The
  // turn of the offset with it then moves the hexahedron as a whole (no hourglass couple on
  // one edge). Joints sharing a hexahedron share its axis (the turn does not depend on which
  // way along the tow the axis points).
  // The axis is defined on the tows' hexahedra (eight nodes, four edges along the tow); slots keep
  // their mesh-wide element index, the index erosion reports.
  const fem::ElementSet& hexes = setup.mesh->elements(fem::ElementKind::Hex8);
  const auto hex_offset = static_cast<std::int32_t>(setup.mesh->element_offset(fem::ElementKind::Hex8));
  joint_slot_.assign(n, -1);
  slot_hex_.clear();
  slot_nodes_.clear();
  slot_w_.clear();
  slot_t0_.clear();
  std::vector<std::int32_t> slot_of_hex(hexes.size(), -1);
  std::vector<std::vector<std::int32_t>> hexes_at(nn);  // hexahedra by node
  for (std::size_t h = 0; h < hexes.size(); ++h)
    for (auto nd : hexes.nodes(h))
      hexes_at[static_cast<std::size_t>(nd)].push_back(static_cast<std::int32_t>(h));
  for (std::size_t i = 0; i < n; ++i) {
    for (auto nd : {a_[i], b_[i], ax_[i]})
      if (nd < 0 || static_cast<std::size_t>(nd) >= nn)
        throw InputError("", name_, "connection joins an invalid node");
    std::int32_t hex = -1;
    for (auto h : hexes_at[static_cast<std::size_t>(b_[i])]) {
      const auto hx = hexes.nodes(static_cast<std::size_t>(h));
      if (std::find(hx.begin(), hx.end(), ax_[i]) != hx.end()) {
        hex = h;
        break;
      }
    }
    if (hex < 0)
      throw InputError("", name_, "a connection's tow node and axis node share no hexahedron");
    auto& slot = slot_of_hex[static_cast<std::size_t>(hex)];
    if (slot < 0) {
      slot = static_cast<std::int32_t>(slot_hex_.size());
      slot_hex_.push_back(hex_offset + hex);
      const auto hx = hexes.nodes(static_cast<std::size_t>(hex));
      const auto b = static_cast<std::size_t>(b_[i]), c = static_cast<std::size_t>(ax_[i]);
      double edge[3], cen[3] = {0, 0, 0};
      for (std::size_t k = 0; k < 3; ++k) edge[k] = x0[3 * c + k] - x0[3 * b + k];
      for (auto nd : hx)
        for (std::size_t k = 0; k < 3; ++k)
          cen[k] += 0.125 * x0[3 * static_cast<std::size_t>(nd) + k];
      double u0[3] = {0, 0, 0};
      for (std::size_t I = 0; I < 8; ++I) {
        const auto nd = static_cast<std::size_t>(hx[I]);
        const double rel[3] = {x0[3 * nd] - cen[0], x0[3 * nd + 1] - cen[1],
                               x0[3 * nd + 2] - cen[2]};
        const double w = dot3(rel, edge) > 0 ? 0.125 : -0.125;
        slot_nodes_.push_back(hx[I]);
        slot_w_.push_back(w);
        for (std::size_t k = 0; k < 3; ++k) u0[k] += w * x0[3 * nd + k];
      }
      const double len = std::sqrt(dot3(u0, u0));
      for (std::size_t k = 0; k < 3; ++k) slot_t0_.push_back(u0[k] / len);
    }
    joint_slot_[i] = slot;
  }
  const std::size_t n_slots = slot_hex_.size();
  slot_turn_.assign(kTurnSize * n_slots, 0.0);
  slot_m_.assign(9 * n_slots, 0.0);
  n_released_ = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const auto a = static_cast<std::size_t>(a_[i]), b = static_cast<std::size_t>(b_[i]);
    const double* t0 = &slot_t0_[3 * static_cast<std::size_t>(joint_slot_[i])];
    if (a == b || !std::isfinite(t0[0] + t0[1] + t0[2]))
      throw InputError("", name_, "connection joins an invalid node pair");
    for (std::size_t k = 0; k < 3; ++k) rest_[3 * i + k] = x0[3 * b + k] - x0[3 * a + k];
    const double m = std::min(setup.mass[3 * a], setup.mass[3 * b]);
    const double k_stable = s_.stiffness_scale * m / (setup.dt * setup.dt);
    k_[i] = s_.stiffness > 0 ? std::min(s_.stiffness, k_stable) : k_stable;
  }
}

void StitchToTowConnection::add_forces(const double* x, const double*, const double*, double, double* fc) {
  const std::size_t n = a_.size(), n_slots = slot_hex_.size();
  const double Fs = s_.sliding_force, Ft = s_.transverse_force;
  // Each hexahedron's axis and its turn from set-up, once.
  for (std::size_t h = 0; h < n_slots; ++h) {
    if (slot_hex_[h] < 0 || (!slot_mine_.empty() && !slot_mine_[h])) continue;  // eroded, remote
    const std::int32_t* hx = &slot_nodes_[8 * h];
    const double* w = &slot_w_[8 * h];
    double u[3] = {0, 0, 0};
    for (std::size_t I = 0; I < 8; ++I)
      for (std::size_t k = 0; k < 3; ++k) u[k] += w[I] * x[3 * static_cast<std::size_t>(hx[I]) + k];
    store(tow_turn(u, &slot_t0_[3 * h]), &slot_turn_[kTurnSize * h]);
    std::fill_n(&slot_m_[9 * h], 9, 0.0);
  }
  double diss = 0;
  std::int64_t sliding = 0;
  fem::V3 total{};
  for (std::size_t i = 0; i < n; ++i) {
    if (joint_slot_[i] < 0) {  // released by erosion
      force_[i] = 0;
      continue;
    }
    if (!joint_mine_.empty() && !joint_mine_[i]) continue;  // another rank's
    const auto h = static_cast<std::size_t>(joint_slot_[i]);
    const std::size_t a = static_cast<std::size_t>(a_[i]), b = static_cast<std::size_t>(b_[i]);
    const TowTurn R = load(&slot_t0_[3 * h], &slot_turn_[kTurnSize * h]);
    double* rho = &rest_[3 * i];  // rest offset (with the slip) in the reference frame of the tow
    double r[3];
    R.apply(rho, r);
    double d[3];  // spring extension: b - a less its turned rest offset
    for (std::size_t k = 0; k < 3; ++k) d[k] = x[3 * b + k] - x[3 * a + k] - r[k];
    const double kk = k_[i];
    // Return mapping, along the tow (the sliding force) and across it (the transverse limit, if
    // any) separately: the slider moves until the spring carries the limit; the slip goes into
    // the rest offset, turned back to the reference frame.
    const double d_t = dot3(d, R.t);
    double dslip = 0, slip[3] = {0, 0, 0};
    if (kk * std::abs(d_t) > Fs) {
      const double ds = std::copysign((kk * std::abs(d_t) - Fs) / kk, d_t);
      for (int k = 0; k < 3; ++k) slip[k] += ds * R.t[k];
      diss += Fs * std::abs(ds);
      dslip += std::abs(ds);
    }
    double d_perp[3];
    for (int k = 0; k < 3; ++k) d_perp[k] = d[k] - d_t * R.t[k];
    const double len_perp = std::sqrt(dot3(d_perp, d_perp));
    if (Ft > 0 && kk * len_perp > Ft) {
      const double q = (kk * len_perp - Ft) / (kk * len_perp);  // share of it that slips
      for (int k = 0; k < 3; ++k) slip[k] += q * d_perp[k];
      diss += Ft * q * len_perp;
      dslip += q * len_perp;
    }
    if (dslip > 0) {
      double back[3];
      R.apply_inverse(slip, back);
      for (int k = 0; k < 3; ++k) rho[k] += back[k], d[k] -= slip[k];
      slip_len_[i] += dslip;
      ++sliding;
    }
    force_[i] = kk * std::sqrt(dot3(d, d));
    const double kd[3] = {kk * d[0], kk * d[1], kk * d[2]};  // pulls a towards b and b towards a
    for (std::size_t k = 0; k < 3; ++k) fc[3 * a + k] += kd[k], fc[3 * b + k] -= kd[k];
    double* M = &slot_m_[9 * h];
    for (int p = 0; p < 3; ++p)
      for (int q = 0; q < 3; ++q) M[3 * p + q] += kd[p] * rho[q];
    total += fem::V3{kd[0], kd[1], kd[2]};
  }
  // The forces of the energy k |d|^2 / 2 through the turn of the rest offsets with each
  // hexahedron's axis u: w_I g on its nodes, g summed over its joints.
  for (std::size_t h = 0; h < n_slots; ++h) {
    if (slot_hex_[h] < 0 || (!slot_mine_.empty() && !slot_mine_[h])) continue;
    const TowTurn R = load(&slot_t0_[3 * h], &slot_turn_[kTurnSize * h]);
    double g[3];
    R.adjoint(&slot_m_[9 * h], g);
    const std::int32_t* hx = &slot_nodes_[8 * h];
    const double* w = &slot_w_[8 * h];
    for (std::size_t I = 0; I < 8; ++I)
      for (std::size_t k = 0; k < 3; ++k)
        fc[3 * static_cast<std::size_t>(hx[I]) + k] += w[I] * g[k];
  }
  dissipated_ += diss;
  n_sliding_ = sliding;
  total_ = total;
}

bool StitchToTowConnection::nodes_to_read(const std::uint8_t* owned, const double*, double,
                                          std::vector<std::int32_t>& out) const {
  for (std::size_t i = 0; i < a_.size(); ++i) {
    if (!owned[static_cast<std::size_t>(a_[i])]) continue;
    out.push_back(b_[i]);
    if (joint_slot_[i] >= 0) {
      const auto h = static_cast<std::size_t>(joint_slot_[i]);
      out.insert(out.end(), &slot_nodes_[8 * h], &slot_nodes_[8 * h] + 8);
    }
  }
  return true;
}

void StitchToTowConnection::restrict_to_rank(const std::uint8_t* owned, const std::uint8_t*) {
  joint_mine_.assign(a_.size(), 0);
  slot_mine_.assign(slot_hex_.size(), 0);
  for (std::size_t i = 0; i < a_.size(); ++i) {
    joint_mine_[i] = owned[static_cast<std::size_t>(a_[i])];
    if (joint_mine_[i] && joint_slot_[i] >= 0)
      slot_mine_[static_cast<std::size_t>(joint_slot_[i])] = 1;
  }
}

void StitchToTowConnection::erode(const std::vector<std::int32_t>& mesh_elements) {
  std::vector<std::int32_t> gone = mesh_elements;  // erosion is rare: a sorted list to look up
  std::sort(gone.begin(), gone.end());
  for (auto& h : slot_hex_)
    if (h >= 0 && std::binary_search(gone.begin(), gone.end(), h)) h = -1;
  for (auto& slot : joint_slot_)
    if (slot >= 0 && slot_hex_[static_cast<std::size_t>(slot)] < 0) slot = -1, ++n_released_;
}

std::vector<fem::ContactResultant> StitchToTowConnection::resultants() const { return {{name_, total_}}; }

void StitchToTowConnection::save_state(fem::CheckpointWriter& w) const {
  w.write_int("n_joints", static_cast<std::int64_t>(a_.size()));
  fem::save_array(w, "rest", rest_);
  fem::save_array(w, "slip_length", slip_len_);
  fem::save_array(w, "force", force_);
  fem::save_array(w, "joint_slot", joint_slot_);
  fem::save_array(w, "slot_hex", slot_hex_);
  w.write_int("n_released", static_cast<std::int64_t>(n_released_));
  w.write_double("dissipated", dissipated_);
  w.write_int("n_sliding", n_sliding_);
  const double t[3] = {total_.x, total_.y, total_.z};
  w.write_array("total", std::span<const double>(t, 3));
}

void StitchToTowConnection::load_state(fem::CheckpointReader& r) {
  r.check_int("n_joints", static_cast<std::int64_t>(a_.size()));
  fem::load_array(r, "rest", rest_);
  fem::load_array(r, "slip_length", slip_len_);
  fem::load_array(r, "force", force_);
  fem::load_array(r, "joint_slot", joint_slot_);
  fem::load_array(r, "slot_hex", slot_hex_);
  n_released_ = static_cast<std::size_t>(r.read_int("n_released"));
  dissipated_ = r.read_double("dissipated");
  n_sliding_ = r.read_int("n_sliding");
  double t[3];
  r.read_into("total", t, 3);
  total_ = {t[0], t[1], t[2]};
}

}  // namespace ncfsim::drape
