// ExplicitSolver: building the solver from the model (element blocks, tool motions, nodal
// masses) and the mass scaling, static at the start and dynamic during the run.
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
#include "fem/huge_pages.hpp"
#include "fem/parallel/domain.hpp"
#include "fem/solver.hpp"

namespace ncfsim::fem {

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
  // The model's arrays are all allocated now: on 2 MB pages from here (no value changes).
  huge_pages_ = advise_huge_pages();
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

void ExplicitSolver::apply_mass_scaling() {
  auto X = x.view();
  for (auto& g : groups_)
    g->scale_mass(X.data(), model_.time.mass_scaling_dt, model_.time.safety_factor);
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

// Dynamic mass scaling: when the last cycle's step (the same on every rank) was set by a
// hexahedron below time.mass_scaling_dt, every hexahedron of this rank below it gets the mass
// that puts its step 5 % above (so that a locking element is not scaled every cycle), up to
// time.mass_scaling_max_ratio times its physical mass, added to its nodes; on several ranks the
// owners sum what their ghosts got. An element at that cap is left to its own step (a folding
// element's falls without bound; erosion_step_ratio takes it): when a scan finds only such
// elements below the target, the next is 50 cycles later (as the erosion checks), so a capped
// element that sets the step does not cost a scan every cycle. A free node that gains mass
// keeps its kinetic energy (its velocity scaled by sqrt(m / (m + dm))): the added inertia brings
// no energy of its own, and the momentum of those nodes drops by that factor (in quasi-static
// forming a share of a small term). A node held at a prescribed velocity keeps it: the fixture
// gives the added mass its kinetic energy, booked as its external work. The balance stays
// closed; the added mass is reported per part.
void ExplicitSolver::scale_mass_dynamic(double* x, double* v, double* m) {
  const double target = model_.time.mass_scaling_dt, sf = model_.time.safety_factor;
  if (cycle_ == 0 || step_.kind != ElementKind::Hex8 ||
      !(sf * step_.dt < target * (1 - kMassScalingBelowShare)))
    return;
  if (cycle_ < mass_scaling_pause_until_) return;
  constexpr double kHeadroom = 1.05;
  constexpr std::int64_t kPauseCycles = 50;
  const std::size_t n = model_.mesh.n_nodes();
  std::vector<double>& dm = added_mass_scratch_;
  dm.assign(3 * n, 0.0);
  // Per part the mass added, then the elements scaled, those held at the cap below the target
  // and all at the cap (all ranks).
  const std::size_t n_part = part_mass_.size();
  std::vector<double> added(n_part + 3, 0.0);
  for (const auto& g : groups_) {
    const DynamicScalingResult r = g->scale_mass_dynamic(
        x, target, sf, kHeadroom, model_.time.mass_scaling_max_ratio, dm.data());
    added[static_cast<std::size_t>(g->part())] += r.added_mass;
    added[n_part] += static_cast<double>(r.scaled);
    added[n_part + 1] += static_cast<double>(r.held_at_cap);
    added[n_part + 2] += static_cast<double>(r.at_cap);
  }
  if (domain_)
    MPI_Allreduce(MPI_IN_PLACE, added.data(), static_cast<int>(added.size()), MPI_DOUBLE, MPI_SUM,
                  domain_->comm());
  mass_scaling_capped_ = static_cast<std::int64_t>(added[n_part + 2]);
  if (!(added[n_part] > 0)) {
    if (added[n_part + 1] > 0) mass_scaling_pause_until_ = cycle_ + kPauseCycles;
    return;
  }
  if (domain_) domain_->add_ghosts_to_owners(dm.data(), nullptr);
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
  for (std::size_t p = 0; p < n_part; ++p) part_mass_[p].added_mass += added[p];
  ++mass_scaling_events_;
}

}  // namespace ncfsim::fem
