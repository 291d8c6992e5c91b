// The meso ring measure through the case and the solver (drape/probes/ring_shear_probe.hpp): on a
// flat, undeformed +-45 blanket the rays that meet it read zero inter-ply shear at the blanket's
// bottom face, the quadrants without a hit are null, and [[output.ring_shear]] is read once.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>

#include "drape/probes/fabric_fields.hpp"
#include "tests/flat_blanket_case.hpp"
#include "drape/probes/ring_shear_probe.hpp"
#include "fem/elements/hex8_block.hpp"
#include "fem/errors.hpp"
#include "fem/solver.hpp"
#include "workflow/case/engine_case.hpp"

namespace fs = std::filesystem;
using namespace ncfsim;

namespace {

const std::string kCase = std::string("[case]\nname = \"ring_flat\"\n") + test::kFlatBlanketBody + R"(
[time]
end_time = 1e-4
[output]
figures = false
# A ring in the plane x = 30 mm about an axis along x below the blanket: azimuth 0 points up
# (+z) through the blanket's bottom face.
[[output.ring_shear]]
parts = ["ncf_ply1", "ncf_ply2"]
centre = [0.0, 0.03, -0.01]
axis = [1.0, 0.0, 0.0]
zero_direction = [0.0, 0.0, 1.0]
height = 0.03
)";

fs::path write_case(const std::string& text, const std::string& name) {
  const fs::path p =
      fs::temp_directory_path() / (name + "_" + std::to_string(::getpid()) + ".toml");
  std::ofstream(p) << text;
  return p;
}

}  // namespace

TEST(RingShearProbe, FlatPlusMinus45BlanketReadsZeroShearWhereTheRaysMeetIt) {
  const fs::path file = write_case(kCase, "ring_flat");
  auto ec = workflow::load_engine_case(file, {});
  ASSERT_EQ(ec.ring_probes.size(), 1u);
  fem::ExplicitSolver solver(ec.model);
  const drape::RingShearMeasure m(ec.ring_probes[0], solver);
  const auto ring = m.ring(solver);
  ASSERT_EQ(ring.size(), 360u);
  int hits = 0;
  for (const auto& r : ring) {
    if (!r.hit) continue;
    ++hits;
    EXPECT_NEAR(r.shear_deg, 0.0, 1e-6) << r.azimuth_deg;
    EXPECT_NEAR(r.point.x, 0.03, 1e-12);
    // the bottom face of the lower ply, or a tow's side face where a ray slips into a tow gap
    EXPECT_GE(r.point.z, -1e-9) << r.azimuth_deg;
    EXPECT_LE(r.point.z, 0.47e-3) << r.azimuth_deg;
  }
  // atan(30 mm / 10 mm) = 71.6 deg either side of straight up meets the 60 mm blanket.
  EXPECT_GT(hits, 2 * 65);
  EXPECT_LT(hits, 2 * 73);
  nlohmann::json s;
  m.add_summary(solver, s);
  EXPECT_NEAR(s["max_shear_deg_q1"].get<double>(), 0.0, 1e-6);
  EXPECT_TRUE(s["max_shear_deg_q3"].is_null()) << "no ray pointing down meets the blanket";
  fs::remove(file);
}

TEST(RingShearProbe, OnlyOneRingAndTwoPlies) {
  std::string two =
      std::string(kCase) + "[[output.ring_shear]]\nparts = [\"ncf_ply1\", \"ncf_ply2\"]\n";
  const fs::path file = write_case(two, "ring_two");
  try {
    workflow::load_engine_case(file, {});
    FAIL() << "two rings were accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("ring_shear"), std::string::npos) << e.what();
  }
  fs::remove(file);
}


namespace {

// The flat +-45 blanket of kCase with its solver and its fabric fields (the solver borrows the
// case's model: the case lives as long as it).
struct FlatBlanketFields {
  fs::path file;
  workflow::EngineCase ec;
  std::unique_ptr<fem::ExplicitSolver> solver;
  std::unique_ptr<drape::FabricFields> fields;
  explicit FlatBlanketFields(const std::string& name)
      : file(write_case(kCase, name)), ec(workflow::load_engine_case(file, {})) {
    const auto& f = ec.fabric_summaries.at(0);
    solver = std::make_unique<fem::ExplicitSolver>(ec.model);
    fields = std::make_unique<drape::FabricFields>(f.name, f.ply_parts.at(0), f.ply_parts.at(1), *solver);
  }
  ~FlatBlanketFields() { fs::remove(file); }
};

}  // namespace

