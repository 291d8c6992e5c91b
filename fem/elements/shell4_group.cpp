// The shell group: fem/elements/shell4_block.hpp's kernel behind the ElementGroup interface. The
// group also holds the rotational degrees of freedom of its nodes (the solver moves only
// translations): their velocities, rotary inertia and the moments of the last cycle, advanced
// by central differences with the same steps as the translations.
#include <cmath>
#include <sstream>

#include "fem/checkpoint.hpp"
#include "fem/elements/element_group.hpp"
#include "fem/elements/shell4_block.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/model.hpp"

namespace ncfsim::fem {

namespace {

class Shell4Group final : public ElementGroup {
 public:
  Shell4Block block;

  void bind(std::size_t n_nodes, const Model& model) {
    part_ = block.part, n_ = block.n, conn_ = block.conn.data(), user_id_ = block.user_id.data();
    set_index_ = block.mesh_index;
    omega_.assign(3 * n_nodes, 0.0);
    moment_.assign(3 * n_nodes, 0.0);
    inertia_.assign(n_nodes, 0.0);
    collect_nodes(0, block.n);
    fixed_.assign(3 * n_nodes, 0);
    for (const auto& fx : model.fixed)
      for (auto node : fx.nodes)
        for (std::size_t c = 0; c < 3; ++c)
          if (fx.rotations[c]) fixed_[3 * static_cast<std::size_t>(node) + c] = 1;
    update_inertia();
  }
  // The nodes whose rotations this rank advances: those of elements [begin, end) and, on
  // several ranks, the group's nodes it owns (their moments are summed there every cycle, so
  // they must be cleared there too).
  void collect_nodes(std::size_t begin, std::size_t end) {
    std::vector<char> mine(omega_.size() / 3, 0);
    for (std::size_t I = 0; I < 4; ++I)
      for (std::size_t e = begin; e < std::min(end, block.n); ++e)
        mine[static_cast<std::size_t>(block.conn[I * block.n + e])] = 1;
    if (!owned_.empty())
      for (auto node : block.conn)
        if (owned_[static_cast<std::size_t>(node)]) mine[static_cast<std::size_t>(node)] = 1;
    nodes_.clear();
    for (std::size_t i = 0; i < mine.size(); ++i)
      if (mine[i]) nodes_.push_back(static_cast<std::int32_t>(i));
    // The group's other nodes: a rank that reads one as a ghost (a contact's halo) receives its
    // owner's summed moment there, which must not go back as this rank's share.
    others_.clear();
    if (!owned_.empty())
      for (auto node : block.conn)
        if (!mine[static_cast<std::size_t>(node)]) {
          mine[static_cast<std::size_t>(node)] = 1;
          others_.push_back(node);
        }
  }
  void update_inertia() {
    std::fill(inertia_.begin(), inertia_.end(), 0.0);
    shell4_rotary_inertia(block, inertia_.data());
  }

