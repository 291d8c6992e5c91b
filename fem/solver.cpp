#include "fem/solver.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>

#include "fem/boundary/picture_frame_motion.hpp"
#include "fem/checkpoint.hpp"
#include "fem/errors.hpp"
#include "fem/parallel/domain.hpp"

namespace ncfsim::fem {

namespace {
using Clock = std::chrono::steady_clock;
// Cycles between searches for folded hexahedra: a fold grows over thousands of cycles (4 ms, 10^4
// cycles, from the first folded corner to a blow-up in the bias extension), and a search costs
// about one pass of the element kernel.
constexpr std::int64_t kFoldCheckInterval = 50;
double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// Sums over the DOFs of F.v^{n-1/2}, F.v^{n+1/2} per force kind and m v^{n-1/2} v^{n+1/2}.
struct NodeUpdateSums {
  double ext_old = 0, ext_new = 0, damp_old = 0, damp_new = 0, con_old = 0, con_new = 0, ke = 0;
  double v_max = 0;  // largest |v| component of v^{n+1/2} (bounds the cycle's node motion)
};

// v^{n+1/2} of every DOF as if free, branch-free so that it vectorises; with kMoveX the positions
// move on to x^{n+1} in the same pass (one sweep over the nodal arrays when no callback needs x^n).
// The pass is bound by memory traffic, so the arrays of absent force kinds (kExt, kContact,
// kDamp false) are neither read nor written: the sums of those kinds stay zero.
template <bool kMoveX, bool kExt, bool kContact, bool kDamp>
NodeUpdateSums free_node_update(std::size_t nd, double alpha, double dt_mid, double dt_new,
                                const double* inv_m, const double* mm, const double* fi,
                                const double* fe, const double* fcon, double* vel, double* fdamp,
                                double* x) {
  double ext_old = 0, ext_new = 0, damp_old = 0, damp_new = 0, con_old = 0, con_new = 0, ke = 0;
  double v_max = 0;
#pragma omp simd reduction(+ : ext_old, ext_new, damp_old, damp_new, con_old, con_new, ke) \
    reduction(max : v_max)
  for (std::size_t d = 0; d < nd; ++d) {
    const double vo = vel[d], m = mm[d];
    double f = fi[d];
    if constexpr (kExt) f += fe[d];
    if constexpr (kContact) f += fcon[d];
    double fd = 0;
    if constexpr (kDamp) fd = -alpha * m * vo, f += fd;
    const double vn = vo + dt_mid * f * inv_m[d];
    vel[d] = vn;
    if constexpr (kMoveX) x[d] += dt_new * vn;
    if constexpr (kExt) ext_old += fe[d] * vo, ext_new += fe[d] * vn;
    if constexpr (kDamp) fdamp[d] = fd, damp_old += fd * vo, damp_new += fd * vn;
    if constexpr (kContact) con_old += fcon[d] * vo, con_new += fcon[d] * vn;
    ke += m * vo * vn;
    v_max = std::max(v_max, std::abs(vn));
  }
  return {ext_old, ext_new, damp_old, damp_new, con_old, con_new, ke, v_max};
}

using NodeUpdate = NodeUpdateSums (*)(std::size_t, double, double, double, const double*,
                                      const double*, const double*, const double*, const double*,
                                      double*, double*, double*);
// free_node_update for each combination, indexed by kMoveX * 8 + kExt * 4 + kContact * 2 + kDamp.
template <std::size_t... I>
constexpr std::array<NodeUpdate, sizeof...(I)> node_update_table(std::index_sequence<I...>) {
  return {&free_node_update<(I & 8) != 0, (I & 4) != 0, (I & 2) != 0, (I & 1) != 0>...};
}
constexpr auto kNodeUpdates = node_update_table(std::make_index_sequence<16>{});

// The node update over a rank's runs of owned nodes; the sums add up over the runs.
NodeUpdateSums owned_node_update(NodeUpdate f,
                                 const std::vector<std::pair<std::size_t, std::size_t>>& runs,
                                 double alpha, double dt_mid, double dt_new, const double* inv_m,
                                 const double* mm, const double* fi, const double* fe,
                                 const double* fcon, double* vel, double* fdamp, double* x) {
  NodeUpdateSums s;
  for (const auto& [b, e] : runs) {
    const std::size_t d = 3 * b;
    const NodeUpdateSums r = f(3 * (e - b), alpha, dt_mid, dt_new, inv_m + d, mm + d, fi + d,
                               fe + d, fcon + d, vel + d, fdamp + d, x ? x + d : nullptr);
    s.ext_old += r.ext_old, s.ext_new += r.ext_new, s.damp_old += r.damp_old;
    s.damp_new += r.damp_new, s.con_old += r.con_old, s.con_new += r.con_new, s.ke += r.ke;
    s.v_max = std::max(s.v_max, r.v_max);
  }
  return s;
}

// The step of the next cycle, the smallest over the ranks, and the controlling element (the
// smallest element step; ties to the lower user id, as on one rank within a group); returns the
// lowest rank that reports a blow-up (`blow_up_rank`: this rank's number if it does, else the
// number of ranks), so that a blow-up costs no collective of its own.
int reduce_step(MPI_Comm comm, double& dt_new, StableStep& st, int blow_up_rank) {
  struct Packed {
    double dt_new, dt, element, kind, blow_up_rank;
  };
  static MPI_Op op = [] {
    MPI_Op o;
    MPI_Op_create(
        [](void* in, void* inout, int* len, MPI_Datatype*) {
          auto* a = static_cast<Packed*>(in);
          auto* b = static_cast<Packed*>(inout);
          for (int i = 0; i < *len; ++i) {
            b[i].dt_new = std::min(a[i].dt_new, b[i].dt_new);
            if (a[i].dt < b[i].dt || (a[i].dt == b[i].dt && a[i].element < b[i].element))
              b[i].dt = a[i].dt, b[i].element = a[i].element, b[i].kind = a[i].kind;
            b[i].blow_up_rank = std::min(a[i].blow_up_rank, b[i].blow_up_rank);
          }
        },
        1, &o);
    return o;
  }();
  static MPI_Datatype type = [] {
    MPI_Datatype t;
    MPI_Type_contiguous(5, MPI_DOUBLE, &t);
    MPI_Type_commit(&t);
    return t;
  }();
  Packed p{dt_new, st.dt, static_cast<double>(st.element), static_cast<double>(st.kind),
           static_cast<double>(blow_up_rank)};
  MPI_Allreduce(MPI_IN_PLACE, &p, 1, type, op, comm);
  dt_new = p.dt_new;
  st.dt = p.dt;
  st.element = static_cast<std::int64_t>(p.element);
  st.kind = static_cast<ElementKind>(static_cast<int>(p.kind));
  return static_cast<int>(p.blow_up_rank);
}

}  // namespace

ExplicitSolver::~ExplicitSolver() = default;

// On several ranks the sums of the last output gather; before the first (a run that failed in
// its first cycle) this rank's own.
std::vector<ContactResultant> ExplicitSolver::contact_resultants(std::size_t k) const {
  return domain_ && k < contact_resultants_.size() ? contact_resultants_[k]
                                                   : model_.contacts.at(k)->resultants();
}

double ExplicitSolver::contact_max_penetration(std::size_t k) const {
  return domain_ && k < contact_max_penetration_.size() ? contact_max_penetration_[k]
                                                        : model_.contacts.at(k)->max_penetration();
}

std::size_t ExplicitSolver::n_elements(ElementKind kind) const {
  std::size_t s = 0;
  for (const auto& g : groups_)
    if (g->kind() == kind) s += g->size();
  return s;
}

std::size_t ExplicitSolver::n_elements() const {
  std::size_t s = 0;
  for (const auto& g : groups_) s += g->size();
  return s;
}

double ExplicitSolver::frame_wall_power(std::size_t k) const {
  if (domain_) return k < frame_wall_power_.size() ? frame_wall_power_[k] : 0.0;
  return frames_ ? frames_->wall_power(k) : 0.0;
}
std::int64_t ExplicitSolver::frame_wall_contacts(std::size_t k) const {
  if (domain_) return k < frame_wall_contacts_.size() ? frame_wall_contacts_[k] : 0;
  return frames_ ? frames_->wall_contacts(k) : 0;
}

V3 ExplicitSolver::reaction_force(const std::vector<std::int32_t>& nodes) const {
  auto R = reaction.view();
  V3 s;
  for (auto node : nodes) {
    const auto i = static_cast<std::size_t>(node);
    s += V3{R[3 * i], R[3 * i + 1], R[3 * i + 2]};
  }
  return s;
}

void ExplicitSolver::check_finite(const double* vel) const {
  const std::size_t n = model_.mesh.n_nodes();
  auto X = x.view();
  std::string what;
  for (std::size_t i = 0; i < n && what.empty(); ++i)
    for (int c = 0; c < 3 && what.empty(); ++c)
      if (!std::isfinite(vel[3 * i + c]) && (!domain_ || domain_->owns(i))) {
        std::ostringstream os;
        os << "numerical instability: velocity of node " << model_.mesh.node_user_id[i] << " at ("
           << X[3 * i] << ", " << X[3 * i + 1] << ", " << X[3 * i + 2]
           << ") m is not finite at t = " << t_ << " s, cycle " << cycle_
           << "; the stable step is controlled by " << element_noun(step_.kind) << " "
           << step_.element << " at " << element_position(step_, X.data());
        what = os.str();
      }
  if (domain_) {
    // The kinetic energy, summed over the ranks, told them all: each stops with the report of
    // the rank that found the node.
    if (what.empty()) what.push_back('-');
    share_blow_up(what);
    throw NumericalError("numerical instability: a velocity is not finite");
  }
  if (!what.empty()) throw NumericalError(what);
}

// One cycle of central differences: the phases below in order, each reading what the ones before
// left in `c`. The vectors' views are held over them and released before the callback, which may
// read the vectors itself.
void ExplicitSolver::step(const std::function<void()>& at_tn, bool at_tn_reads_x) {
  Cycle c;
  c.move_x_in_pass = !at_tn || !at_tn_reads_x;
  {
    auto X = x.view();
    auto Vv = v.view();
    auto X0 = x0.view();
    auto M = mass.view();
    auto Fi = f_int.view();
    auto Fe = f_ext.view();
    auto Fc = f_contact.view();
    auto Fd = f_damp.view();
    auto Rr = reaction.view();
    const CycleArrays a{X.data(),  Vv.data(), X0.data(), M.data(), Fi.data(),
                        Fe.data(), Fc.data(), Fd.data(), Rr.data()};
    if (domain_ && !model_.contacts.empty()) {
      const auto th = Clock::now();
      refresh_contact_halo(a.x, a.v);
      timers_.exchange += seconds_since(th);
    }
    if (model_.time.mass_scaling_dynamic) {
      const auto tm = Clock::now();
      scale_mass_dynamic(a.x, a.v, M.data());
      timers_.internal_force += seconds_since(tm);
    }
    auto t0 = Clock::now();
    internal_forces(a, c);
    erode_and_choose_step(a, c);
    timers_.internal_force += seconds_since(t0);
    t0 = Clock::now();
    contact_forces(a, c);
    timers_.contact += seconds_since(t0);
    if (domain_) {
      t0 = Clock::now();
      exchange_forces(a, c);
      timers_.exchange += seconds_since(t0);
    }
    t0 = Clock::now();
    external_forces(a, c);
    update_velocities(a, c);
    if (domain_) sum_over_ranks(c);
    book_energies(a, c);
    timers_.update += seconds_since(t0);
  }
  if (at_tn) {
    const auto t0 = Clock::now();
    at_tn();
    timers_.output += seconds_since(t0);
  }
  finish_cycle(c);
}

// Clears the force arrays and adds the elements' internal forces at x^n from v^{n-1/2}.
void ExplicitSolver::internal_forces(const CycleArrays& a, Cycle& c) {
  const std::size_t nd = 3 * model_.mesh.n_nodes();
  // Arrays a model does not use stay zero and are neither cleared nor read in the node loop.
  c.has_ext = !model_.loads.empty() || model_.gravity.x != 0 || model_.gravity.y != 0 ||
              model_.gravity.z != 0;
  c.has_contact = !model_.tools.empty() || !model_.contacts.empty() || has_motion_forces_;
  c.has_damp = model_.mass_damping != 0 &&
               (model_.mass_damping_end_time <= 0 || t_ < model_.mass_damping_end_time);
  // Several ranks: only the entries this rank reads are written or read (its elements' nodes,
  // its contacts' and its ghosts'), so only they are cleared (about half of each array on 2).
  const auto clear = [&](double* f) {
    if (!domain_) return std::fill(f, f + nd, 0.0);
    for (const auto& [b, e] : domain_->readable_runs()) std::fill(f + 3 * b, f + 3 * e, 0.0);
  };
  clear(a.fi);
  if (c.has_ext) std::fill(a.fe, a.fe + nd, 0.0);  // every rank adds every load (all nodes)
  if (c.has_contact) clear(a.fc);

  // Several ranks: energies booked directly in the cycle (erosion) are summed over the ranks
  // as increments from here.
  c.booked0 = {energy_.internal, energy_.eroded_internal, energy_.eroded_kinetic};
  eroded_any_ = false;
  const ElementCycleState cs{a.x, a.v, a.x0, dt_prev_};
  // Several ranks: a kernel's blow-up report is told to all at the next collective (the erosion
  // count or the step); this rank skips the rest of the cycle's work until then.
  for (std::size_t k = 0; k < groups_.size() && c.blow_up.empty(); ++k) {
    group_step_[k] = StableStep{};
    const auto t0 = Clock::now();
    try {
      groups_[k]->internal_forces(cs, a.fi, c.inc, group_step_[k]);
      group_seconds_[k] += seconds_since(t0);
    } catch (const NumericalError& e) {
      if (!domain_) throw;
      c.blow_up = e.what();
    }
  }
}

// Erosion, then the next step from the elements left (this rank's; exchange_forces takes the
// smallest over the ranks).
void ExplicitSolver::erode_and_choose_step(const CycleArrays& a, Cycle& c) {
  // Erosion: a step below the limit is seen at once; folded corners, which develop over many
  // cycles, are looked for every kFoldCheckInterval cycles. The forces of this cycle stand.
  // A failed material point (damage laws) is eroded in the cycle it fails.
  const double dt_erode = model_.time.erosion_step_ratio * dt_initial_;
  // With time.mass_scaling_erode_at_cap, an element at the mass cap is eroded once its step is
  // below the target: looked for whenever the step is.
  const double cap_dt = mass_cap_erosion_step();
  if (dt_erode > 0 || cap_dt > 0 || material_failure_) {
    bool check_steps = false;
    if (dt_erode > 0 || cap_dt > 0) {
      StableStep erodible;
      for (std::size_t k = 0; k < groups_.size(); ++k)
        if (groups_[k]->can_erode()) take_smaller(erodible, group_step_[k]);
      const double sf_dt = model_.time.safety_factor * erodible.dt;
      check_steps = sf_dt < dt_erode || cycle_ % kFoldCheckInterval == 0 ||
                    (sf_dt < cap_dt && capped_below(a.x, cap_dt));
    }
    erode(a.x, a.v, dt_erode, check_steps, c.blow_up);
  }
  for (const auto& s : group_step_) take_smaller(c.st, s);
  if (!domain_) {  // on several ranks they are summed over the ranks with the works
    energy_.internal += c.inc.internal;
    energy_.stabilisation += c.inc.stabilisation;
    energy_.hourglass += c.inc.hourglass;
    energy_.rotational_kinetic += c.inc.kinetic;
  }
  step_ = c.st;
  c.dt_new = model_.time.safety_factor * c.st.dt;
  if (dt_prev_ > 0) c.dt_new = std::min(c.dt_new, 1.1 * dt_prev_);  // limit step growth
  if (c.st.element < 0 && dt_prev_ > 0) c.dt_new = dt_prev_;  // every element eroded: no bound
}

// Whether an element of this rank at the cap of dynamic mass scaling has its step below cap_dt;
// only those elements are measured. The statically scaled tows' step sits at the target (a
// rounding below it, in the kernel's arithmetic), so "the step below the target" alone measured
// every element every cycle: 17 ms of a 79 ms cycle of the paper's model on one rank.
bool ExplicitSolver::capped_below(const double* x, double cap_dt) {
  if (mass_scaling_capped_ == 0) return false;
  const double sf = model_.time.safety_factor;
  for (const auto& g : groups_) {
    if (!g->can_erode()) continue;
    g->capped_element_steps(x, model_.time.mass_scaling_max_ratio, step_scratch_);
    for (const double dt : step_scratch_)
      if (sf * dt < cap_dt) return true;
  }
  return false;
}

// Contact forces at x^n: rigid tools, contacts (which may lower the step), rigs' walls.
void ExplicitSolver::contact_forces(const CycleArrays& a, Cycle& c) {
  if (!c.blow_up.empty()) return;  // several ranks: stopping at the step's reduction
  const double dt_c = dt_prev_ > 0 ? dt_prev_ : c.dt_new;
  try {
    for (std::size_t q = 0; q < model_.tools.size(); ++q) {
      const auto t0 = Clock::now();
      tool_contact_forces(model_.tools[q], a.x, a.v, a.m, dt_c, a.fc, node_travel_);
      tool_seconds_[q] += seconds_since(t0);
    }
    for (std::size_t q = 0; q < model_.contacts.size(); ++q) {
      const auto t0 = Clock::now();
      auto& k = model_.contacts[q];
      k->set_node_travel(domain_ ? travel_all_ranks_ : node_travel_);
      k->add_forces(a.x, a.v, a.m, dt_c, a.fc);
      c.dt_new = std::min(c.dt_new, k->stable_step_limit());
      contact_seconds_[q] += seconds_since(t0);
    }
    for (auto& m : motions_)
      if (m->has_forces()) m->add_forces(t_, a.x, a.m, dt_c, a.fc);
  } catch (const NumericalError& e) {
    // Several ranks: the others would wait for this one at the step's reduction; tell them there.
    if (!domain_) throw;
    c.blow_up = e.what();
  }
}

// Several ranks: the smallest step of all ranks (its element named as on one rank) and every
// node's whole force on its owner.
void ExplicitSolver::exchange_forces(const CycleArrays& a, Cycle& c) {
  const int me = c.blow_up.empty() ? domain_->size() : domain_->rank();
  throw_blow_up_of(reduce_step(domain_->comm(), c.dt_new, c.st, me), c.blow_up);
  step_ = c.st;
  domain_->add_ghosts_to_owners(a.fi, c.has_contact ? a.fc : nullptr);
  // The shells' nodal moments: each node's whole moment on every rank that advances its rotation.
  for (auto& g : groups_)
    if (double* m = g->nodal_moments()) {
      domain_->add_ghosts_to_owners(m, nullptr);
      domain_->refresh_ghosts(m);
    }
}

// External forces at t^n (loads, gravity); a step below time.min_step_ratio stops the run.
void ExplicitSolver::external_forces(const CycleArrays& a, Cycle& c) {
  const std::size_t n = model_.mesh.n_nodes();
  for (const auto& ld : model_.loads) {
    const V3 F = smooth_ramp(t_, ld.ramp_time) * ld.force_per_node;
    for (auto node : ld.nodes) {
      const auto i = static_cast<std::size_t>(node);
      a.fe[3 * i] += F.x, a.fe[3 * i + 1] += F.y, a.fe[3 * i + 2] += F.z;
    }
  }
  const V3 g = smooth_ramp(t_, model_.gravity_ramp_time) * model_.gravity;
  if (g.x != 0 || g.y != 0 || g.z != 0)
    for (std::size_t i = 0; i < n; ++i)
      a.fe[3 * i] += gravity_mass_[3 * i] * g.x, a.fe[3 * i + 1] += gravity_mass_[3 * i + 1] * g.y,
          a.fe[3 * i + 2] += gravity_mass_[3 * i + 2] * g.z;
  c.alpha = c.has_damp ? model_.mass_damping : 0.0;  // damping from v^{n-1/2}

  const double dt_new = c.dt_new;
  if (dt_new < model_.time.min_step_ratio * dt_initial_) {
    std::ostringstream os;
    os << "numerical instability: the stable time step fell to " << dt_new << " s ("
       << dt_new / dt_initial_ << " of the initial " << dt_initial_ << " s) at t = " << t_
       << " s, cycle " << cycle_ << "; controlled by " << element_noun(c.st.kind) << " "
       << c.st.element << " at " << element_position(c.st, a.x)
       << " (severely distorted or inverted)";
    throw NumericalError(os.str());
  }
}

// v^{n+1/2} of every DOF (x^{n+1} too when the callback does not read x^n), constrained and
// freed DOFs held at their velocities; the works of each force kind over the increments around
// t^n and the kinetic energy into c (this rank's share).
void ExplicitSolver::update_velocities(const CycleArrays& a, Cycle& c) {
  const std::size_t nd = 3 * model_.mesh.n_nodes();
  const double dt_new = c.dt_new, alpha = c.alpha;
  // Prescribed velocities at t^{n+1/2}.
  c.t_half = t_ + 0.5 * dt_new;
  std::vector<V3>& vpres = vpres_;
  for (std::size_t k = 0; k < vpres.size(); ++k)
    vpres[k] =
        smooth_ramp(c.t_half - model_.velocities[k].start_time, model_.velocities[k].ramp_time) *
        model_.velocities[k].velocity;

  const double dt_mid = c.dt_mid = 0.5 * (dt_prev_ + dt_new);
  // Unless the callback reads x^n the position update joins this loop (one pass over the
  // nodal arrays).
  double* xfused = c.move_x_in_pass ? a.x : nullptr;
  const double* inv_m = inv_mass_.data();
  const double* fe = c.has_ext ? a.fe : zero_.data();
  const double* fcon = c.has_contact ? a.fc : zero_.data();
  double* fdamp = a.fd;
  double* rr = a.r;
  double* vel = a.v;
  const double* mm = a.m;
  // Constrained DOFs keep their v^{n-1/2} aside: the free update below runs over every DOF
  // without branches (it vectorises), then those DOFs are corrected.
  // With the positions moved in the pass their x^n too, so that a held DOF ends at
  // x^n + dt v^{n+1/2} exactly as in a separate position pass.
  for (std::size_t k = 0; k < constrained_.size(); ++k) constrained_vo_[k] = vel[constrained_[k]];
  freeing_vo_.resize(freeing_.size());
  for (std::size_t k = 0; k < freeing_.size(); ++k) freeing_vo_[k] = vel[freeing_[k]];
  if (xfused) {
    constrained_xo_.resize(constrained_.size());
    for (std::size_t k = 0; k < constrained_.size(); ++k)
      constrained_xo_[k] = xfused[constrained_[k]];
    freeing_xo_.resize(freeing_.size());
    for (std::size_t k = 0; k < freeing_.size(); ++k) freeing_xo_[k] = xfused[freeing_[k]];
  }
  const double dtp = dt_prev_;
  // Without damping this cycle f_damp is left alone by the pass, so it is cleared once here.
  if (alpha == 0 && !f_damp_zero_) std::fill(fdamp, fdamp + nd, 0.0);
  f_damp_zero_ = alpha == 0;
  const std::size_t kind =
      (xfused ? 8 : 0) + (c.has_ext ? 4 : 0) + (c.has_contact ? 2 : 0) + (alpha != 0 ? 1 : 0);
  const NodeUpdateSums s =
      domain_ ? owned_node_update(kNodeUpdates[kind], domain_->owned_runs(), alpha, dt_mid, dt_new,
                                  inv_m, mm, a.fi, fe, fcon, vel, fdamp, xfused)
              : kNodeUpdates[kind](nd, alpha, dt_mid, dt_new, inv_m, mm, a.fi, fe, fcon, vel, fdamp,
                                   xfused);
  double &ext_old = c.ext_old, &ext_new = c.ext_new, &damp_old = c.damp_old, &damp_new = c.damp_new,
         &con_old = c.con_old, &con_new = c.con_new, &ke = c.ke;
  ext_old = s.ext_old, ext_new = s.ext_new, damp_old = s.damp_old, damp_new = s.damp_new;
  con_old = s.con_old, con_new = s.con_new, ke = s.ke;
  // Works over the increments du_old = dt_prev v^{n-1/2}, du_new = dt_new v^{n+1/2}; kinetic
  // energy in product form: with the trapezoidal works, 1/2 v^{n-1/2} M v^{n+1/2} makes the
  // discrete energy balance of central differences exact for conservative forces.
  ext_old *= dtp, ext_new *= dt_new, damp_old *= dtp, damp_new *= dt_new, con_old *= dtp,
      con_new *= dt_new;
  ext_old += 2.0 * mass_scaling_work_;  // booked whole in this cycle (WorkAccumulator halves it)
  mass_scaling_work_ = 0;
  ke *= 0.5;
  const double inv_dt_mid = dt_mid > 0 ? 1.0 / dt_mid : 0.0;
  for (auto& m : motions_) m->velocities(c.t_half, motion_v_.data());
  // Holds DOF d (v^{n-1/2} = vo, free v^{n+1/2} in vel) at velocity vp: the works of the forces
  // over the new increment and the kinetic energy are corrected; returns the reaction.
  const auto hold = [&](std::size_t d, double vo, double vp, double xo) {
    const double m = mm[d], vfree = vel[d], dv = vp - vfree;
    vel[d] = vp;
    if (xfused) xfused[d] = xo + dt_new * vp;
    ext_new += fe[d] * dt_new * dv;
    damp_new += fdamp[d] * dt_new * dv;
    con_new += fcon[d] * dt_new * dv;
    ke += 0.5 * m * vo * dv;
    return m * dv * inv_dt_mid;
  };
  for (std::size_t k = 0; k < constrained_.size(); ++k) {
    const std::size_t d = constrained_[k];
    const std::uint8_t code = fixed_mask_[d];
    const double vo = constrained_vo_[k];
    double vp = 0.0;
    if (code == 254) {
      vp = motion_v_[k];
    } else if (code > 1) {
      vp = vpres[code - 2].arr()[d % 3];
    }
    const double r = hold(d, vo, vp, xfused ? constrained_xo_[k] : 0.0);
    rr[d] = r;
    ext_old += r * dtp * vo;
    ext_new += r * dt_new * vp;
  }
  // Nodes freed by erosion this cycle (free_orphan_nodes) are held at rest like a fixed DOF;
  // the work of that reaction, 1/2 r du_old as the external work would book it, is their
  // kinetic energy (product form), which leaves the model. Then a zero inverse mass keeps them.
  for (std::size_t k = 0; k < freeing_.size(); ++k) {
    const std::size_t d = freeing_[k];
    const double vo = freeing_vo_[k];
    energy_.eroded_kinetic -= 0.5 * hold(d, vo, 0.0, xfused ? freeing_xo_[k] : 0.0) * dtp * vo;
    inv_mass_[d] = 0;
  }
  freeing_.clear();
  // How far any node of this rank can have moved in this cycle (x += dt v; the rounding of a
  // component's sum at most doubles its increment): the rigid tools skip their displacement
  // check while this bound cannot have taken a node past their margin (same results).
  double v_max = s.v_max;
  for (const std::size_t d : constrained_) v_max = std::max(v_max, std::abs(vel[d]));
  node_travel_ += 3.5 * dt_new * v_max;
  // An eroded element's nodes may be owned elsewhere: their v^{n+1/2} first.
  if (domain_ && eroded_any_) domain_->refresh_ghosts(vel);
  for (const auto& ef : eroded_forces_)  // see ErodedForce
    for (int I = 0; I < ef.n_nodes; ++I)
      for (int k = 0; k < 3; ++k)
        energy_.internal +=
            0.5 * ef.f[3 * I + k] * dt_new * vel[3 * static_cast<std::size_t>(ef.node[I]) + k];
  eroded_forces_.clear();
}

// Several ranks: works, kinetic energy, element energy increments, energies booked by erosion,
// friction, tool forces and the rigs' wall works, each rank holding its nodes' and elements'
// share, summed over the ranks (one reduction).
void ExplicitSolver::sum_over_ranks(Cycle& c) {
  const auto tr = Clock::now();
  const auto& booked0 = c.booked0;
  const auto& inc = c.inc;
  std::vector<double>& r = reduce_buffer_;
  r.assign({c.ext_old, c.ext_new, c.damp_old, c.damp_new, c.con_old, c.con_new, c.ke, inc.internal,
            inc.stabilisation, inc.hourglass, inc.kinetic, energy_.internal - booked0[0],
            energy_.eroded_internal - booked0[1], energy_.eroded_kinetic - booked0[2]});
  double fr_rank = 0;  // friction dissipated so far, this rank's share
  for (const auto& tool : model_.tools) fr_rank += tool.friction_dissipation;
  for (const auto& k : model_.contacts) fr_rank += k->friction_dissipation();
  r.push_back(fr_rank);
  for (const auto& tool : model_.tools)
    r.insert(r.end(), {tool.force.x, tool.force.y, tool.force.z});
  // The rigs' walls push this rank's nodes: their work (rig and on the nodes) is its share.
  std::array<double, 4> mw = {0, 0, 0, 0};
  for (auto& m : motions_)
    if (m->has_forces())
      m->add_force_work(t_ - 0.5 * dt_prev_, c.t_half, dt_prev_, c.dt_new, mw[0], mw[1], mw[2],
                        mw[3]);
  if (has_motion_forces_) r.insert(r.end(), mw.begin(), mw.end());
  // The loop's requests (raise_requests), one count per flag: 0 where no rank raised it.
  const std::size_t at_requests = r.size();
  for (unsigned b = 0; (kRequestMask >> b) != 0; ++b) r.push_back((requests_ >> b) & 1u);
  // This cycle's bound on the rank's node travel: summed, a bound for every node (the halo).
  r.push_back(node_travel_ - node_travel_sent_);
  node_travel_sent_ = node_travel_;
  MPI_Allreduce(MPI_IN_PLACE, r.data(), static_cast<int>(r.size()), MPI_DOUBLE, MPI_SUM,
                domain_->comm());
  requests_all_ranks_ = 0;
  for (unsigned b = 0; (kRequestMask >> b) != 0; ++b)
    if (r[at_requests + b] > 0) requests_all_ranks_ |= 1u << b;
  halo_travel_ += r.back();
  travel_all_ranks_ += r.back();
  c.ext_old = r[0], c.ext_new = r[1], c.damp_old = r[2], c.damp_new = r[3], c.con_old = r[4],
  c.con_new = r[5], c.ke = r[6];
  energy_.internal = booked0[0] + r[11] + r[7];
  energy_.eroded_internal = booked0[1] + r[12];
  energy_.eroded_kinetic = booked0[2] + r[13];
  energy_.stabilisation += r[8];
  energy_.hourglass += r[9];
  energy_.rotational_kinetic += r[10];
  friction_all_ranks_ = r[14];
  for (std::size_t k = 0; k < model_.tools.size(); ++k)
    model_.tools[k].force = {r[15 + 3 * k], r[16 + 3 * k], r[17 + 3 * k]};
  if (has_motion_forces_)
    std::copy(r.begin() + static_cast<std::ptrdiff_t>(at_requests) - 4,
              r.begin() + static_cast<std::ptrdiff_t>(at_requests), motion_work_all_ranks_.begin());
  timers_.exchange += seconds_since(tr);
}

// The works of the cycle, the tools' velocities over the next half step and their works, and the
// energy balance at t^n.
void ExplicitSolver::book_energies(const CycleArrays& a, Cycle& c) {
  const double t_half = c.t_half, dt_mid = c.dt_mid, dt_new = c.dt_new;
  double& ke = c.ke;
  w_ext_.add(c.ext_old, c.ext_new);
  w_damp_.add(c.damp_old, c.damp_new);
  w_contact_nodes_.add(c.con_old, c.con_new);

  // Tools: velocity over the next half step, and their work.
  double tool_on_nodes_old = 0, tool_on_nodes_new = 0, tool_src_old = 0, tool_src_new = 0;
  for (auto& tool : model_.tools) {
    const V3 vo = tool.velocity;
    V3 vn;
    if (tool.motion.kind == ToolMotion::Kind::Velocity) {
      vn = tool_prescribed_velocity(tool, t_half);
    } else if (tool.motion.kind == ToolMotion::Kind::Force) {
      const V3 ax = tool.motion.axis;
      const double acc = (tool.motion.force + dot(tool.force, ax)) / tool.motion.mass;
      vn = (dot(vo, ax) + dt_mid * acc) * ax;
      ke += 0.5 * tool.motion.mass * dot(vo, vn);
    }
    tool.velocity = vn;
    // The tool pushes the nodes with -tool.force.
    tool_on_nodes_old += -dot(tool.force, dt_prev_ * vo);
    tool_on_nodes_new += -dot(tool.force, dt_new * vn);
    if (tool.motion.kind == ToolMotion::Kind::Velocity) {
      tool_src_old += -dot(tool.force, dt_prev_ * vo);
      tool_src_new += -dot(tool.force, dt_new * vn);
    } else if (tool.motion.kind == ToolMotion::Kind::Force) {
      const V3 F = tool.motion.force * tool.motion.axis;
      tool_src_old += dot(F, dt_prev_ * vo);
      tool_src_new += dot(F, dt_new * vn);
    }
  }
  // Rigs' walls: driven like velocity tools, so their work on the nodes is the rig's (external)
  // work; the contact energy keeps the penalty energy stored.
  if (!domain_) {
    for (auto& m : motions_)
      if (m->has_forces())
        m->add_force_work(t_ - 0.5 * dt_prev_, t_half, dt_prev_, dt_new, tool_src_old, tool_src_new,
                          tool_on_nodes_old, tool_on_nodes_new);
  } else if (has_motion_forces_) {  // summed over the ranks (sum_over_ranks)
    const auto& mw = motion_work_all_ranks_;
    tool_src_old += mw[0], tool_src_new += mw[1];
    tool_on_nodes_old += mw[2], tool_on_nodes_new += mw[3];
  }
  w_tools_.add(tool_src_old, tool_src_new);
  tool_work_on_nodes_.add(tool_on_nodes_old, tool_on_nodes_new);

  energy_.time = t_;
  energy_.kinetic = ke + energy_.rotational_kinetic;
  energy_.external_work = w_ext_.committed + w_tools_.committed;
  energy_.damping = -w_damp_.committed;
  energy_.contact = tool_work_on_nodes_.committed - w_contact_nodes_.committed;
  double fr = 0;
  for (const auto& tool : model_.tools) fr += tool.friction_dissipation;
  for (const auto& k : model_.contacts) fr += k->friction_dissipation();
  energy_.friction = domain_ ? friction_all_ranks_ : fr;
  energy_.scale_max = std::max(energy_.scale_max, energy_.scale());
  if (!std::isfinite(ke)) check_finite(a.v);
}

// x^{n+1} (already moved in the velocity pass unless the callback reads x^n), the ghosts' x and
// v from their owners, the tools' displacements, and the clock on to t^{n+1}.
void ExplicitSolver::finish_cycle(const Cycle& c) {
  const std::size_t nd = 3 * model_.mesh.n_nodes();
  const double dt_new = c.dt_new;
  if (!c.move_x_in_pass) {
    auto X = x.view();
    auto Vv = v.view();
    if (domain_) {
      for (const auto& [b, e] : domain_->owned_runs())
        for (std::size_t d = 3 * b; d < 3 * e; ++d) X[d] += dt_new * Vv[d];
    } else {
      for (std::size_t d = 0; d < nd; ++d) X[d] += dt_new * Vv[d];
    }
  }
  if (domain_) {
    const auto t0 = Clock::now();
    auto X = x.view();
    auto Vv = v.view();
    domain_->refresh_ghosts(X.data(), Vv.data());
    timers_.exchange += seconds_since(t0);
  }
  for (auto& tool : model_.tools) tool.displacement += dt_new * tool.velocity;
  t_ += dt_new;
  dt_prev_ = dt_new;
  dt_ = dt_new;
  ++cycle_;
  // What the first cycles allocated (the contacts' first sort, the output's buffers) lies in new
  // mappings that the set-up's advice did not reach.
  if (++cycles_here_ == kHugePageSecondLook) huge_pages_ = advise_huge_pages();
}

}  // namespace ncfsim::fem
