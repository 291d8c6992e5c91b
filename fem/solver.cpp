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
// Centroid at x of element e of a block with nn nodes per element, connectivity [nn][stride].
V3 centroid(const std::int32_t* conn, std::size_t stride, std::size_t e, int nn, const double* x) {
  V3 c;
  for (int I = 0; I < nn; ++I)
    c += (1.0 / nn) *
         V3::at(x + 3 * static_cast<std::size_t>(conn[static_cast<std::size_t>(I) * stride + e]));
  return c;
}
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

ExplicitSolver::ExplicitSolver(Model& model) : model_(model) {
  Mesh& mesh = model_.mesh;
  mesh.fill_default_user_ids();
  try {
    mesh.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError("", "mesh", e.what());
  }
  if (mesh.n_nodes() == 0 || mesh.n_elements() == 0)
    throw InputError("", "mesh", "the model has no elements");
  if (model_.parts.size() != mesh.part_names.size())
    throw InputError("", "parts", "every mesh part needs properties");
  if (!(model_.time.end_time > 0)) throw InputError("", "time.end_time", "must be > 0");
  if (!(model_.time.safety_factor > 0 && model_.time.safety_factor <= 1))
    throw InputError("", "time.safety_factor", "must be in (0, 1]");

  const std::size_t n = mesh.n_nodes();
  for (NodalVector* vec : {&x0, &x, &v, &mass, &f_int, &f_ext, &f_contact, &f_damp, &reaction})
    *vec = NodalVector(n);
  {
    auto X0 = x0.view();
    auto X = x.view();
    std::copy(mesh.coords.begin(), mesh.coords.end(), X0.data());
    std::copy(mesh.coords.begin(), mesh.coords.end(), X.data());
  }
  build_blocks();
  for (const auto& g : groups_)
    material_failure_ = material_failure_ || (g->can_erode() && g->material_can_fail());
  if (erosion_enabled()) {
    node_elements_.assign(n, 0);
    node_freed_.assign(n, 0);
    for (const auto& g : groups_)
      for (std::size_t k = 0; k < g->size() * static_cast<std::size_t>(g->nodes_per_element()); ++k)
        ++node_elements_[static_cast<std::size_t>(g->conn()[k])];
  }
  assemble_mass();
  {  // gravity acts on the physical mass only: mass scaling adds inertia, not weight
    auto M = mass.view();
    gravity_mass_.assign(M.data(), M.data() + 3 * n);
  }
  if (model_.time.mass_scaling_dt > 0) {
    apply_mass_scaling();
    assemble_mass();
  }
  {
    auto M = mass.view();
    inv_mass_.resize(3 * n);
    for (std::size_t d = 0; d < 3 * n; ++d) inv_mass_[d] = 1.0 / M[d];
  }

  if (PetscSession::size() > 1) decompose();

  fixed_mask_.assign(3 * n, 0);
  for (const auto& fx : model_.fixed)
    for (auto node : fx.nodes)
      for (int c = 0; c < 3; ++c)
        if (fx.dofs[c]) fixed_mask_[3 * static_cast<std::size_t>(node) + c] = 1;
  for (std::size_t k = 0; k < model_.velocities.size(); ++k) {
    const auto& pv = model_.velocities[k];
    for (auto node : pv.nodes)
      for (int c = 0; c < 3; ++c)
        if (pv.dofs[c])
          fixed_mask_[3 * static_cast<std::size_t>(node) + c] = static_cast<std::uint8_t>(2 + k);
  }
  build_motions();
  zero_.assign(3 * n, 0.0);
  if (model_.velocities.size() > 250)
    throw InputError("", "boundary.velocity", "at most 250 prescribed-velocity sets");

  {
    auto V = v.view();
    for (const auto& iv : model_.initial_velocities)
      for (auto node : iv.nodes) {
        const auto i = static_cast<std::size_t>(node);
        V[3 * i] = iv.velocity.x, V[3 * i + 1] = iv.velocity.y, V[3 * i + 2] = iv.velocity.z;
      }
    for (std::size_t d = 0; d < 3 * n; ++d)
      if (fixed_mask_[d] == 1) V[d] = 0;
    auto M = mass.view();
    double ke = 0;
    for (std::size_t d = 0; d < 3 * n; ++d) ke += 0.5 * M[d] * V[d] * V[d];
    energy_.initial_total = ke;
    energy_.kinetic = ke;
  }

  StableStep s;
  {
    auto X = x.view();
    for (const auto& g : groups_) take_smaller(s, g->stable_step(X.data()));
  }
  step_ = s;
  dt_ = model_.time.safety_factor * s.dt;
  if (!(dt_ > 0) || !std::isfinite(dt_))
    throw InputError("", "mesh",
                     "no finite stable time step (element " + std::to_string(s.element) + ")");

  for (auto& tool : model_.tools) {
    if (tool.motion.kind == ToolMotion::Kind::Force && !(tool.motion.mass > 0))
      throw InputError("", "tool." + tool.name + ".mass", "a force-driven tool needs a mass > 0");
    for (auto node : tool.contact_nodes)
      if (node < 0 || static_cast<std::size_t>(node) >= n)
        throw InputError("", "tool." + tool.name, "contact node outside the mesh");
    tool.tangential.assign(3 * tool.contact_nodes.size(), 0.0);
    tool.proximity = ToolProximity{};
    tool.displacement = {};
    tool.velocity = tool_prescribed_velocity(tool, 0.5 * dt_);
  }

  {
    auto X0 = x0.view();
    auto M = mass.view();
    ContactSetup setup{&model_.mesh, X0.data(), M.data(), dt_, erosion_enabled()};
    for (auto& c : model_.contacts) {
      c->initialise(setup);
      dt_ = std::min(dt_, c->stable_step_limit());
    }
    contact_seconds_.assign(model_.contacts.size(), 0.0);
    tool_seconds_.assign(model_.tools.size(), 0.0);
  }
  if (domain_) {
    // What each rank's contacts read of the others, then the exchange that keeps it current.
    auto X0 = x0.view();
    std::vector<std::int32_t> extra;
    for (auto& c : model_.contacts) {
      extra.clear();
      if (!c->nodes_to_read(domain_->owned_mask().data(), X0.data(), model_.parallel.contact_halo,
                            extra))
        throw InputError("", "contact." + c->name(),
                         "this contact cannot run on several MPI ranks yet: run it with --np 1");
      domain_->add_readable(extra);
    }
    domain_->finalise();
    for (auto& c : model_.contacts)
      c->restrict_to_rank(domain_->owned_mask().data(), domain_->readable_mask().data());
    halo_x_.assign(X0.data(), X0.data() + 3 * n);
  }
  dt_initial_ = dt_;
  vpres_.resize(model_.velocities.size());
}