  ElementKind kind() const override { return ElementKind::Quad4; }
  void lumped_mass(double* mass) const override { shell4_lumped_mass(block, mass); }
  void add_part_mass(double& mass, double& added_mass) const override {
    for (std::size_t e = 0; e < block.n; ++e) {
      mass += block.areal_density * block.area0[e];
      added_mass += block.areal_density * (block.mass_scale[e] - 1.0) * block.area0[e];
    }
  }
  void scale_mass(const double* x, double target, double sf) override {
    std::vector<double> dt;
    shell4_element_steps(block, x, dt);
    for (std::size_t e = 0; e < block.n; ++e)
      if (dt[e] > 0 && sf * dt[e] < target)
        block.mass_scale[e] *= std::pow(target / (sf * dt[e]), 2);
    update_inertia();
  }
  StableStep stable_step(const double* x) const override {
    std::vector<double> dt;
    shell4_element_steps(block, x, dt);
    StableStep s;
    for (std::size_t e = 0; e < block.n; ++e)
      if (dt[e] < s.dt) s = {dt[e], block.user_id[e], ElementKind::Quad4};
    return s;
  }
  void internal_forces(const ElementCycleState& s, double* f, ElementEnergyIncrement& energy,
                       StableStep& step) override {
    // w^{n-1/2} from the moments at t^{n-1}; kinetic energy of the rotations at t^{n-1} in the
    // product form the solver uses for the translations (its change is booked one step late).
    const double dt_mid = 0.5 * (dt_last_ + s.dt);
    // Several ranks: the moments are the sums over the ranks (nodal_moments), so every rank
    // advances the rotations of its elements' nodes alike; each node's energy on its owner.
    double ke = 0;
    for (auto node : nodes_) {
      const auto i = static_cast<std::size_t>(node);
      const double inv_i = inertia_[i] > 0 ? 1.0 / inertia_[i] : 0.0;
      const double booked = owned_.empty() || owned_[i] ? 0.5 * inertia_[i] : 0.0;
      for (std::size_t c = 0; c < 3; ++c) {
        const std::size_t d = 3 * i + c;
        const double wo = omega_[d];
        const double wn = fixed_[d] ? 0.0 : wo + dt_mid * moment_[d] * inv_i;
        omega_[d] = wn;
        ke += booked * wo * wn;
        moment_[d] = 0;
      }
    }
    for (auto node : others_)
      for (std::size_t c = 0; c < 3; ++c) moment_[3 * static_cast<std::size_t>(node) + c] = 0;
    energy.kinetic += ke - ke_rot_;
    ke_rot_ = ke;
    dt_last_ = s.dt;
    shell4_internal_forces(block, s.x, s.v, omega_.data(), s.dt, f, moment_.data(), energy, step);
  }
  std::vector<CellFieldSpec> cell_fields() const override {
    return {{"shear_angle_deg", 1},
            {"membrane_force", 6},
            {"bending_moment", 6},
            {"fibre_direction", 3}};
  }
  void cell_values(const double* x, double* const* out) const override {
    shell4_output_fields(block, x, out[0], out[1], out[2], out[3]);
  }

  const std::vector<double>& rotation_velocity() const { return omega_; }

  // Domain decomposition.
  std::size_t chunk() const override { return kShell4Chunk; }
  bool set_range(std::size_t begin, std::size_t end) override {
    block.range_begin = begin, block.range_end = end;
    collect_nodes(begin, end);
    return true;
  }
  void set_owned_nodes(const std::uint8_t* owned) override {
    owned_.assign(owned, owned + omega_.size() / 3);
    collect_nodes(block.range_begin, block.range_end);
  }
  double* nodal_moments() override { return moment_.data(); }
  std::vector<std::pair<double*, int>> state_arrays() override {
    std::vector<std::pair<double*, int>> a;
    for_each_element_array(*this, [&](const char*, std::vector<double>& v) {
      if (block.n > 0 && !v.empty()) a.emplace_back(v.data(), static_cast<int>(v.size() / block.n));
    });
    return a;
  }

  void save_state(CheckpointWriter& w) const override {
    for_each_state_array(*this, [&](const char* name, const auto& v) { save_array(w, name, v); });
    w.write_double("dt_last", dt_last_);
    w.write_double("rotational_kinetic", ke_rot_);
  }
  void load_state(CheckpointReader& r) override {
    for_each_state_array(*this, [&](const char* name, auto& v) { load_array(r, name, v); });
    dt_last_ = r.read_double("dt_last");
    ke_rot_ = r.read_double("rotational_kinetic");
  }

 private:
  std::vector<double> omega_, moment_, inertia_;  // [3 n], [3 n], [n] over all mesh nodes
  std::vector<std::uint8_t> fixed_;               // [3 n] rotation held at zero
  std::vector<std::int32_t> nodes_;               // the nodes of its elements (this rank's)
  std::vector<std::uint8_t> owned_;               // several ranks: [n] nodes this rank owns
  std::vector<std::int32_t> others_;              // several ranks: see collect_nodes
  double dt_last_ = 0, ke_rot_ = 0;

