// ExplicitSolver on several MPI ranks (docs/parallel.md): the decomposition, the gather of the
// whole model for output on the root, a blow-up made known to every rank, and the contact halo
// (the nodes a rank reads beyond its own), built again as the nodes move.
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>

#include "fem/boundary/picture_frame_motion.hpp"
#include "fem/checkpoint.hpp"
#include "fem/contact/tied_contact.hpp"
#include "fem/errors.hpp"
#include "fem/parallel/domain.hpp"
#include "fem/solver.hpp"

namespace ncfsim::fem {

void ExplicitSolver::decompose() {
  const auto refuse = [](const std::string& key, const std::string& what) {
    throw InputError("", key, what + " cannot run on several MPI ranks yet: run it with --np 1");
  };
  {  // a rank must integrate something: at most one rank per kernel chunk of the largest group
    std::size_t most = 0, n_el = 0;
    for (const auto& g : groups_) most = std::max(most, (g->size() + g->chunk() - 1) / g->chunk());
    for (const auto& g : groups_) n_el += g->size();
    const int p = PetscSession::size();
    if (static_cast<std::size_t>(p) > most)
      throw InputError(
          "", "--np",
          std::to_string(p) + " MPI ranks for " + std::to_string(n_el) +
              " elements: the model splits into at most " + std::to_string(most) +
              " (one kernel chunk of 32 hexahedra, 64 shells or 256 bars per rank at least)");
  }
  {
    auto X0 = x0.view();
    domain_ = std::make_unique<Domain>(PETSC_COMM_WORLD, model_.mesh.n_nodes(), X0.data(), groups_);
  }
  for (int r = 0; r < domain_->size(); ++r) {
    std::size_t n_el = 0;
    for (std::size_t g = 0; g < groups_.size(); ++g)
      n_el += domain_->range(g, r).second - domain_->range(g, r).first;
    if (n_el == 0)
      throw InputError(
          "", "--np",
          "rank " + std::to_string(r) + " of " + std::to_string(domain_->size()) +
              " gets no element (the model's elements come in too few kernel "
              "chunks of 32 hexahedra, 64 shells or 256 bars for so many ranks): fewer ranks");
  }
  for (std::size_t g = 0; g < groups_.size(); ++g) {
    const auto [b, e] = domain_->range(g);
    if (!groups_[g]->set_range(b, e))
      refuse("part." + model_.mesh.part_names[static_cast<std::size_t>(groups_[g]->part())],
             std::string("a part of ") + element_noun(groups_[g]->kind()) + " elements");
    groups_[g]->set_owned_nodes(domain_->owned_mask().data());
  }
  // Each node meets each tool on the rank that owns it.
  for (auto& tool : model_.tools)
    std::erase_if(tool.contact_nodes,
                  [&](std::int32_t i) { return !domain_->owns(static_cast<std::size_t>(i)); });
}

void ExplicitSolver::gather_for_output() {
  if (!domain_) return;
  for (NodalVector* vec : {&x, &v, &f_int, &f_ext, &f_contact, &f_damp, &reaction}) {
    auto a = vec->view();
    domain_->gather_to_root(a.data());
  }
  for (std::size_t g = 0; g < groups_.size(); ++g)
    for (const auto& [data, comps] : groups_[g]->state_arrays())
      domain_->gather_group_array(g, data, groups_[g]->size(), comps);
  for (auto& tool : model_.tools) {
    std::int64_t active = tool.n_active;
    double pen = tool.max_penetration;
    MPI_Reduce(domain_->root() ? MPI_IN_PLACE : &active, &active, 1, MPI_INT64_T, MPI_SUM, 0,
               domain_->comm());
    MPI_Reduce(domain_->root() ? MPI_IN_PLACE : &pen, &pen, 1, MPI_DOUBLE, MPI_MAX, 0,
               domain_->comm());
    if (domain_->root()) tool.n_active = active, tool.max_penetration = pen;
  }
  {  // what each rank holds and where its time went (load balance)
    std::size_t n_el = 0;
    for (std::size_t g = 0; g < groups_.size(); ++g)
      n_el += domain_->range(g).second - domain_->range(g).first;
    const double mine[] = {static_cast<double>(n_el),
                           static_cast<double>(domain_->n_owned()),
                           static_cast<double>(domain_->n_ghosts()),
                           static_cast<double>(domain_->ghost_bytes_per_cycle()),
                           timers_.internal_force,
                           timers_.contact,
                           timers_.update,
                           timers_.exchange};
    constexpr int kN = static_cast<int>(std::size(mine));
    std::vector<double> all(domain_->root() ? kN * static_cast<std::size_t>(domain_->size()) : 0);
    MPI_Gather(mine, kN, MPI_DOUBLE, all.data(), kN, MPI_DOUBLE, 0, domain_->comm());
    rank_reports_.clear();
    for (std::size_t r = 0; domain_->root() && r < static_cast<std::size_t>(domain_->size()); ++r) {
      const double* a = &all[kN * r];
      rank_reports_.push_back({static_cast<std::size_t>(a[0]), static_cast<std::size_t>(a[1]),
                               static_cast<std::size_t>(a[2]), static_cast<std::size_t>(a[3]),
                               PhaseTimers{a[4], a[5], a[6], 0.0, a[7]}});
    }
  }
  if (frames_) {  // the walls' power and contacts of each frame, summed over the ranks
    const std::size_t nf = model_.picture_frames.size();
    std::vector<double> buf(2 * nf);
    for (std::size_t k = 0; k < nf; ++k)
      buf[k] = frames_->wall_power(k), buf[nf + k] = static_cast<double>(frames_->wall_contacts(k));
    MPI_Reduce(domain_->root() ? MPI_IN_PLACE : buf.data(), buf.data(),
               static_cast<int>(buf.size()), MPI_DOUBLE, MPI_SUM, 0, domain_->comm());
    frame_wall_power_.assign(buf.begin(), buf.begin() + static_cast<std::ptrdiff_t>(nf));
    frame_wall_contacts_.clear();
    for (std::size_t k = 0; k < nf; ++k)
      frame_wall_contacts_.push_back(static_cast<std::int64_t>(buf[nf + k]));
  }
  // Tied contacts: the ties other ranks hold failed or intact, into the root's copy (each rank
  // updates only its own).
  for (const auto& c : model_.contacts)
    if (auto* tied = dynamic_cast<TiedContact*>(c.get())) {
      std::vector<std::uint8_t> states = tied->tie_states();
      MPI_Reduce(domain_->root() ? MPI_IN_PLACE : states.data(), states.data(),
                 static_cast<int>(states.size()), MPI_UINT8_T, MPI_MIN, 0, domain_->comm());
      if (domain_->root()) tied->take_other_ranks_tie_states(states);
    }
  contact_resultants_.resize(model_.contacts.size());
  contact_max_penetration_.resize(model_.contacts.size());
  for (std::size_t k = 0; k < model_.contacts.size(); ++k) {
    auto res = model_.contacts[k]->resultants();
    std::vector<double> buf;
    for (const auto& r : res) buf.insert(buf.end(), {r.force.x, r.force.y, r.force.z});
    double pen = model_.contacts[k]->max_penetration();
    MPI_Reduce(domain_->root() ? MPI_IN_PLACE : buf.data(), buf.data(),
               static_cast<int>(buf.size()), MPI_DOUBLE, MPI_SUM, 0, domain_->comm());
    MPI_Reduce(domain_->root() ? MPI_IN_PLACE : &pen, &pen, 1, MPI_DOUBLE, MPI_MAX, 0,
               domain_->comm());
    for (std::size_t j = 0; j < res.size(); ++j) res[j].force = V3::at(&buf[3 * j]);
    contact_resultants_[k] = std::move(res);
    contact_max_penetration_[k] = pen;
  }
}

void ExplicitSolver::share_blow_up(const std::string& what) const {
  int from = what.empty() || what == "-" ? domain_->size() : domain_->rank();
  MPI_Allreduce(MPI_IN_PLACE, &from, 1, MPI_INT, MPI_MIN, domain_->comm());
  throw_blow_up_of(from, what);
}

void ExplicitSolver::throw_blow_up_of(int from, const std::string& what) const {
  if (from >= domain_->size()) return;  // no rank has one
  std::string msg = what;
  int len = static_cast<int>(msg.size());
  MPI_Bcast(&len, 1, MPI_INT, from, domain_->comm());
  msg.resize(static_cast<std::size_t>(len));
  MPI_Bcast(msg.data(), len, MPI_CHAR, from, domain_->comm());
  throw NumericalError(msg);
}

// Several ranks: a rank reads the remote contact segments within the halo of its own surface
// nodes. As the surfaces slide, the halo is built again at the nodes' current positions before
// any could have slid `contact_halo_refresh` of it relative to another surface (each node at most
// half that from its position at the last build): exact, the contacts found are those of a halo
// built at the start wide enough for the whole run. The decision is the same on every rank (a
// bound summed over the ranks, then a max over the ranks).
void ExplicitSolver::refresh_contact_halo(double* x, double* v) {
  const double share = model_.parallel.contact_halo_refresh;
  if (share <= 0) return;
  if (halo_due_) {  // a resume: the halo of the last build, at the positions it was built at
    if (halo_x_.empty()) {  // a checkpoint without them: at the saved positions
      domain_->gather_to_all(x);
      halo_x_.assign(x, x + 3 * model_.mesh.n_nodes());
      halo_travel_ = halo_checked_d_ = halo_travel_checked_ = 0;
    }
    build_contact_halo(x, v);
    halo_due_ = false;
    return;
  }
  const double reach = 0.5 * share * model_.parallel.contact_halo;
  if (halo_checked_d_ + (halo_travel_ - halo_travel_checked_) < reach) return;
  double d2 = 0;
  for (const auto& [b, e] : domain_->owned_runs())
    for (std::size_t i = b; i < e; ++i) {
      const double dx = x[3 * i] - halo_x_[3 * i], dy = x[3 * i + 1] - halo_x_[3 * i + 1],
                   dz = x[3 * i + 2] - halo_x_[3 * i + 2];
      d2 = std::max(d2, dx * dx + dy * dy + dz * dz);
    }
  double d = std::sqrt(d2);
  MPI_Allreduce(MPI_IN_PLACE, &d, 1, MPI_DOUBLE, MPI_MAX, domain_->comm());
  if (d < reach) {
    halo_checked_d_ = d, halo_travel_checked_ = halo_travel_;
    return;
  }
  // Every node's position from its owner (a rank's copies of the nodes it does not read are
  // stale), the halo at those positions.
  domain_->gather_to_all(x);
  halo_x_.assign(x, x + 3 * model_.mesh.n_nodes());
  halo_travel_ = halo_checked_d_ = halo_travel_checked_ = 0;
  build_contact_halo(x, v);
  ++halo_builds_;
}

// The contacts' halo at the positions halo_x_, and the ghosts that go with it (x, v refreshed).
void ExplicitSolver::build_contact_halo(double* x, double* v) {
  std::vector<std::int32_t> extra, part;
  for (auto& c : model_.contacts) {
    part.clear();
    c->nodes_to_read(domain_->owned_mask().data(), halo_x_.data(), model_.parallel.contact_halo,
                     part);
    extra.insert(extra.end(), part.begin(), part.end());
  }
  domain_->rebuild_ghosts(extra, x, v);
  for (auto& c : model_.contacts)
    c->restrict_to_rank(domain_->owned_mask().data(), domain_->readable_mask().data());
}

}  // namespace ncfsim::fem