ExplicitSolver::~ExplicitSolver() = default;

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

// One group per kind and part, kinds in ElementKind order: element forces are summed in this order.
void ExplicitSolver::build_blocks() {
  const Mesh& mesh = model_.mesh;
  auto X = x.view();
  std::vector<int> kind_of_part(model_.parts.size(), -1);
  for (const ElementSet& set : mesh.sets) {
    std::vector<std::vector<std::size_t>> of_part(model_.parts.size());
    for (std::size_t e = 0; e < set.size(); ++e)
      of_part[static_cast<std::size_t>(set.part[e])].push_back(e);
    for (std::size_t p = 0; p < of_part.size(); ++p) {
      if (of_part[p].empty()) continue;
      if (kind_of_part[p] >= 0)
        throw InputError("", "part." + mesh.part_names[p],
                         std::string("a part holds both ") +
                             element_noun(static_cast<ElementKind>(kind_of_part[p])) + " and " +
                             element_noun(set.kind) + " elements");
      kind_of_part[p] = static_cast<int>(set.kind);
      if (set.material.empty()) {
        groups_.push_back(
            make_element_group(model_, set, static_cast<int>(p), of_part[p], X.data()));
        continue;
      }
      // Elements with their own material: one group per material of the part (batches of one law).
      std::map<std::int32_t, std::vector<std::size_t>> of_material;
      for (auto e : of_part[p]) of_material[set.material[e]].push_back(e);
      for (const auto& [material, elements] : of_material)
        groups_.push_back(make_element_group(model_, set, static_cast<int>(p), elements, X.data()));
    }
  }
  group_step_.resize(groups_.size());
  group_seconds_.assign(groups_.size(), 0.0);
}

