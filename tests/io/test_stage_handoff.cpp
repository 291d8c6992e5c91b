// Stage hand-off (issue 17): a run's results.h5, read back through fem::io::read_last_frame,
// rebuilds the same model: nodes, elements, parts, materials, user ids and the fabric's ply and
// tow ids, reference and current coordinates equal (bitwise: they are stored as float64). The
// model is the stitched picture-frame cell (two plies of tows, stitches as bars, a rigid frame),
// written through the run's own conversion (workflow/run/result_mesh.hpp) and XdmfResultWriter.
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "fem/errors.hpp"
#include "fem/io/stage_handoff.hpp"
#include "fem/solver.hpp"
#include "workflow/case/engine_case.hpp"
#include "workflow/run/result_mesh.hpp"
#include "workflow/stages/stage_registry.hpp"

namespace fs = std::filesystem;
using namespace ncfsim;

namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d =
      fs::temp_directory_path() / ("ncfsim_handoff_" + name + "_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

struct Element {
  std::vector<std::int32_t> nodes;
  int part = -1, material = -1, ply = -1, tow = -1;
  bool operator==(const Element&) const = default;
};

// Elements of a mesh by kind and user id (the file keeps the solver's block order).
std::map<std::pair<int, std::int64_t>, Element> by_user_id(const fem::Mesh& m,
                                                           const fem::Model& model) {
  std::map<std::pair<int, std::int64_t>, Element> out;
  for (const auto& set : m.sets)
    for (std::size_t e = 0; e < set.size(); ++e) {
      const auto& pp = model.parts[static_cast<std::size_t>(set.part[e])];
      const bool solid = set.kind == fem::ElementKind::Hex8;
      const auto n = set.nodes(e);
      out[{set.nodes_per_element, set.user_id[e]}] = {std::vector<std::int32_t>(n.begin(), n.end()),
                                                      set.part[e], solid ? pp.material : pp.bar_law,
                                                      solid && !set.ply.empty() ? set.ply[e] : -1,
                                                      solid && !set.tow.empty() ? set.tow[e] : -1};
    }
  return out;
}

}  // namespace

TEST(StageHandoff, LastFrameRebuildsTheFabricModel) {
  auto ec = workflow::load_engine_case(
      fs::path(NCFSIM_SOURCE_DIR) / "cases/drape/picture_frame_positive.toml",
      {"output.figures=false"});
  fem::ExplicitSolver solver(ec.model);
  const fem::Mesh& mesh = ec.model.mesh;
  const fs::path dir = fresh_dir("pf");
  {
    fem::io::XdmfResultWriter writer(dir, workflow::result_mesh(solver));
    writer.write_frame(workflow::make_frame(solver));
    for (int i = 0; i < 20; ++i) solver.step();
    writer.write_frame(workflow::make_frame(solver));
    writer.close();
  }
  const fem::io::StageFrame fr = fem::io::read_last_frame(dir / "results.h5");
  EXPECT_EQ(fr.index, 1u);
  EXPECT_EQ(fr.n_frames, 2u);
  EXPECT_EQ(fr.cycle, solver.cycle());
  EXPECT_EQ(fr.time, solver.time());

  // Counts: nodes, elements per kind, parts, materials.
  ASSERT_EQ(fr.n_points(), mesh.n_nodes());
  EXPECT_EQ(fr.mesh.n_hex(), mesh.n_elements(fem::ElementKind::Hex8));
  EXPECT_EQ(fr.mesh.n_bar(), mesh.n_elements(fem::ElementKind::Bar2));
  EXPECT_GT(fr.mesh.n_bar(), 0u) << "the stitches";
  EXPECT_EQ(fr.mesh.part_names, mesh.part_names);
  ASSERT_EQ(fr.mesh.material_names.size(), ec.model.materials.size());
  for (std::size_t k = 0; k < ec.model.materials.size(); ++k)
    EXPECT_EQ(fr.mesh.material_names[k], ec.model.materials[k]->name());
  ASSERT_EQ(fr.mesh.bar_law_names.size(), ec.model.bar_laws.size());
  EXPECT_EQ(fr.mesh.node_user_id, mesh.node_user_id);

  // Coordinates: reference as in the model, current as the solver's.
  EXPECT_EQ(fr.reference_coordinates(), mesh.coords);
  auto X = solver.x.view();
  EXPECT_EQ(fr.coordinates, std::vector<double>(X.data(), X.data() + 3 * mesh.n_nodes()));
  ASSERT_NE(fr.field("velocity"), nullptr);
  ASSERT_NE(fr.field("fibre_direction"), nullptr);

  // The rebuilt mesh holds the same elements (by user id) with the same nodes, part, material,
  // ply and tow.
  const fem::Mesh rebuilt = workflow::mesh_from_stage_frame(fr, false);
  EXPECT_NO_THROW(rebuilt.validate());
  EXPECT_EQ(rebuilt.coords, mesh.coords);
  const auto original = by_user_id(mesh, ec.model), again = by_user_id(rebuilt, ec.model);
  EXPECT_EQ(original.size(), mesh.n_elements()) << "user ids are unique per kind";
  EXPECT_TRUE(original == again);
  for (std::size_t e = 0; e < fr.mesh.n_hex(); ++e)  // the material per element as stored
    EXPECT_EQ(fr.mesh.hex().material[e],
              ec.model.parts[static_cast<std::size_t>(fr.mesh.hex().part[e])].material);
  std::set<std::pair<int, int>> tows, tows_again;
  const auto& hexes = mesh.elements(fem::ElementKind::Hex8);
  const auto& hexes_again = rebuilt.elements(fem::ElementKind::Hex8);
  for (std::size_t e = 0; e < hexes.size(); ++e)
    if (hexes.tow[e] >= 0) tows.insert({hexes.ply[e], hexes.tow[e]});
  for (std::size_t e = 0; e < hexes_again.size(); ++e)
    if (hexes_again.tow[e] >= 0) tows_again.insert({hexes_again.ply[e], hexes_again.tow[e]});
  EXPECT_GE(tows.size(), 4u) << "two plies of tows";
  EXPECT_EQ(tows, tows_again);

  // The deformed shape: the frame's current coordinates.
  EXPECT_EQ(workflow::mesh_from_stage_frame(fr, true).coords, fr.coordinates);
  fs::remove_all(dir);
}

