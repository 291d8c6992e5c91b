// The mesh as element sets per kind and the solver's element groups (fem/elements/).
#include "fem/elements/bar_block.hpp"
#include "fem/elements/element_fields.hpp"
#include "fem/elements/hex8_block.hpp"
#include "fem/errors.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

// A 3 x 2 x 1 block of hexahedra (part "block") and a line of two bars along its top edge at
// y = 0 (part "yarn"), the bars added first.
fem::Model block_and_bars() {
  fem::Model model;
  const int yarn = model.mesh.add_part("yarn");
  const int block = model.mesh.add_part("block");
  const auto ids = fem::add_hex_block(model.mesh, block, {0, 0, 0}, {0.03, 0.02, 0.01}, {3, 2, 1});
  fem::ElementSet& bars = model.mesh.elements(fem::ElementKind::Bar2);
  const std::int32_t top0 = ids[static_cast<std::size_t>(4 * 3 * 1)];  // (0, 0, 1)
  bars.add({top0, top0 + 1}, yarn);
  bars.add({top0 + 1, top0 + 2}, yarn);
  model.materials.push_back(std::make_unique<fem::ElasticIsotropic>("steel", 7850, 210e9, 0.3));
  model.bar_laws.push_back(fem::BarForceLaw::linear("yarn", 100.0, true, 1e-4));
  model.parts.resize(2);
  model.parts[static_cast<std::size_t>(yarn)].bar_law = 0;
  model.parts[static_cast<std::size_t>(block)].material = 0;
  model.time.end_time = 1;
  return model;
}

}  // namespace

TEST(ElementSets, KeptOnePerKindInKindOrderWhateverTheOrderOfFirstUse) {
  fem::Mesh m;
  const int p = m.add_part("p");
  m.coords = {0, 0, 0, 1, 0, 0};
  m.elements(fem::ElementKind::Bar2).add({0, 1}, p);
  fem::add_hex_block(m, p, {0, 0, 1}, {1, 1, 1}, {1, 1, 1});
  ASSERT_EQ(m.sets.size(), 2u);
  EXPECT_EQ(m.sets[0].kind, fem::ElementKind::Hex8);
  EXPECT_EQ(m.sets[1].kind, fem::ElementKind::Bar2);
  EXPECT_EQ(m.n_elements(fem::ElementKind::Hex8), 1u);
  EXPECT_EQ(m.n_elements(), 2u);
  EXPECT_EQ(m.element_offset(fem::ElementKind::Bar2), 1u);
  EXPECT_NO_THROW(m.validate());
  EXPECT_THROW(m.elements(fem::ElementKind::Bar2).add({0, 1, 2}, p), std::invalid_argument);
  m.elements(fem::ElementKind::Bar2).add({1, 1}, p);
  EXPECT_THROW(m.validate(), std::invalid_argument);  // a bar joining a node to itself
}

TEST(ElementSets, RenumberingKeepsTagsAndIdsWithTheirElement) {
  fem::Model model = block_and_bars();
  fem::Mesh& m = model.mesh;
  m.fill_default_user_ids();
  for (auto& s : m.sets)
    for (std::size_t e = 0; e < s.size(); ++e) {
      s.ply[e] = static_cast<std::int32_t>(s.user_id[e] % 3);
      s.tow[e] = static_cast<std::int32_t>(s.user_id[e] * 7);
    }
  std::vector<std::array<double, 3>> centre_of_id(7);  // by hexahedron user id
  const fem::ElementSet& hexes = m.elements(fem::ElementKind::Hex8);
  auto centre = [&](std::size_t e) {
    std::array<double, 3> c{0, 0, 0};
    for (auto v : hexes.nodes(e))
      for (std::size_t k = 0; k < 3; ++k) c[k] += m.coords[3 * static_cast<std::size_t>(v) + k] / 8;
    return c;
  };
  for (std::size_t e = 0; e < hexes.size(); ++e)
    centre_of_id[static_cast<std::size_t>(hexes.user_id[e])] = centre(e);
  fem::renumber_for_locality(m);
  for (const auto& s : m.sets)
    for (std::size_t e = 0; e < s.size(); ++e) {
      EXPECT_EQ(s.ply[e], s.user_id[e] % 3);
      EXPECT_EQ(s.tow[e], s.user_id[e] * 7);
    }
  for (std::size_t e = 0; e < hexes.size(); ++e) {
    const auto c = centre(e), c0 = centre_of_id[static_cast<std::size_t>(hexes.user_id[e])];
    for (std::size_t k = 0; k < 3; ++k) EXPECT_NEAR(c[k], c0[k], 1e-15);
  }
  std::size_t visits = 0;
  m.for_each_element_node(m.find_part("yarn"), [&](std::int32_t) { ++visits; });
  EXPECT_EQ(visits, 4u);
}

TEST(ElementGroups, OneGroupPerKindAndPartInKindOrderWithTheKernelsFields) {
  fem::Model model = block_and_bars();
  model.initial_velocities.push_back(
      {test::nodes_at(model.mesh, 0, 0.03), {1.0, 0, 0.5}});  // stretch
  fem::ExplicitSolver solver(model);
  const auto& groups = solver.groups();
  ASSERT_EQ(groups.size(), 2u);
  EXPECT_EQ(groups[0]->kind(), fem::ElementKind::Hex8);
  EXPECT_EQ(groups[0]->part(), model.mesh.find_part("block"));
  EXPECT_EQ(groups[1]->kind(), fem::ElementKind::Bar2);
  EXPECT_EQ(solver.n_elements(fem::ElementKind::Hex8), 6u);
  EXPECT_EQ(solver.n_elements(), 8u);
  EXPECT_EQ(solver.blocks<fem::Hex8Block>().size(), 1u);
  EXPECT_EQ(solver.blocks<fem::BarBlock>().at(0).n, 2u);
  for (int k = 0; k < 20; ++k) solver.step();

  auto X = solver.x.view();
  const auto& hex = solver.blocks<fem::Hex8Block>()[0];
  const auto specs = groups[0]->cell_fields();
  ASSERT_EQ(specs.size(), 4u);
  std::vector<std::vector<double>> values;
  std::vector<double*> out;
  for (const auto& f : specs) values.emplace_back(hex.n * static_cast<std::size_t>(f.components));
  for (auto& v : values) out.push_back(v.data());
  groups[0]->cell_values(X.data(), out.data());
  std::vector<double> cauchy(6 * hex.n), vm(hex.n), fibre(3 * hex.n);
  fem::hex8_output_fields(hex, X.data(), cauchy.data(), vm.data(), fibre.data());
  EXPECT_EQ(values[0], cauchy);
  EXPECT_EQ(values[1], vm);
  EXPECT_EQ(values[2], fibre);

  const auto& bar = solver.blocks<fem::BarBlock>()[0];
  std::vector<double> force(bar.n), strain(bar.n);
  double* bout[] = {force.data(), strain.data()};
  groups[1]->cell_values(X.data(), bout);
  EXPECT_EQ(force, bar.force);
  EXPECT_EQ(strain, bar.strain);
}

TEST(ElementGroups, APartHoldingTwoKindsIsRefused) {
  fem::Model model = block_and_bars();
  for (auto& p : model.mesh.elements(fem::ElementKind::Bar2).part)
    p = model.mesh.find_part("block");
  try {
    fem::ExplicitSolver solver(model);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("both hexahedron and bar"), std::string::npos) << e.what();
  }
}