void ExplicitSolver::build_motions() {
  const std::size_t n = model_.mesh.n_nodes();
  if (!model_.picture_frames.empty()) {
    auto pf = std::make_unique<PictureFrameMotion>(model_.picture_frames);
    frames_ = pf.get();
    motions_.push_back(std::move(pf));
  }
  for (const auto& m : motions_) m->check(n);
  // Several ranks: a node meets the arms (walls) on the rank that owns it, as it meets a tool;
  // the rig's wall work and power are summed over the ranks (step, gather_for_output). Each
  // rank's motion was told it has walls from the whole lists (the ranks take the same branches).
  if (domain_)
    for (auto& pf : model_.picture_frames)
      for (auto& w : pf.walls)
        std::erase_if(w,
                      [&](std::int32_t i) { return !domain_->owns(static_cast<std::size_t>(i)); });
  // Driven nodes: code 254; the owning (motion, set) of each kept to bind its DOFs below.
  std::vector<std::pair<std::int32_t, std::int32_t>> owner(n, {-1, -1});
  for (std::size_t m = 0; m < motions_.size(); ++m)
    for (std::size_t k = 0; k < motions_[m]->n_driven_sets(); ++k)
      for (auto node : motions_[m]->driven_nodes(k)) {
        owner[static_cast<std::size_t>(node)] = {static_cast<std::int32_t>(m),
                                                 static_cast<std::int32_t>(k)};
        for (int c = 0; c < 3; ++c)
          fixed_mask_[3 * static_cast<std::size_t>(node) + static_cast<std::size_t>(c)] = 254;
      }
  for (std::size_t d = 0; d < 3 * n; ++d)
    if (fixed_mask_[d] && (!domain_ || domain_->owns(d / 3))) constrained_.push_back(d);
  constrained_vo_.resize(constrained_.size());
  motion_v_.assign(constrained_.size(), 0.0);
  auto X0 = x0.view();
  for (std::size_t k = 0; k < constrained_.size(); ++k) {
    const std::size_t d = constrained_[k];
    if (fixed_mask_[d] != 254) continue;
    const auto [m, set] = owner[d / 3];
    motions_[static_cast<std::size_t>(m)]->bind_dof(static_cast<std::size_t>(set), k, d, X0.data());
  }
  for (const auto& m : motions_) has_motion_forces_ = has_motion_forces_ || m->has_forces();
}

double ExplicitSolver::frame_wall_power(std::size_t k) const {
  if (domain_) return k < frame_wall_power_.size() ? frame_wall_power_[k] : 0.0;
  return frames_ ? frames_->wall_power(k) : 0.0;
}
std::int64_t ExplicitSolver::frame_wall_contacts(std::size_t k) const {
  if (domain_) return k < frame_wall_contacts_.size() ? frame_wall_contacts_[k] : 0;
  return frames_ ? frames_->wall_contacts(k) : 0;
}

void ExplicitSolver::apply_mass_scaling() {
  auto X = x.view();
  for (auto& g : groups_)
    g->scale_mass(X.data(), model_.time.mass_scaling_dt, model_.time.safety_factor);
}

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

