// Abaqus and LS-DYNA export of an impregnated model, read back: node, element, orientation,
// material and tie counts, and one element's local axes round-trip. With a crush: the LS-DYNA
// deck's failure materials, softening bonds, rigid tools (their facets on the sphere and the
// plane, outward), the punch's motion and the end time read back; the tools' meshes and the
// velocity ramp against their definitions; the Abaqus deck says what it leaves out.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "transfer/deck_common.hpp"
#include "transfer/deck_export.hpp"

namespace ncfsim {
namespace {

transfer::ExportModel two_tows() {
  transfer::ExportModel m;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 3; ++i) m.nodes.push_back({1e-3 * i, 1e-3 * j, 0.23e-3 * k});
  auto id = [](int i, int j, int k) { return static_cast<std::int32_t>(i + 3 * j + 6 * k); };
  for (int i = 0; i < 2; ++i)
    m.hex.push_back({id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1),
                     id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)});
  const double c = std::sqrt(0.5);
  m.frame = {{c, -c, 0, c, c, 0, 0, 0, 1}, {c, c, 0, -c, c, 0, 0, 0, 1}};  // +45 and -45 fibres
  m.material = {0, 1};
  m.materials = {
      {"tow_vf0600", 1548, {139e9, 8.5e9, 8.5e9, 0.26, 0.26, 0.36, 4.8e9, 4.8e9, 3.1e9}},
      {"tow_vf0650", 1580, {150e9, 9.5e9, 9.5e9, 0.25, 0.25, 0.35, 5.2e9, 5.2e9, 3.4e9}}};
  m.ties.push_back({"tow_tow", {{0, 3}}, {{1, 5}}, {}});
  return m;
}

TEST(DeckExport, AbaqusAndLsDynaDecksReadBackWithTheirCountsAndAxes) {
  const auto m = two_tows();
  const auto dir = std::filesystem::temp_directory_path() / "ncfsim_deck_export";
  std::filesystem::create_directories(dir);
  transfer::write_abaqus_inp(dir / "model.inp", m);
  transfer::write_lsdyna_keyword(dir / "model.k", m);
  for (const std::string format : {"abaqus", "lsdyna"}) {
    const auto c =
        transfer::read_deck(dir / (format == "abaqus" ? "model.inp" : "model.k"), format);
    EXPECT_EQ(c.nodes, 12u) << format;
    EXPECT_EQ(c.elements, 2u) << format;
    EXPECT_EQ(c.orientations, 2u) << format;
    EXPECT_EQ(c.materials, 2u) << format;
    EXPECT_EQ(c.ties, 1u) << format;
    ASSERT_EQ(c.axes.size(), 2u) << format;
    // element 2: fibre (a1) at -45 deg, a2 at +45 deg (Abaqus: a and b axes; LS-DYNA: a and d)
    const double h = std::sqrt(0.5);
    const double want[6] = {h, -h, 0, h, h, 0};
    for (int k = 0; k < 6; ++k)
      EXPECT_NEAR(c.axes[1][static_cast<std::size_t>(k)], want[k], 1e-9) << format << k;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "model.inp.tmp"));
  std::filesystem::remove_all(dir);
}

