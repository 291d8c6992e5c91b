// ExplicitSolver: element erosion (a folded element, or one whose step fell under the limit),
// agreed over the ranks, and the nodes it leaves without an element.
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
#include "fem/solver.hpp"

namespace ncfsim::fem {

namespace {
// Centroid at x of element e of a block with nn nodes per element, connectivity [nn][stride].
V3 centroid(const std::int32_t* conn, std::size_t stride, std::size_t e, int nn, const double* x) {
  V3 c;
  for (int I = 0; I < nn; ++I)
    c += (1.0 / nn) *
         V3::at(x + 3 * static_cast<std::size_t>(conn[static_cast<std::size_t>(I) * stride + e]));
  return c;
}
}  // namespace

std::string ExplicitSolver::element_position(const StableStep& st, const double* x) const {
  auto centre = [&](const std::int32_t* conn, std::size_t stride, std::size_t e, int nn) {
    const V3 c = centroid(conn, stride, e, nn, x);
    std::ostringstream os;
    os << "(" << c.x << ", " << c.y << ", " << c.z << ") m";
    return os.str();
  };
  for (const auto& g : groups_)
    if (g->kind() == st.kind)
      for (std::size_t e = 0; e < g->size(); ++e)
        if (g->user_id(e) == st.element)
          return centre(g->conn(), g->size(), e, g->nodes_per_element());
  return "(unknown position)";
}

double ExplicitSolver::mass_cap_erosion_step() const {
  return model_.time.mass_scaling_erode_at_cap
             ? model_.time.mass_scaling_dt * (1 - kMassScalingBelowShare)
             : 0.0;
}

void ExplicitSolver::erode(const double* x, const double* v, double dt_erode, bool check_steps,
                           const std::string& blow_up) {
  const double sf = model_.time.safety_factor;
  // Dynamic mass scaling with time.mass_scaling_erode_at_cap: an element at the cap below the
  // target step cannot be held by mass any more.
  const double cap_dt = mass_cap_erosion_step();
  const double cap_ratio = model_.time.mass_scaling_max_ratio;
  std::vector<std::int32_t> gone;  // mesh-wide element indices
  std::vector<std::int32_t> orphans;
  std::vector<std::size_t> failed;
  // A rank whose kernels blew up only takes part in the sharing below, which tells the others.
  for (std::size_t k = 0; k < groups_.size() && blow_up.empty(); ++k) {
    ElementGroup& g = *groups_[k];
    if (!g.can_erode()) continue;
    failed.clear();
    g.failed_elements(failed);
    if (!check_steps && failed.empty()) continue;
    g.element_steps(x, step_scratch_, &jacobian_scratch_);
    std::vector<char> material_failed(failed.empty() ? 0 : g.size(), 0);
    for (auto e : failed) material_failed[e] = 1;
    const int nn = g.nodes_per_element();
    const std::size_t offset = model_.mesh.element_offset(g.kind());
    StableStep left;
    const auto [e_begin, e_end] =
        domain_ ? domain_->range(k) : std::pair<std::size_t, std::size_t>{0, g.size()};
    for (std::size_t e = e_begin; e < e_end; ++e) {
      const double dt = step_scratch_[e];
      const bool folded = check_steps && dt_erode > 0 && !(jacobian_scratch_[e] > 0);
      const bool too_small = check_steps && dt_erode > 0 && sf * dt < dt_erode;
      const bool broken = !material_failed.empty() && material_failed[e];
      const bool capped =
          check_steps && !too_small && !folded && sf * dt < cap_dt && g.at_mass_cap(e, cap_ratio);
      if (!too_small && !folded && !broken && !capped) {
        if (dt < left.dt) left = {dt, g.user_id(e), g.kind()};
        continue;
      }
      using Cause = ErosionEvent::Cause;
      const ErosionEvent ev{broken   ? Cause::MaterialFailure
                            : folded ? Cause::InvertedCorner
                            : capped ? Cause::MassCap
                                     : Cause::StableStep,
                            t_,
                            cycle_,
                            g.user_id(e),
                            g.kind(),
                            g.part(),
                            sf * dt,
                            centroid(g.conn(), g.size(), e, nn, x)};
      ErodedForce& ef = eroded_forces_.emplace_back();
      ef.n_nodes = nn;
      for (int I = 0; I < nn; ++I) {
        const std::int32_t node = g.conn()[static_cast<std::size_t>(I) * g.size() + e];
        ef.node[I] = node;
        if (--node_elements_[static_cast<std::size_t>(node)] == 0) orphans.push_back(node);
      }
      g.element_force(e, x, v, ef.f);
      energy_.eroded_internal += g.erode(e);
      gone.push_back(static_cast<std::int32_t>(offset + static_cast<std::size_t>(g.set_index(e))));
      erosions_.push_back(ev);
      if (domain_) local_erosions_.push_back({k, e});
    }
    group_step_[k] = left;
  }
  if (domain_) share_erosions(gone, orphans, blow_up);
  if (!gone.empty())
    for (auto& c : model_.contacts) c->erode(gone);
  if (!orphans.empty()) free_orphan_nodes(orphans);
}

// Several ranks: every rank learns the elements the others eroded this cycle (in the order one
// rank would have eroded them: group, then element), takes them out of its copies of the groups,
// contacts and node counts, and lists the events; each rank has booked the energies of its own.
void ExplicitSolver::share_erosions(std::vector<std::int32_t>& gone,
                                    std::vector<std::int32_t>& orphans,
                                    const std::string& blow_up) {
  constexpr int kFields = 12;
  const std::size_t n_mine = local_erosions_.size();
  std::vector<double> mine;
  for (std::size_t q = 0; q < n_mine; ++q) {
    const ErosionEvent& ev = erosions_[erosions_.size() - n_mine + q];
    mine.insert(mine.end(),
                {static_cast<double>(local_erosions_[q].first),
                 static_cast<double>(local_erosions_[q].second), static_cast<double>(ev.cause),
                 ev.time, static_cast<double>(ev.cycle), static_cast<double>(ev.element),
                 static_cast<double>(ev.kind), static_cast<double>(ev.part), ev.step, ev.centroid.x,
                 ev.centroid.y, ev.centroid.z});
  }
  local_erosions_.clear();
  const int p = domain_->size();
  std::vector<int> counts(static_cast<std::size_t>(p)), displs(static_cast<std::size_t>(p));
  int n = static_cast<int>(mine.size());
  // With each rank's count goes whether its kernels blew up: the report needs no collective
  // of its own.
  std::vector<int> sent(2 * static_cast<std::size_t>(p));
  const std::array<int, 2> pair{n, blow_up.empty() ? 0 : 1};
  MPI_Allgather(pair.data(), 2, MPI_INT, sent.data(), 2, MPI_INT, domain_->comm());
  int from = p;
  for (int r = p - 1; r >= 0; --r) {
    counts[static_cast<std::size_t>(r)] = sent[2 * static_cast<std::size_t>(r)];
    if (sent[2 * static_cast<std::size_t>(r) + 1]) from = r;
  }
  throw_blow_up_of(from, blow_up);
  int total = 0;
  for (int r = 0; r < p; ++r)
    displs[static_cast<std::size_t>(r)] = total, total += counts[static_cast<std::size_t>(r)];
  eroded_any_ = total > 0;
  if (total == 0) return;
  std::vector<double> all(static_cast<std::size_t>(total));
  MPI_Allgatherv(mine.data(), n, MPI_DOUBLE, all.data(), counts.data(), displs.data(), MPI_DOUBLE,
                 domain_->comm());
  std::vector<std::size_t> order(static_cast<std::size_t>(total / kFields));
  std::iota(order.begin(), order.end(), std::size_t{0});
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return std::pair{all[kFields * a], all[kFields * a + 1]} <
           std::pair{all[kFields * b], all[kFields * b + 1]};
  });
  erosions_.resize(erosions_.size() - n_mine);
  gone.clear();
  for (std::size_t q : order) {
    const double* f = &all[kFields * q];
    const auto k = static_cast<std::size_t>(f[0]), e = static_cast<std::size_t>(f[1]);
    ElementGroup& g = *groups_[k];
    erosions_.push_back({static_cast<ErosionEvent::Cause>(static_cast<int>(f[2])), f[3],
                         static_cast<std::int64_t>(f[4]), static_cast<std::int64_t>(f[5]),
                         static_cast<ElementKind>(static_cast<int>(f[6])), static_cast<int>(f[7]),
                         f[8], V3{f[9], f[10], f[11]}});
    gone.push_back(static_cast<std::int32_t>(model_.mesh.element_offset(g.kind()) +
                                             static_cast<std::size_t>(g.set_index(e))));
    const auto [b, end] = domain_->range(k);
    if (e >= b && e < end) continue;  // mine: done in erode()
    g.erode(e);                       // its energy was booked by the rank that integrates it
    for (int I = 0; I < g.nodes_per_element(); ++I) {
      const std::int32_t node = g.conn()[static_cast<std::size_t>(I) * g.size() + e];
      if (--node_elements_[static_cast<std::size_t>(node)] == 0) orphans.push_back(node);
    }
  }
}