void ExplicitSolver::erode(const double* x, const double* v, double dt_erode, bool check_steps,
                           const std::string& blow_up) {
  const double sf = model_.time.safety_factor;
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
      if (!too_small && !folded && !broken) {
        if (dt < left.dt) left = {dt, g.user_id(e), g.kind()};
        continue;
      }
      using Cause = ErosionEvent::Cause;
      const ErosionEvent ev{
          broken ? Cause::MaterialFailure : (folded ? Cause::InvertedCorner : Cause::StableStep),
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

void ExplicitSolver::assemble_mass() {
  mass.set(0.0);
  {
    auto M = mass.view();
    for (const auto& g : groups_) g->lumped_mass(M.data());
    const std::size_t n = model_.mesh.n_nodes();
    for (std::size_t i = 0; i < n; ++i)
      if (!(M[3 * i] > 0)) {
        const auto p = model_.mesh.node(i);
        std::ostringstream os;
        os << "node " << model_.mesh.node_user_id[i] << " at (" << p[0] << ", " << p[1] << ", "
           << p[2] << ") belongs to no element and has no mass";
        throw InputError("", "mesh", os.str());
      }
  }
  part_mass_.assign(model_.parts.size(), {});
  for (std::size_t p = 0; p < part_mass_.size(); ++p)
    part_mass_[p].part = model_.mesh.part_names[p];
  for (const auto& g : groups_) {
    auto& pm = part_mass_[static_cast<std::size_t>(g->part())];
    g->add_part_mass(pm.mass, pm.added_mass);
  }
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
    if (what.empty()) what = "-";
    share_blow_up(what);
    throw NumericalError("numerical instability: a velocity is not finite");
  }
  if (!what.empty()) throw NumericalError(what);
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

// Dynamic mass scaling: when the last cycle's step (the same on every rank) was set by a
// hexahedron below time.mass_scaling_dt, every hexahedron of this rank below it gets the mass
// that puts its step 5 % above (so that a locking element is not scaled every cycle), added to
// its nodes; on several ranks the owners sum what their ghosts got. A free node that gains mass
// keeps its kinetic energy (its velocity scaled by sqrt(m / (m + dm))): the added inertia brings
// no energy of its own, and the momentum of those nodes drops by that factor (in quasi-static
// forming a share of a small term). A node held at a prescribed velocity keeps it: the fixture
// gives the added mass its kinetic energy, booked as its external work. The balance stays
// closed; the added mass is reported per part.
void ExplicitSolver::scale_mass_dynamic(double* x, double* v, double* m) {
  const double target = model_.time.mass_scaling_dt, sf = model_.time.safety_factor;
  if (cycle_ == 0 || step_.kind != ElementKind::Hex8 || !(sf * step_.dt < target)) return;
  constexpr double kHeadroom = 1.05;
  const std::size_t n = model_.mesh.n_nodes();
  std::vector<double>& dm = added_mass_scratch_;
  dm.assign(3 * n, 0.0);
  std::vector<double> added(part_mass_.size(), 0.0);
  for (const auto& g : groups_)
    added[static_cast<std::size_t>(g->part())] +=
        g->scale_mass_dynamic(x, target, sf, kHeadroom, dm.data());
  if (domain_) {
    domain_->add_ghosts_to_owners(dm.data(), nullptr);
    MPI_Allreduce(MPI_IN_PLACE, added.data(), static_cast<int>(added.size()), MPI_DOUBLE, MPI_SUM,
                  domain_->comm());
  }
  const auto scale = [&](std::size_t b, std::size_t e) {
    for (std::size_t d = 3 * b; d < 3 * e; ++d) {
      if (!(dm[d] > 0)) continue;
      if (!fixed_mask_[d])
        v[d] *= std::sqrt(m[d] / (m[d] + dm[d]));
      else  // held at its velocity: the fixture gives the added mass its kinetic energy
        mass_scaling_work_ += 0.5 * dm[d] * v[d] * v[d];
      m[d] += dm[d];
      if (inv_mass_[d] > 0) inv_mass_[d] = 1.0 / m[d];  // a freed node stays held (0)
    }
  };
  if (domain_) {
    for (const auto& [b, e] : domain_->owned_runs()) scale(b, e);
    domain_->refresh_ghosts(x, v);  // the ghosts' velocities as their owners scaled them
  } else {
    scale(0, n);
  }
  for (std::size_t p = 0; p < added.size(); ++p) part_mass_[p].added_mass += added[p];
  ++mass_scaling_events_;
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
  if (dt_erode > 0 || material_failure_) {
    bool check_steps = false;
    if (dt_erode > 0) {
      StableStep erodible;
      for (std::size_t k = 0; k < groups_.size(); ++k)
        if (groups_[k]->can_erode()) take_smaller(erodible, group_step_[k]);
      check_steps =
          model_.time.safety_factor * erodible.dt < dt_erode || cycle_ % kFoldCheckInterval == 0;
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
}

}  // namespace ncfsim::fem

namespace ncfsim::fem {

namespace {
constexpr const char* kEnergyNames[] = {
    "time",          "kinetic",         "rotational_kinetic", "internal", "stabilisation",
    "hourglass",     "contact",         "friction",           "damping",  "external_work",
    "initial_total", "eroded_internal", "eroded_kinetic",     "scale_max"};
double* energy_field(EnergyBalance& e, std::size_t k) {
  double* f[] = {
      &e.time,          &e.kinetic,         &e.rotational_kinetic, &e.internal, &e.stabilisation,
      &e.hourglass,     &e.contact,         &e.friction,           &e.damping,  &e.external_work,
      &e.initial_total, &e.eroded_internal, &e.eroded_kinetic,     &e.scale_max};
  return f[k];
}
constexpr std::size_t kEnergyFields = std::size(kEnergyNames);
}  // namespace

void ExplicitSolver::save_state(CheckpointWriter& w) const {
  if (!freeing_.empty() || !eroded_forces_.empty())
    throw std::logic_error("ExplicitSolver::save_state: not at a cycle boundary");
  const std::size_t n = model_.mesh.n_nodes();
  CheckpointScope<CheckpointWriter> solver(w, "solver");
  w.write_int("n_nodes", static_cast<std::int64_t>(n));
  {
    auto X = x.view();
    auto V = v.view();
    w.write_array("x", std::span<const double>(X.data(), 3 * n));
    w.write_array("v", std::span<const double>(V.data(), 3 * n));
    if (model_.time.mass_scaling_dynamic) {  // the masses added during the run
      auto M = mass.view();
      w.write_array("mass", std::span<const double>(M.data(), 3 * n));
      std::vector<double> added;
      for (const auto& pm : part_mass_) added.push_back(pm.added_mass);
      save_array(w, "part_added_mass", added);
      w.write_int("mass_scaling_events", mass_scaling_events_);
    }
  }
  w.write_double("t", t_);
  w.write_double("dt", dt_);
  w.write_double("dt_prev", dt_prev_);
  w.write_double("dt_initial", dt_initial_);
  w.write_int("cycle", cycle_);
  w.write_int("contact_halo_builds", halo_builds_);
  if (!halo_x_.empty()) {  // several ranks: the halo's last build, so a resume rebuilds it
    save_array(w, "halo_x", halo_x_);
    save_array(w, "halo_travel",
               std::vector<double>{halo_travel_, halo_checked_d_, halo_travel_checked_});
  }
  w.write_double("step_dt", step_.dt);
  w.write_int("step_element", step_.element);
  w.write_int("step_kind", static_cast<std::int64_t>(step_.kind));
  {
    EnergyBalance e = energy_;
    std::vector<double> a(kEnergyFields);
    for (std::size_t k = 0; k < kEnergyFields; ++k) a[k] = *energy_field(e, k);
    save_array(w, "energy", a);
    const WorkAccumulator* acc[] = {&w_ext_, &w_damp_, &w_contact_nodes_, &w_tools_,
                                    &tool_work_on_nodes_};
    std::vector<double> work;
    for (const auto* a : acc) work.push_back(a->committed), work.push_back(a->pending);
    save_array(w, "work", work);
    const std::vector<double> timers = {timers_.internal_force, timers_.contact, timers_.update,
                                        timers_.output};
    save_array(w, "timers", timers);
  }
  {
    CheckpointScope<CheckpointWriter> er(w, "erosions");
    std::vector<std::int64_t> cause, cycle, element, kind, part;
    std::vector<double> time, step, centroid;
    for (const auto& ev : erosions_) {
      cause.push_back(static_cast<std::int64_t>(ev.cause));
      time.push_back(ev.time);
      cycle.push_back(ev.cycle);
      element.push_back(ev.element);
      kind.push_back(static_cast<std::int64_t>(ev.kind));
      part.push_back(ev.part);
      step.push_back(ev.step);
      centroid.insert(centroid.end(), {ev.centroid.x, ev.centroid.y, ev.centroid.z});
    }
    save_array(w, "cause", cause);
    save_array(w, "time", time);
    save_array(w, "cycle", cycle);
    save_array(w, "element", element);
    save_array(w, "kind", kind);
    save_array(w, "part", part);
    save_array(w, "step", step);
    save_array(w, "centroid", centroid);
  }
  save_array(w, "node_elements", node_elements_);
  save_array(w, "node_freed", node_freed_);
  {
    CheckpointScope<CheckpointWriter> gs(w, "groups");
    w.write_int("count", static_cast<std::int64_t>(groups_.size()));
    for (std::size_t k = 0; k < groups_.size(); ++k) {
      CheckpointScope<CheckpointWriter> g(w, checkpoint_index(k));
      w.write_int("kind", static_cast<std::int64_t>(groups_[k]->kind()));
      w.write_int("part", groups_[k]->part());
      w.write_int("size", static_cast<std::int64_t>(groups_[k]->size()));
      groups_[k]->save_state(w);
    }
  }
  {
    CheckpointScope<CheckpointWriter> ts(w, "tools");
    for (const auto& tool : model_.tools) {
      CheckpointScope<CheckpointWriter> t(w, tool.name);
      save_tool_state(tool, w);
    }
  }
  {
    CheckpointScope<CheckpointWriter> cs(w, "contacts");
    w.write_int("count", static_cast<std::int64_t>(model_.contacts.size()));
    for (std::size_t k = 0; k < model_.contacts.size(); ++k) {
      CheckpointScope<CheckpointWriter> c(w, checkpoint_index(k));
      w.write_string("name", model_.contacts[k]->name());
      model_.contacts[k]->save_state(w);
    }
  }
}

void ExplicitSolver::load_state(CheckpointReader& r) {
  if (cycle_ != 0 || t_ != 0)
    throw std::logic_error("ExplicitSolver::load_state: the solver has already stepped");
  const std::size_t n = model_.mesh.n_nodes();
  // The contact halo was built at the start positions: built again at the saved ones.
  halo_due_ = domain_ && !model_.contacts.empty() && model_.parallel.contact_halo_refresh > 0;
  CheckpointScope<CheckpointReader> solver(r, "solver");
  r.check_int("n_nodes", static_cast<std::int64_t>(n));
  {
    std::vector<double> a;
    auto X = x.view();
    r.read_array("x", a, 3 * n);
    std::copy(a.begin(), a.end(), X.data());
    auto V = v.view();
    r.read_array("v", a, 3 * n);
    std::copy(a.begin(), a.end(), V.data());
    if (r.has("mass")) {  // dynamic mass scaling: the masses as they stood (freed nodes below)
      auto M = mass.view();
      r.read_array("mass", a, 3 * n);
      std::copy(a.begin(), a.end(), M.data());
      for (std::size_t d = 0; d < 3 * n; ++d) inv_mass_[d] = 1.0 / M[d];
      r.read_array("part_added_mass", a, part_mass_.size());
      for (std::size_t p = 0; p < part_mass_.size(); ++p) part_mass_[p].added_mass = a[p];
      mass_scaling_events_ = r.read_int("mass_scaling_events");
    }
  }
  if (r.read_double("dt_initial") != dt_initial_)
    r.mismatch("dt_initial",
               "another initial stable step than this model's (another mesh or "
               "material?)");
  t_ = r.read_double("t");
  dt_ = r.read_double("dt");
  dt_prev_ = r.read_double("dt_prev");
  cycle_ = r.read_int("cycle");
  halo_builds_ = r.has("contact_halo_builds") ? r.read_int("contact_halo_builds") : 0;
  halo_x_.clear();  // none saved: built at the saved positions
  if (halo_due_ && r.has("halo_x")) {
    std::vector<double> tr;
    r.read_array("halo_x", halo_x_, 3 * n);
    r.read_array("halo_travel", tr, 3);
    halo_travel_ = tr[0], halo_checked_d_ = tr[1], halo_travel_checked_ = tr[2];
  }
  step_.dt = r.read_double("step_dt");
  step_.element = r.read_int("step_element");
  step_.kind = static_cast<ElementKind>(r.read_int("step_kind"));
  {
    std::vector<double> a;
    r.read_array("energy", a, kEnergyFields);
    for (std::size_t k = 0; k < kEnergyFields; ++k) *energy_field(energy_, k) = a[k];
    WorkAccumulator* acc[] = {&w_ext_, &w_damp_, &w_contact_nodes_, &w_tools_,
                              &tool_work_on_nodes_};
    r.read_array("work", a, 2 * std::size(acc));
    for (std::size_t k = 0; k < std::size(acc); ++k)
      acc[k]->committed = a[2 * k], acc[k]->pending = a[2 * k + 1];
    r.read_array("timers", a, 4);
    timers_ = {a[0], a[1], a[2], a[3]};
    timers_loaded_ = timers_;
  }
  {
    CheckpointScope<CheckpointReader> er(r, "erosions");
    std::vector<std::int64_t> cause, cycle, element, kind, part;
    std::vector<double> time, step, centroid;
    r.read_array("cause", cause);
    const std::size_t m = cause.size();
    r.read_array("time", time, m);
    r.read_array("cycle", cycle, m);
    r.read_array("element", element, m);
    r.read_array("kind", kind, m);
    r.read_array("part", part, m);
    r.read_array("step", step, m);
    r.read_array("centroid", centroid, 3 * m);
    erosions_.clear();
    for (std::size_t k = 0; k < m; ++k)
      erosions_.push_back({static_cast<ErosionEvent::Cause>(cause[k]), time[k], cycle[k],
                           element[k], static_cast<ElementKind>(kind[k]), static_cast<int>(part[k]),
                           step[k], V3{centroid[3 * k], centroid[3 * k + 1], centroid[3 * k + 2]}});
  }
  load_array(r, "node_elements", node_elements_);
  load_array(r, "node_freed", node_freed_);
  n_freed_nodes_ = 0;
  for (std::size_t i = 0; i < node_freed_.size(); ++i)
    if (node_freed_[i]) {
      ++n_freed_nodes_;
      for (std::size_t d = 3 * i; d < 3 * i + 3; ++d) inv_mass_[d] = 0;
    }
  {
    CheckpointScope<CheckpointReader> gs(r, "groups");
    r.check_int("count", static_cast<std::int64_t>(groups_.size()));
    for (std::size_t k = 0; k < groups_.size(); ++k) {
      CheckpointScope<CheckpointReader> g(r, checkpoint_index(k));
      r.check_int("kind", static_cast<std::int64_t>(groups_[k]->kind()));
      r.check_int("part", groups_[k]->part());
      r.check_int("size", static_cast<std::int64_t>(groups_[k]->size()));
      groups_[k]->load_state(r);
    }
  }
  {
    CheckpointScope<CheckpointReader> ts(r, "tools");
    for (auto& tool : model_.tools) {
      CheckpointScope<CheckpointReader> t(r, tool.name);
      load_tool_state(tool, r);
    }
  }
  {
    CheckpointScope<CheckpointReader> cs(r, "contacts");
    r.check_int("count", static_cast<std::int64_t>(model_.contacts.size()));
    for (std::size_t k = 0; k < model_.contacts.size(); ++k) {
      CheckpointScope<CheckpointReader> c(r, checkpoint_index(k));
      if (r.read_string("name") != model_.contacts[k]->name())
        r.mismatch("name", "contact '" + r.read_string("name") + "', this model has '" +
                               model_.contacts[k]->name() + "' here");
      model_.contacts[k]->load_state(r);
    }
  }
}

}  // namespace ncfsim::fem