TEST(StageHandoff, FramesByIndexAndTime) {
  auto ec =
      workflow::load_engine_case(fs::path(NCFSIM_SOURCE_DIR) / "cases/verification/cantilever.toml",
                                 {"mesh.resolution=coarse"});
  fem::ExplicitSolver solver(ec.model);
  const fs::path dir = fresh_dir("cantilever");
  std::vector<double> times;
  {
    fem::io::XdmfResultWriter writer(dir, workflow::result_mesh(solver));
    for (int f = 0; f < 3; ++f) {
      for (int i = 0; i < 5; ++i) solver.step();
      writer.write_frame(workflow::make_frame(solver));
      times.push_back(solver.time());
    }
  }
  const fs::path h5 = dir / "results.h5";
  EXPECT_EQ(fem::io::read_frame(h5, 1).time, times[1]);
  EXPECT_EQ(fem::io::read_frame_at_time(h5, 0.5 * (times[1] + times[2])).index, 1u);
  EXPECT_EQ(fem::io::read_frame_at_time(h5, times[2]).index, 2u);
  EXPECT_EQ(fem::io::read_last_frame(h5).index, 2u);
  EXPECT_THROW(fem::io::read_frame(h5, 3), std::out_of_range);
  EXPECT_THROW(fem::io::read_frame_at_time(h5, 0.5 * times[0]), std::out_of_range);
  const auto fr = fem::io::read_last_frame(h5);
  EXPECT_TRUE(fr.mesh.hex_tow.empty() ||
              fr.mesh.hex_tow == std::vector<std::int32_t>(fr.mesh.n_hex(), -1))
      << "no fabric: no tows";
  EXPECT_EQ(fr.mesh.hex().user_id.size(), fr.mesh.n_hex());
  fs::remove_all(dir);
}

TEST(StageRegistry, UnknownKindNamesTheAllowedOnes) {
  EXPECT_EQ(workflow::find_stage("engine").kind, "engine");
  EXPECT_EQ(workflow::find_stage("crush").kind, "crush");
  EXPECT_EQ(workflow::find_stage("workflow").kind, "workflow");
  try {
    workflow::find_stage("macro_drape", "case.toml");
    FAIL() << "no macro drape stage yet";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "case.kind");
    const std::string m = e.what();
    EXPECT_NE(m.find("'macro_drape'"), std::string::npos) << m;
    EXPECT_NE(m.find("allowed: engine"), std::string::npos) << m;
    EXPECT_NE(m.find("transfer"), std::string::npos) << m;
  }
  EXPECT_EQ(
      workflow::case_kind(fs::path(NCFSIM_SOURCE_DIR) / "cases/verification/cantilever.toml", {}),
      "engine");
  EXPECT_EQ(workflow::case_kind(fs::path(NCFSIM_SOURCE_DIR) / "cases/verification/cantilever.toml",
                                {"case.kind=transfer"}),
            "transfer");
}

TEST(StageHandoff, OptionalIdsAreEmptyOrOnePerElement) {
  fem::io::ResultMesh m;
  m.points = {0, 0, 0, 1, 0, 0};
  m.bars().conn = {0, 1};
  m.bars().part = {0};
  EXPECT_NO_THROW(fem::io::validate_mesh(m));  // no hand-off ids: an older writer's mesh
  m.bars().user_id = {7, 8};
  EXPECT_THROW(fem::io::validate_mesh(m), std::invalid_argument);
  m.bars().user_id = {7};
  m.node_user_id = {1};
  EXPECT_THROW(fem::io::validate_mesh(m), std::invalid_argument);
  m.node_user_id = {1, 2};
  m.hex_ply = {0};  // no hexahedra
  EXPECT_THROW(fem::io::validate_mesh(m), std::invalid_argument);
}
