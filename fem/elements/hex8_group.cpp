// The hexahedron group: fem/elements/hex8_block.hpp's kernels behind the ElementGroup interface.
#include <cmath>

#include "fem/checkpoint.hpp"
#include "fem/elements/element_fields.hpp"
#include "fem/elements/element_group.hpp"
#include "fem/elements/hex8_block.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/model.hpp"

namespace ncfsim::fem {

namespace {

class Hex8Group final : public ElementGroup {
 public:
  Hex8Block block;

  void bind() {
    part_ = block.part, n_ = block.n, conn_ = block.conn.data(), user_id_ = block.user_id.data();
    set_index_ = block.mesh_hex;
  }
  ElementKind kind() const override { return ElementKind::Hex8; }
  void lumped_mass(double* mass) const override { hex8_lumped_mass(block, mass); }
  void add_part_mass(double& mass, double& added_mass) const override {
    const double rho = block.material->density();
    for (std::size_t e = 0; e < block.n; ++e) {
      mass += rho * block.volume[e];
      added_mass += (block.density[e] - rho) * block.volume[e];
    }
  }
  void scale_mass(const double* x, double target, double sf) override {
    std::vector<double> dt;
    hex8_element_steps(block, x, dt);
    for (std::size_t e = 0; e < block.n; ++e)
      if (sf * dt[e] < target) block.density[e] *= std::pow(target / (sf * dt[e]), 2);
  }
  DynamicScalingResult scale_mass_dynamic(const double* x, double target, double sf,
                                          double headroom, double max_added_ratio,
                                          double* dm) override {
    std::vector<double> dt;
    hex8_element_steps(block, x, dt, nullptr, true);
    const double cap = mass_cap_density(max_added_ratio);
    DynamicScalingResult r;
    for (std::size_t e = block.range_begin; e < std::min(block.range_end, block.n); ++e) {
      // Below the target (eroded: 1e300); at the cap: left to its step.
      if (!(sf * dt[e] < target * (1 - kMassScalingBelowShare))) {
        r.at_cap += block.density[e] >= cap ? 1 : 0;
        continue;
      }
      if (block.density[e] >= cap) {
        ++r.held_at_cap, ++r.at_cap;
        continue;
      }
      const double rho =
          std::min(block.density[e] * std::pow(headroom * target / (sf * dt[e]), 2), cap);
      const double m = (rho - block.density[e]) * block.volume0[e];
      block.density[e] = rho;
      r.added_mass += m;
      ++r.scaled;
      r.at_cap += rho >= cap ? 1 : 0;
      for (int I = 0; I < 8; ++I) {
        const auto node = static_cast<std::size_t>(block.conn[I * block.n + e]);
        for (int c = 0; c < 3; ++c) dm[3 * node + c] += m / 8.0;
      }
    }
    return r;
  }
  bool at_mass_cap(std::size_t e, double max_added_ratio) const override {
    return block.density[e] >= mass_cap_density(max_added_ratio);
  }
  // The density at the cap of dynamic mass scaling: (1 + ratio) times the material's.
  double mass_cap_density(double max_added_ratio) const {
    return (1 + max_added_ratio) * block.material->density();
  }
  StableStep stable_step(const double* x) const override { return hex8_stable_step(block, x); }
  void internal_forces(const ElementCycleState& s, double* f, ElementEnergyIncrement& energy,
                       StableStep& step) override {
    hex8_internal_forces(block, s.x, s.v, s.dt, f, energy, step, s.x_ref);
  }
  std::size_t chunk() const override { return kHex8Chunk; }
  bool set_range(std::size_t begin, std::size_t end) override {
    block.range_begin = begin, block.range_end = end;
    return true;
  }
  std::vector<std::pair<double*, int>> state_arrays() override {
    const int nh = block.material->n_history();
    std::vector<std::pair<double*, int>> a = {{block.stress.data(), 6},
                                              {block.strain.data(), 6},
                                              {block.hg_force.data(), 12},
                                              {block.hg_viscous.data(), 12},
                                              {block.volume.data(), 1}};
    if (nh > 0) a.emplace_back(block.history.data(), nh);
    return a;
  }
  bool can_erode() const override { return true; }
  void element_steps(const double* x, std::vector<double>& dt,
                     std::vector<double>* corner_jacobian) const override {
    hex8_element_steps(block, x, dt, corner_jacobian, true);
  }
  void capped_element_steps(const double* x, double max_added_ratio,
                            std::vector<double>& dt) const override {
    hex8_element_steps(block, x, dt, nullptr, true, mass_cap_density(max_added_ratio));
  }
  void element_force(std::size_t e, const double* x, const double* v, double* f) const override {
    hex8_element_force(block, e, x, v, f);
  }
  double erode(std::size_t e) override { return hex8_erode(block, e); }
  std::size_t n_eroded() const override { return block.n_eroded; }
  bool material_can_fail() const override { return block.material->failure_history_row() >= 0; }
  void failed_elements(std::vector<std::size_t>& out) const override {
    const int row = block.material->failure_history_row();
    if (row < 0) return;
    const double* f = block.history.data() + static_cast<std::size_t>(row) * block.n;
    for (std::size_t e = 0; e < block.n; ++e)
      if (f[e] >= 1.0 && !(block.n_eroded && block.eroded[e])) out.push_back(e);
  }
  std::vector<CellFieldSpec> cell_fields() const override {
    return {{"stress", 6}, {"von_mises_stress", 1}, {"fibre_direction", 3}, {"eroded", 1}};
  }
  void cell_values(const double* x, double* const* out) const override {
    hex8_output_fields(block, x, out[0], out[1], out[2]);
    for (std::size_t e = 0; e < block.n; ++e) out[3][e] = block.n_eroded ? block.eroded[e] : 0.0;
  }
  void save_state(CheckpointWriter& w) const override {
    save_array(w, "stress", block.stress);
    save_array(w, "strain", block.strain);
    save_array(w, "history", block.history);
    save_array(w, "hg_force", block.hg_force);
    save_array(w, "hg_viscous", block.hg_viscous);
    save_array(w, "volume", block.volume);
    save_array(w, "eroded", block.eroded);  // empty: none eroded yet
    save_array(w, "density", block.density);  // mass scaling, static and dynamic
  }
  void load_state(CheckpointReader& r) override {
    load_array(r, "stress", block.stress);
    load_array(r, "strain", block.strain);
    load_array(r, "history", block.history);
    load_array(r, "hg_force", block.hg_force);
    load_array(r, "hg_viscous", block.hg_viscous);
    load_array(r, "volume", block.volume);
    if (r.has("density")) load_array(r, "density", block.density);
    r.read_array("eroded", block.eroded);
    if (!block.eroded.empty() && block.eroded.size() != block.n)
      r.mismatch("eroded", "has " + std::to_string(block.eroded.size()) +
                               " values, this model needs " + std::to_string(block.n));
    block.n_eroded = 0;
    for (auto e : block.eroded) block.n_eroded += e ? 1 : 0;
  }
};

}  // namespace

std::unique_ptr<ElementGroup> make_hex8_group(const Model& model, const ElementSet& set, int part,
                                              const std::vector<std::size_t>& elements,
                                              const double* x_ref) {
  const PartProperties& pp = model.parts[static_cast<std::size_t>(part)];
  const int material =
      !set.material.empty() && !elements.empty() && set.material[elements.front()] >= 0
          ? set.material[elements.front()]
          : pp.material;
  if (material < 0 || static_cast<std::size_t>(material) >= model.materials.size())
    throw InputError("",
                     "part." + model.mesh.part_names[static_cast<std::size_t>(part)] + ".material",
                     "no such material");
  auto g = std::make_unique<Hex8Group>();
  Hex8Block& b = g->block;
  b.part = part;
  b.material = model.materials[static_cast<std::size_t>(material)].get();
  b.material_index = material;
  b.n = elements.size();
  b.conn.resize(8 * b.n);
  b.user_id.resize(b.n);
  b.mesh_hex.resize(b.n);
  for (std::size_t j = 0; j < b.n; ++j) {
    const auto nodes = set.nodes(elements[j]);
    for (std::size_t I = 0; I < 8; ++I) b.conn[I * b.n + j] = nodes[I];
    b.user_id[j] = set.user_id[elements[j]];
    b.mesh_hex[j] = static_cast<std::int32_t>(elements[j]);
  }
  b.hourglass_stiffness = pp.hourglass_stiffness;
  b.hourglass_viscosity = pp.hourglass_viscosity;
  std::vector<double> element_axes;  // [9][n], block order
  if (!set.material_axes.empty()) {
    element_axes.resize(9 * b.n);
    for (std::size_t j = 0; j < b.n; ++j)
      for (std::size_t k = 0; k < 9; ++k)
        element_axes[k * b.n + j] = set.material_axes[9 * elements[j] + k];
  }
  hex8_initialise(b, x_ref, pp.material_axes, element_axes.empty() ? nullptr : element_axes.data());
  g->bind();
  return g;
}

template <>
Hex8Block* block_of<Hex8Block>(ElementGroup& g) {
  return block_of_group<Hex8Group>(g);
}
template <>
const Hex8Block* block_of<Hex8Block>(const ElementGroup& g) {
  return block_of_group<Hex8Group>(g);
}

}  // namespace ncfsim::fem