transfer::ExportModel two_tows_crushed() {
  auto m = two_tows();
  m.group = {0, 1};
  m.group_names = {"ply1", "ply2"};
  auto& c = m.crush;
  c.enabled = true;
  c.name = "two_tows_crush";
  for (int k = 0; k < 2; ++k)
    c.failure.push_back({2.8e9,
                         1.7e9,
                         60e6,
                         200e6,
                         80e6,
                         50e6,
                         {90e3, 80e3, 280, 800, 800, 500},
                         0.2,
                         {true, true, false, false, false, false}});
  c.bonds.push_back({40e6, 60e6, 300, 1000, 1.45});
  c.first_step = 1.8e-8;
  // Two tied nodes as the crush would tie them (a Radioss deck writes a spring each).
  m.ties[0].points = {{1, {1, 4, 10, 7}, {0.5, 0.5, 0, 0}, 2e8, 0.25e-6},
                      {4, {1, 4, 10, 7}, {0, 1, 0, 0}, 3e8, 0.5e-6}};
  transfer::ExportTool punch;
  punch.name = "punch";
  punch.sphere = true;
  punch.point = {1e-3, 0.5e-3, 0.026};
  punch.radius = 0.025;
  punch.velocity = {0, 0, -1.5};
  punch.ramp_time = 2e-4;
  punch.friction = 0.2;
  transfer::ExportTool support;
  support.name = "support";
  support.point = {0, 0, -1e-4};
  support.half_size = 0.01;
  support.friction = 0.3;
  c.tools = {punch, support};
  c.punch = 0;
  c.ply_contact = true;
  c.ply_friction = 0.3;
  c.end_time = 2.2e-3;
  c.history_interval = 2.5e-5;
  c.frame_interval = 1e-4;
  c.erosion_step_ratio = 0.2;
  return m;
}