  // The arrays a checkpoint holds, by name: save and load walk the same list.
  // The per-element ones ([components][n] each) first: an output on several ranks gathers those.
  template <class Group, class Fn>
  static void for_each_element_array(Group& g, Fn&& fn) {
    auto& b = g.block;
    fn("strain", b.strain), fn("curvature", b.curvature), fn("shear", b.shear);
    fn("resultant", b.resultant), fn("moment", b.moment), fn("shear_force", b.shear_force);
    fn("hg_force", b.hg_force), fn("drill_moment", b.drill_moment);
    fn("polar_angle", b.polar_angle), fn("history", b.history);
  }
  template <class Group, class Fn>
  static void for_each_state_array(Group& g, Fn&& fn) {
    for_each_element_array(g, fn);
    fn("rotation_velocity", g.omega_), fn("nodal_moment", g.moment_);
  }
};

// E and nu of an isotropic elastic material from its stiffness, or false.
bool isotropic_constants(const SolidMaterial& m, double& E, double& nu) {
  const Voigt6x6 C = m.elastic_stiffness();
  const double l2m = C[0], lam = C[1], mu = C[21];
  const double tol = 1e-9 * std::abs(l2m);
  if (std::abs(C[7] - l2m) > tol || std::abs(C[14] - l2m) > tol || std::abs(C[2] - lam) > tol ||
      std::abs(0.5 * (l2m - lam) - mu) > tol || std::abs(C[28] - mu) > tol ||
      std::abs(C[35] - mu) > tol)
    return false;
  E = mu * (3 * lam + 2 * mu) / (lam + mu);
  nu = lam / (2 * (lam + mu));
  return true;
}

}  // namespace

std::unique_ptr<ElementGroup> make_quad4_group(const Model& model, const ElementSet& set, int part,
                                               const std::vector<std::size_t>& elements,
                                               const double* x_ref) {
  const PartProperties& pp = model.parts[static_cast<std::size_t>(part)];
  const std::string key = "part." + model.mesh.part_names[static_cast<std::size_t>(part)];
  auto g = std::make_unique<Shell4Group>();
  Shell4Block& b = g->block;
  b.part = part;
  Shell4Section& sec = b.section;
  sec.thickness = pp.shell_thickness;
  if (!(sec.thickness > 0))
    throw InputError("", key + ".thickness", "a shell part needs a thickness > 0 (m)");
  sec.integration_points = pp.shell_integration_points;
  sec.hourglass_stiffness = pp.hourglass_stiffness;
  if (pp.membrane_law >= 0) {
    if (static_cast<std::size_t>(pp.membrane_law) >= model.membrane_laws.size())
      throw InputError("", key + ".membrane_law", "no such membrane law");
    sec.law = model.membrane_laws[static_cast<std::size_t>(pp.membrane_law)].get();
    b.material_index = pp.membrane_law;
  } else {
    if (pp.material < 0 || static_cast<std::size_t>(pp.material) >= model.materials.size())
      throw InputError("", key + ".material", "no such material");
    const SolidMaterial& m = *model.materials[static_cast<std::size_t>(pp.material)];
    if (!isotropic_constants(m, sec.youngs_modulus, sec.poisson_ratio))
      throw InputError("", key + ".material",
                       "material '" + m.name() +
                           "' is not isotropic elastic: a shell takes an elastic_isotropic "
                           "material or a membrane_law");
    sec.density = m.density();
    b.material_index = pp.material;
  }
  b.n = elements.size();
  b.conn.resize(4 * b.n);
  b.user_id.resize(b.n);
  b.mesh_index.resize(b.n);
  for (std::size_t j = 0; j < b.n; ++j) {
    const auto nodes = set.nodes(elements[j]);
    for (std::size_t I = 0; I < 4; ++I) b.conn[I * b.n + j] = nodes[I];
    b.user_id[j] = set.user_id[elements[j]];
    b.mesh_index[j] = static_cast<std::int32_t>(elements[j]);
  }
  const double axis[3] = {pp.material_axes[0], pp.material_axes[3], pp.material_axes[6]};
  shell4_initialise(b, x_ref, axis);
  g->bind(model.mesh.n_nodes(), model);
  return g;
}

template <>
Shell4Block* block_of<Shell4Block>(ElementGroup& g) {
  return block_of_group<Shell4Group>(g);
}
template <>
const Shell4Block* block_of<Shell4Block>(const ElementGroup& g) {
  return block_of_group<Shell4Group>(g);
}

}  // namespace ncfsim::fem