// A node no element holds would drift on with its last velocity, hit the tools and feed them
// forces from nothing (LS-DYNA deletes such nodes with their elements). It is stopped where it is:
// in this cycle's node update it is held like a fixed DOF, and the work of that reaction, its
// kinetic energy, leaves the model as eroded kinetic energy; from then on a zero inverse mass
// keeps it at rest without a branch in the node update. It leaves the tools' contact nodes (the
// penalty contacts have already dropped it: all its faces were eroded).
void ExplicitSolver::free_orphan_nodes(const std::vector<std::int32_t>& candidates) {
  bool any = false;
  for (const std::int32_t node : candidates) {
    const auto i = static_cast<std::size_t>(node);
    if (node_elements_[i] != 0 || node_freed_[i]) continue;
    if (fixed_mask_[3 * i] || fixed_mask_[3 * i + 1] || fixed_mask_[3 * i + 2]) continue;
    if (!domain_ || domain_->owns(i))  // its owner holds it (and books its kinetic energy)
      for (std::size_t d = 3 * i; d < 3 * i + 3; ++d) freeing_.push_back(d);
    node_freed_[i] = 1;
    ++n_freed_nodes_;
    any = true;
  }
  if (any)
    for (auto& tool : model_.tools) remove_tool_contact_nodes(tool, node_freed_);
}

}  // namespace ncfsim::fem
