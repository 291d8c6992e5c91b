// The bar group: fem/elements/bar_block.hpp's kernels behind the ElementGroup interface.
#include <cmath>

#include "fem/checkpoint.hpp"
#include "fem/elements/bar_block.hpp"
#include "fem/elements/element_group.hpp"
#include "fem/errors.hpp"
#include "fem/mesh.hpp"
#include "fem/model.hpp"

namespace ncfsim::fem {

namespace {

class BarGroup final : public ElementGroup {
 public:
  BarBlock block;

  void bind(std::vector<std::int32_t> set_index) {
    part_ = block.part, n_ = block.n, conn_ = block.conn.data(), user_id_ = block.user_id.data();
    set_index_ = std::move(set_index);
  }
  ElementKind kind() const override { return ElementKind::Bar2; }
  void lumped_mass(double* mass) const override { bar_lumped_mass(block, mass); }
  void add_part_mass(double& mass, double& added_mass) const override {
    const double rho_l = block.law->linear_density();
    for (std::size_t e = 0; e < block.n; ++e) {
      mass += rho_l * block.length0[e];
      added_mass += rho_l * (block.mass_scale[e] - 1.0) * block.length0[e];
    }
  }
  void scale_mass(const double* x, double target, double sf) override {
    for (std::size_t e = 0; e < block.n; ++e)
      if (sf * block.dt_crit[e] < target)
        block.mass_scale[e] = std::pow(target / (sf * block.dt_crit[e]), 2);
    bar_initialise(block, x);
  }
  StableStep stable_step(const double*) const override {
    StableStep s;
    for (std::size_t e = 0; e < block.n; ++e)
      if (block.dt_crit[e] < s.dt) s = {block.dt_crit[e], block.user_id[e], ElementKind::Bar2};
    return s;
  }
  void internal_forces(const ElementCycleState& s, double* f, ElementEnergyIncrement& energy,
                       StableStep& step) override {
    bar_internal_forces(block, s.x, f, energy, step);
  }
  std::size_t chunk() const override { return 256; }
  bool set_range(std::size_t begin, std::size_t end) override {
    block.range_begin = begin, block.range_end = end;
    return true;
  }
  std::vector<std::pair<double*, int>> state_arrays() override {
    return {{block.strain.data(), 1}, {block.force.data(), 1}};
  }
  std::vector<CellFieldSpec> cell_fields() const override {
    return {{"axial_force", 1}, {"axial_strain", 1}};
  }
  void cell_values(const double*, double* const* out) const override {
    for (std::size_t e = 0; e < block.n; ++e)
      out[0][e] = block.force[e], out[1][e] = block.strain[e];
  }
  void save_state(CheckpointWriter& w) const override {
    save_array(w, "strain", block.strain);
    save_array(w, "force", block.force);
  }
  void load_state(CheckpointReader& r) override {
    load_array(r, "strain", block.strain);
    load_array(r, "force", block.force);
  }
};

}  // namespace

std::unique_ptr<ElementGroup> make_bar2_group(const Model& model, const ElementSet& set, int part,
                                              const std::vector<std::size_t>& elements,
                                              const double* x_ref) {
  const PartProperties& pp = model.parts[static_cast<std::size_t>(part)];
  if (pp.bar_law < 0 || static_cast<std::size_t>(pp.bar_law) >= model.bar_laws.size())
    throw InputError("",
                     "part." + model.mesh.part_names[static_cast<std::size_t>(part)] + ".bar_law",
                     "no such bar law");
  auto g = std::make_unique<BarGroup>();
  BarBlock& b = g->block;
  b.part = part;
  b.law = &model.bar_laws[static_cast<std::size_t>(pp.bar_law)];
  b.n = elements.size();
  b.conn.resize(2 * b.n);
  b.user_id.resize(b.n);
  std::vector<std::int32_t> index(b.n);
  for (std::size_t j = 0; j < b.n; ++j) {
    const auto nodes = set.nodes(elements[j]);
    b.conn[j] = nodes[0];
    b.conn[b.n + j] = nodes[1];
    b.user_id[j] = set.user_id[elements[j]];
    index[j] = static_cast<std::int32_t>(elements[j]);
  }
  bar_initialise(b, x_ref);
  g->bind(std::move(index));
  return g;
}

template <>
BarBlock* block_of<BarBlock>(ElementGroup& g) {
  return block_of_group<BarGroup>(g);
}
template <>
const BarBlock* block_of<BarBlock>(const ElementGroup& g) {
  return block_of_group<BarGroup>(g);
}

}  // namespace ncfsim::fem