std::string slurp_file(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

TEST(DeckExport, CrushDeckCarriesFailureBondsToolsMotionAndEndTime) {
  const auto m = two_tows_crushed();
  const auto dir = std::filesystem::temp_directory_path() / "ncfsim_deck_export_crush";
  std::filesystem::create_directories(dir);
  transfer::write_lsdyna_keyword(dir / "crush.k", m);
  const auto c = transfer::read_deck(dir / "crush.k", "lsdyna");
  std::size_t tool_nodes = 0, tool_facets = 0;
  for (const auto& t : m.crush.tools) {
    const auto mesh = transfer::deck::tool_mesh(t);
    tool_nodes += mesh.nodes.size(), tool_facets += mesh.quads.size();
  }
  EXPECT_EQ(c.nodes, 12u + tool_nodes);
  EXPECT_EQ(c.elements, 2u);
  EXPECT_EQ(c.orientations, 2u);
  EXPECT_EQ(c.materials, 2u);          // the tows' (the tools' rigid ones apart)
  EXPECT_EQ(c.failure_materials, 2u);  // *MAT_262
  EXPECT_EQ(c.ties, 1u);
  EXPECT_EQ(c.softening_ties, 1u);  // tiebreak, not tied
  EXPECT_EQ(c.rigid_parts, 2u);
  EXPECT_EQ(c.tool_elements, tool_facets);
  EXPECT_EQ(c.motions, 1u);   // the punch along its motion; the rest held (CON1)
  EXPECT_EQ(c.contacts, 3u);  // punch, support, plies
  EXPECT_DOUBLE_EQ(c.end_time, 2.2e-3);
  const std::string deck = slurp_file(dir / "crush.k");
  // The bond's law on its tiebreak card: OPTION 9, strengths, B-K (PARAM < 0), energies.
  EXPECT_NE(deck.find("         9     4e+07     6e+07     -1.45       300      1000"),
            std::string::npos);
  // The fibre modes erode (DAF = DKF = 0), matrix and shear do not (DMF = DSF = 1).
  EXPECT_NE(deck.find("        2         0         0         1         0\n"), std::string::npos);
  EXPECT_NE(deck.find("$ left out: "), std::string::npos);
  // The punch moves along z only: x and y held by its rigid material (CON1 4), the support fully.
  EXPECT_NE(deck.find("         1         4         7\n"), std::string::npos);
  EXPECT_NE(deck.find("         1         7         7\n"), std::string::npos);
  transfer::write_abaqus_inp(dir / "crush.inp", m);
  const std::string inp = slurp_file(dir / "crush.inp");
  EXPECT_NE(inp.find("** left out: the tows' per-mode damage"), std::string::npos);
  EXPECT_NE(inp.find("** the crush's tow failure (not carried: elastic here): Xt 2.8e+09"),
            std::string::npos);
  EXPECT_NE(inp.find("** the crush's resin bond (not carried by *TIE): strengths N 4e+07"),
            std::string::npos);
  const auto a = transfer::read_deck(dir / "crush.inp", "abaqus");
  EXPECT_EQ(a.elements, 2u);
  EXPECT_EQ(a.materials, 2u);
  std::filesystem::remove_all(dir);
}

TEST(DeckExport, RadiossDeckCarriesLawAxesTiesToolsMotionAndEndTime) {
  const auto m = two_tows_crushed();
  const auto dir = std::filesystem::temp_directory_path() / "ncfsim_deck_export_radioss";
  std::filesystem::create_directories(dir);
  const auto files = transfer::write_radioss_deck(dir, m);
  ASSERT_EQ(files.size(), 2u);
  EXPECT_EQ(files[0].filename(), "two_tows_crush_0000.rad");
  EXPECT_EQ(files[1].filename(), "two_tows_crush_0001.rad");
  const auto c = transfer::read_deck(files[0], "radioss");
  std::size_t tool_nodes = 0, tool_facets = 0;
  for (const auto& t : m.crush.tools) {
    const auto mesh = transfer::deck::tool_mesh(t);
    tool_nodes += mesh.nodes.size() + 1, tool_facets += mesh.quads.size();  // + the main node
  }
  EXPECT_EQ(c.nodes, 12u + tool_nodes + 2u);  // + an /RBE3 point per tied node
  EXPECT_EQ(c.elements, 2u);
  EXPECT_EQ(c.materials, 2u);  // LAW123 per class
  EXPECT_EQ(c.failure_materials, 2u);
  EXPECT_EQ(c.ties, 1u);  // one interface
  EXPECT_EQ(c.softening_ties, 1u);
  EXPECT_EQ(c.tie_points, 2u);
  EXPECT_EQ(c.rigid_parts, 2u);  // RBODY
  EXPECT_EQ(c.tool_elements, tool_facets);
  EXPECT_EQ(c.motions, 1u);   // IMPVEL along the motion; the rest held (BCS)
  EXPECT_EQ(c.contacts, 3u);  // tows on the punch both ways (a sphere), on the support
  EXPECT_DOUBLE_EQ(c.end_time, 2.2e-3);
  // Each brick's axes as the model's: element 2's fibre at -45 deg, its second axis at +45.
  ASSERT_EQ(c.orientations, 2u);
  const double h = std::sqrt(0.5);
  const double want[6] = {h, -h, 0, h, h, 0};
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(c.axes[1][static_cast<std::size_t>(k)], want[k], 1e-9);
  // LAW123's energies: ENKINK (fibre compression), ENA (fibre tension), ENB (matrix tension), ENT
  // (transverse shear), ENL (in-plane shear).
  const std::string deck = slurp_file(files[0]);
  EXPECT_NE(
      deck.find("               80000               90000                 280                 "
                "500                 800"),
      std::string::npos);
  EXPECT_NE(deck.find("# left out: the bonds' softening"), std::string::npos);
  // The second tie's spring: k within 1 % (its class's centre), failing at 40 MPa x 0.5 mm^2 =
  // 20 N (to its class's 1 %), its mass k (dt / 0.9)^2.
  const auto at = deck.find("/PROP/TYPE8/10002\ntow_tow_bond_");
  ASSERT_NE(at, std::string::npos) << deck;
  std::istringstream card(deck.substr(deck.find('\n', deck.find('\n', at) + 1) + 1));
  std::string mass_line, k_line, fail_line;
  std::getline(card, mass_line), std::getline(card, k_line), std::getline(card, fail_line);
  const double k = std::stod(k_line.substr(0, 20));
  EXPECT_NEAR(k, 3e8, 0.01 * 3e8);
  EXPECT_NEAR(std::stod(mass_line.substr(0, 20)), k * std::pow(1.8e-8 / 0.9, 2), 1e-9 * k);
  EXPECT_EQ(mass_line.substr(70, 20), "         1         1");  // Ifail, Ifail2: |F| on force
  EXPECT_NEAR(std::stod(fail_line.substr(60, 20)), -20.0, 0.2);
  EXPECT_NEAR(std::stod(fail_line.substr(80, 20)), 20.0, 0.2);
  // The punch held in x, y and rotation (its z driven), the support in everything.
  EXPECT_NE(deck.find("   110 111"), std::string::npos);
  EXPECT_NE(deck.find("   111 111"), std::string::npos);
  std::filesystem::remove_all(dir);
}

TEST(DeckExport, ToolMeshesLieOnTheirSurfacesFacingTheBody) {
  const auto m = two_tows_crushed();
  const auto& punch = m.crush.tools[0];
  const auto sphere = transfer::deck::tool_mesh(punch);
  for (const auto& p : sphere.nodes) {
    const double d[3] = {p[0] - punch.point[0], p[1] - punch.point[1], p[2] - punch.point[2]};
    EXPECT_NEAR(std::sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), punch.radius, 1e-12);
    EXPECT_LE(d[2], 1e-12);  // the half ahead of the punch's motion (-z)
  }
  auto outward = [](const transfer::deck::ToolMesh& mesh, std::size_t q,
                    const std::array<double, 3>& dir) {
    const auto& n = mesh.quads[q];
    const auto& a = mesh.nodes[static_cast<std::size_t>(n[0])];
    const auto& b = mesh.nodes[static_cast<std::size_t>(n[1])];
    const auto& c = mesh.nodes[static_cast<std::size_t>(n[2])];
    const double u[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
    const double w[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
    return (u[1] * w[2] - u[2] * w[1]) * dir[0] + (u[2] * w[0] - u[0] * w[2]) * dir[1] +
           (u[0] * w[1] - u[1] * w[0]) * dir[2];
  };
  for (std::size_t q = 0; q < sphere.quads.size(); ++q) {
    const auto& a = sphere.nodes[static_cast<std::size_t>(sphere.quads[q][1])];
    EXPECT_GT(
        outward(sphere, q, {a[0] - punch.point[0], a[1] - punch.point[1], a[2] - punch.point[2]}),
        0)
        << q;
  }
  // The facets' chord error: under 0.05 mm on the 25 mm punch.
  EXPECT_LT(punch.radius * (1 - std::cos(0.5 * 2 * M_PI / 64)), 5e-5);
  const auto& support = m.crush.tools[1];
  const auto plane = transfer::deck::tool_mesh(support);
  for (const auto& p : plane.nodes) {
    EXPECT_NEAR(p[2], support.point[2], 1e-15);
    EXPECT_LE(std::max(std::abs(p[0]), std::abs(p[1])), support.half_size + 1e-15);
  }
  for (std::size_t q = 0; q < plane.quads.size(); ++q)
    EXPECT_GT(outward(plane, q, support.axis), 0) << q;
}

TEST(DeckExport, VelocityRampIsTheEnginesCubicRamp) {
  const auto c = transfer::deck::ramp_curve(2e-4, 2.2e-3);
  ASSERT_GE(c.size(), 3u);
  EXPECT_EQ(c.front()[1], 0.0);
  for (const auto& [t, f] : c) {
    const double s = std::min(t / 2e-4, 1.0);
    EXPECT_NEAR(f, s * s * (3 - 2 * s), 1e-15) << t;
  }
  EXPECT_GE(c.back()[0], 2.2e-3);  // held to past the end
  EXPECT_EQ(c.back()[1], 1.0);
}

TEST(DeckExport, NumbersFitTheirFieldsWithABlankBefore) {
  for (const double v : {1566.91, 1.46158e11, 0.0156133201, -1.45, 3.07e14, 2.5e-5, 0.0})
    ASSERT_EQ(transfer::deck::field(v).size(), 10u) << v;
  EXPECT_EQ(transfer::deck::field(1.46158e11)[0], ' ');
  // Six significant digits at least where a value has that many.
  EXPECT_NEAR(std::stod(transfer::deck::field(0.0156133201)), 0.0156133201, 1e-5 * 0.0156133201);
}

TEST(DeckExport, ElementNamingAMissingMaterialIsRefused) {
  auto m = two_tows();
  m.material[1] = 7;
  EXPECT_THROW(transfer::write_abaqus_inp(std::filesystem::temp_directory_path() / "bad.inp", m),
               std::invalid_argument);
}

}  // namespace
}  // namespace ncfsim