// The fabric's element fields (drape/probes/fabric_fields.hpp) on the flat +-45 blanket: none
// undeformed; under an in-plane simple shear x' = x + k y of both plies, every element reads the
// angle the mapped fibres (1, 1) and (1, -1) make, 90 - acos(|Fa.Fb| / |Fa||Fb|), and no slip;
// then ply 1 moved by d along x: slip d everywhere, the shear unchanged (the fibres stay).
TEST(FabricFields, ShearAngleAndSlipOfAnAffineDeformation) {
  const fs::path file = write_case(kCase, "fields_flat");
  auto ec = workflow::load_engine_case(file, {});
  ASSERT_EQ(ec.fabric_summaries.size(), 1u);
  const auto& f = ec.fabric_summaries[0];
  ASSERT_EQ(f.ply_parts.size(), 2u);
  fem::ExplicitSolver solver(ec.model);
  const drape::FabricFields m(f.name, f.ply_parts[0], f.ply_parts[1], solver);
  auto finite_values = [](const std::vector<double>& v) {
    std::vector<double> out;
    for (double e : v)
      if (std::isfinite(e)) out.push_back(e);
    return out;
  };
  auto v = m.values(solver);
  const std::size_t n = v.shear_deg.size();
  ASSERT_GT(n, 100u);
  ASSERT_EQ(finite_values(v.shear_deg).size(), n) << "every element finds the other ply";
  for (double e : v.shear_deg) EXPECT_NEAR(e, 0.0, 1e-9);
  for (double e : v.slip_m) EXPECT_NEAR(e, 0.0, 1e-15);

  const double k = 0.3;
  {
    auto X = solver.x.view();
    for (std::size_t i = 0; i < X.size() / 3; ++i) X[3 * i] += k * X[3 * i + 1];
  }
  const double c = std::abs((1 + k) * (1 - k) - 1.0) / (std::hypot(1 + k, 1.0) * std::hypot(1 - k, 1.0));
  const double expected = 90.0 - std::acos(c) * 180.0 / M_PI;  // 16.6 deg at k = 0.3
  v = m.values(solver);
  for (double e : v.shear_deg) EXPECT_NEAR(e, expected, 1e-6);
  for (double e : v.slip_m) EXPECT_NEAR(e, 0.0, 1e-12);

  const double d = 1.0e-3;  // less than half an element: the neighbours stay the same
  {
    auto X = solver.x.view();
    std::vector<char> in_ply1(X.size() / 3, 0);
    for (const auto& b : solver.blocks<fem::Hex8Block>())
      if (b.part == f.ply_parts[0])
        for (std::size_t I = 0; I < 8 * b.n; ++I) in_ply1[static_cast<std::size_t>(b.conn[I])] = 1;
    for (std::size_t i = 0; i < in_ply1.size(); ++i)
      if (in_ply1[i]) X[3 * i] += d;
  }
  v = m.values(solver);
  for (double e : v.shear_deg) EXPECT_NEAR(e, expected, 1e-6);
  for (double e : v.slip_m) EXPECT_NEAR(e, d, 1e-12);

  // In the frames: one field each, NaN on the stitch bars.
  std::vector<fem::MeasureCellField> fields;
  m.add_frame_fields(solver, fields);
  ASSERT_EQ(fields.size(), 3u);
  EXPECT_EQ(fields[0].name, "shear_angle_deg");
  EXPECT_EQ(fields[1].name, "interply_slip_m");
  const std::size_t nh = solver.n_elements(fem::ElementKind::Hex8), nb = solver.n_elements(fem::ElementKind::Bar2);
  ASSERT_EQ(fields[0].values.size(), nh + nb);
  EXPECT_EQ(finite_values(fields[0].values).size(), n);
  EXPECT_TRUE(std::isnan(fields[0].values[nh + nb - 1]));
  nlohmann::json s;
  m.add_summary(solver, s);
  EXPECT_NEAR(s["fabrics"]["ncf"]["max_shear_deg"].get<double>(), expected, 1e-6);
  EXPECT_NEAR(s["fabrics"]["ncf"]["max_interply_slip_m"].get<double>(), d, 1e-12);
  fs::remove(file);
}

// Draw-in of the blank's outline: none undeformed; a uniform in-plane shrink by a factor (1 - c)
// about the blank's centre (30, 30) mm brings each outline node nearer by c times its distance:
// the 30 mm to the edge mid-points, 42.4 mm to the corners.
TEST(FabricFields, DrawInOfTheOutline) {
  FlatBlanketFields b("fields_drawin");
  fem::ExplicitSolver& solver = *b.solver;
  const drape::FabricFields& m = *b.fields;
  nlohmann::json s;
  m.add_summary(solver, s);
  EXPECT_NEAR(s["fabrics"]["ncf"]["draw_in_max_m"].get<double>(), 0.0, 1e-15);
  const double c = 0.1;
  {
    auto X = solver.x.view();
    for (std::size_t i = 0; i < X.size() / 3; ++i)
      for (int k = 0; k < 2; ++k) X[3 * i + k] = 0.03 + (1 - c) * (X[3 * i + k] - 0.03);
  }
  m.add_summary(solver, s);
  const auto& fab = s["fabrics"]["ncf"];
  EXPECT_NEAR(fab["draw_in_mid_edge_m"].get<double>(), c * 0.03, 0.05 * c * 0.03);
  EXPECT_NEAR(fab["draw_in_corner_m"].get<double>(), c * 0.03 * std::sqrt(2.0), 0.05 * c * 0.03);
  EXPECT_NEAR(fab["draw_in_max_m"].get<double>(), c * 0.03 * std::sqrt(2.0), 0.05 * c * 0.03);
}

// Wrinkle indicator: none on the flat blanket; a wave z = A sin(2 pi x / L) shorter than the
// neighbourhood (L = 20 mm, A = 1 mm: largest slope 2 pi A / L, 17.4 deg) reads close to its
// slope where it is steepest (the elements' normals average the slope over their length).
TEST(FabricFields, WrinkleAngleReadsTheSlopeOfAShortWave) {
  FlatBlanketFields b("fields_wrinkle");
  fem::ExplicitSolver& solver = *b.solver;
  const drape::FabricFields& m = *b.fields;
  for (double w : m.values(solver).wrinkle_deg) EXPECT_NEAR(w, 0.0, 1e-6);
  const double A = 1e-3, L = 0.02;
  {
    auto X = solver.x.view();
    for (std::size_t i = 0; i < X.size() / 3; ++i) X[3 * i + 2] += A * std::sin(2 * M_PI * X[3 * i] / L);
  }
  const double slope_deg = std::atan(2 * M_PI * A / L) * 180.0 / M_PI;
  double most = 0;
  for (double w : m.values(solver).wrinkle_deg) most = std::max(most, w);
  EXPECT_GT(most, 0.6 * slope_deg);
  EXPECT_LT(most, 1.2 * slope_deg);
}
