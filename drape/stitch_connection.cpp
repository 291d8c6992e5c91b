#include "drape/stitch_connection.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "fem/errors.hpp"
#include "fem/mesh.hpp"

namespace ncfsim::drape {

namespace {

inline void cross(const double* a, const double* b, double* c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}
inline double dot(const double* a, const double* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}

// The smallest rotation R that turns the unit vector t0 into the unit vector t (about t0 x t):
// R v = c v + a x v + (a.v) a / (1 + c), c = t0.t, a = t0 x t.
struct TowTurn {
  double t0[3], t[3], a[3], c, len_u;
  void apply(const double* v, double* out) const {
    double axv[3];
    cross(a, v, axv);
    const double q = dot(a, v) / (1 + c);
    for (int k = 0; k < 3; ++k) out[k] = c * v[k] + axv[k] + q * a[k];
  }
  void apply_inverse(const double* v, double* out) const {  // R^T: the turn from t back to t0
    double axv[3];
    cross(a, v, axv);
    const double q = dot(a, v) / (1 + c);
    for (int k = 0; k < 3; ++k) out[k] = c * v[k] - axv[k] + q * a[k];
  }
  /// g = (d(R v)/d u)^T h, with t = u/|u| (u the tow axis vector the turn was made from).
  void adjoint(const double* v, const double* h, double* g) const {
    // h . d(R v) = dt . g_t, from dc = t0.dt and da = t0 x dt.
    const double vh = dot(v, h), t0v = dot(t0, v), t0h = dot(t0, h), av = dot(a, v), ah = dot(a, h);
    double v_t0[3], h_t0[3];
    cross(v, t0, v_t0);
    cross(h, t0, h_t0);
    const double inv = 1 / (1 + c);
    double g_t[3];
    for (int k = 0; k < 3; ++k)
      g_t[k] = vh * t0[k] + t0v * h[k] - t0h * v[k] + (ah * v_t0[k] + av * h_t0[k]) * inv -
               av * ah * inv * inv * t0[k];
    const double gt = dot(g_t, t);
    for (int k = 0; k < 3; ++k) g[k] = (g_t[k] - gt * t[k]) / len_u;
  }
};

// The turn from t0 to the direction of u.
inline TowTurn tow_turn(const double* u, const double* t0) {
  TowTurn r;
  for (std::size_t k = 0; k < 3; ++k) r.t[k] = u[k], r.t0[k] = t0[k];
  r.len_u = std::sqrt(dot(r.t, r.t));
  for (double& v : r.t) v /= r.len_u;
  r.c = dot(t0, r.t);
  cross(t0, r.t, r.a);
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

void StitchToTowConnection::initialise(const fem::ContactSetup& setup) {
  const std::size_t n = a_.size(), nn = setup.mesh->n_nodes();
  rest_.assign(3 * n, 0.0);
  t0_.assign(3 * n, 0.0);
  k_.assign(n, 0.0);
  force_.assign(n, 0.0);
  slip_len_.assign(n, 0.0);
  const double* x0 = setup.x0;
  // The tow's axis at a joint is the axis of a hexahedron holding its tow edge (b, c): the mean
  // of its four edges along the tow, u = sum_I w_I x_I with w_I = +-1/8 at its two ends. The
  // turn of the offset with it then moves the hexahedron as a whole (no hourglass couple on
  // one edge).
  const auto& hexes = setup.mesh->hexes;
  hex8_.assign(8 * n, 0);
  w8_.assign(8 * n, 0.0);
  joint_hex_.assign(n, -1);
  {
    std::vector<std::vector<std::int32_t>> hexes_at(nn);  // hexahedra by node
    for (std::size_t h = 0; h < hexes.size(); ++h)
      for (auto nd : hexes[h])
        hexes_at[static_cast<std::size_t>(nd)].push_back(static_cast<std::int32_t>(h));
    for (std::size_t i = 0; i < n; ++i) {
      for (auto nd : {a_[i], b_[i], ax_[i]})
        if (nd < 0 || static_cast<std::size_t>(nd) >= nn)
          throw InputError("", name_, "connection joins an invalid node");
      for (auto h : hexes_at[static_cast<std::size_t>(b_[i])]) {
        const auto& hx = hexes[static_cast<std::size_t>(h)];
        if (std::find(hx.begin(), hx.end(), ax_[i]) != hx.end()) {
          joint_hex_[i] = h;
          break;
        }
      }
      if (joint_hex_[i] < 0)
        throw InputError("", name_, "a connection's tow node and axis node share no hexahedron");
    }
    for (std::size_t i = 0; i < n; ++i) {
      const auto& hx = hexes[static_cast<std::size_t>(joint_hex_[i])];
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
        const double w = dot(rel, edge) > 0 ? 0.125 : -0.125;
        hex8_[8 * i + I] = hx[I], w8_[8 * i + I] = w;
        for (std::size_t k = 0; k < 3; ++k) u0[k] += w * x0[3 * nd + k];
      }
      const double len = std::sqrt(dot(u0, u0));
      for (std::size_t k = 0; k < 3; ++k) t0_[3 * i + k] = u0[k] / len;
    }
    n_released_ = 0;
  }
  for (std::size_t i = 0; i < n; ++i) {
    const auto a = static_cast<std::size_t>(a_[i]), b = static_cast<std::size_t>(b_[i]);
    if (a == b || !std::isfinite(t0_[3 * i] + t0_[3 * i + 1] + t0_[3 * i + 2]))
      throw InputError("", name_, "connection joins an invalid node pair");
    for (std::size_t k = 0; k < 3; ++k) rest_[3 * i + k] = x0[3 * b + k] - x0[3 * a + k];
    const double m = std::min(setup.mass[3 * a], setup.mass[3 * b]);
    const double k_stable = s_.stiffness_scale * m / (setup.dt * setup.dt);
    k_[i] = s_.stiffness > 0 ? std::min(s_.stiffness, k_stable) : k_stable;
  }
}

void StitchToTowConnection::add_forces(const double* x, const double*, const double*, double, double* fc) {
  const std::size_t n = a_.size();
  const double Fs = s_.sliding_force, Ft = s_.transverse_force;
  double diss = 0;
  std::int64_t sliding = 0;
  fem::V3 total{};
  for (std::size_t i = 0; i < n; ++i) {
    if (joint_hex_[i] < 0) {  // released by erosion
      force_[i] = 0;
      continue;
    }
    const std::size_t a = static_cast<std::size_t>(a_[i]), b = static_cast<std::size_t>(b_[i]);
    const std::int32_t* hx = &hex8_[8 * i];
    const double* w = &w8_[8 * i];
    double u[3] = {0, 0, 0};
    for (std::size_t I = 0; I < 8; ++I)
      for (std::size_t k = 0; k < 3; ++k) u[k] += w[I] * x[3 * static_cast<std::size_t>(hx[I]) + k];
    const TowTurn R = tow_turn(u, &t0_[3 * i]);
    double* rho = &rest_[3 * i];  // rest offset (with the slip) in the reference frame of the tow
    double r[3];
    R.apply(rho, r);
    double d[3];  // spring extension: b - a less its turned rest offset
    for (std::size_t k = 0; k < 3; ++k) d[k] = x[3 * b + k] - x[3 * a + k] - r[k];
    const double kk = k_[i];
    // Return mapping, along the tow (the sliding force) and across it (the transverse limit, if
    // any) separately: the slider moves until the spring carries the limit; the slip goes into
    // the rest offset, turned back to the reference frame.
    const double d_t = dot(d, R.t);
    double dslip = 0, slip[3] = {0, 0, 0};
    if (kk * std::abs(d_t) > Fs) {
      const double ds = std::copysign((kk * std::abs(d_t) - Fs) / kk, d_t);
      for (int k = 0; k < 3; ++k) slip[k] += ds * R.t[k];
      diss += Fs * std::abs(ds);
      dslip += std::abs(ds);
    }
    double d_perp[3];
    for (int k = 0; k < 3; ++k) d_perp[k] = d[k] - d_t * R.t[k];
    const double len_perp = std::sqrt(dot(d_perp, d_perp));
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
    force_[i] = kk * std::sqrt(dot(d, d));
    // The forces of the energy k |d|^2 / 2: the turn of the rest offset with the hexahedron's
    // axis u puts w_I g on its nodes.
    const double kd[3] = {kk * d[0], kk * d[1], kk * d[2]};  // pulls a towards b and b towards a
    double g[3];
    R.adjoint(rho, kd, g);
    for (std::size_t k = 0; k < 3; ++k) fc[3 * a + k] += kd[k], fc[3 * b + k] -= kd[k];
    for (std::size_t I = 0; I < 8; ++I)
      for (std::size_t k = 0; k < 3; ++k)
        fc[3 * static_cast<std::size_t>(hx[I]) + k] += w[I] * g[k];
    total += fem::V3{kd[0], kd[1], kd[2]};
  }
  dissipated_ += diss;
  n_sliding_ = sliding;
  total_ = total;
}

void StitchToTowConnection::erode(const std::vector<std::int32_t>& mesh_hexes) {
  std::vector<std::int32_t> gone = mesh_hexes;  // erosion is rare: a sorted list to look up
  std::sort(gone.begin(), gone.end());
  for (auto& h : joint_hex_)
    if (h >= 0 && std::binary_search(gone.begin(), gone.end(), h)) h = -1, ++n_released_;
}

std::vector<fem::ContactResultant> StitchToTowConnection::resultants() const { return {{name_, total_}}; }

}  // namespace ncfsim::drape
