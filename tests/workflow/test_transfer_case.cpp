// The transfer stage end to end (issue #20): a flat +-45 blanket is run for a few cycles (nearly
// undeformed), then `ncfsim run` of a kind = "transfer" case maps it: every tow hexahedron, Vf at
// its undeformed value, fibre directions at +-45 deg in orthonormal frames, plies tied face to face
// and tows to their neighbours; `ncfsim export` writes Abaqus and LS-DYNA decks that read back with
// the same counts; bad input names the key.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "fem/io/stage_handoff.hpp"
#include "tests/flat_blanket_case.hpp"
#include "tests/workflow/cli_test_support.hpp"
#include "transfer/deck_export.hpp"

namespace ncfsim::test {
namespace {

const std::string& kBlanket = kFlatBlanketBriefRun;

const char* kTransfer = R"(
[case]
name = "flat_transfer"
kind = "transfer"
[source]
results = "drape/results.h5"
[trim]
radius = 0.0
centre = [0.03, 0.03, 0.0]
)";

struct Fixture {
  fs::path dir = fresh_dir("transfer_case");
  fs::path drape_case = dir / "blanket.toml", transfer_case = dir / "transfer.toml";
  Fixture() {
    fs::create_directories(dir);
    std::ofstream(drape_case) << kBlanket;
    std::ofstream(transfer_case) << kTransfer;
    const auto r = run_cli({"-q", "run", drape_case.string(), "-o", (dir / "drape").string()});
    EXPECT_EQ(r.code, 0) << r.output;
  }
  ~Fixture() { fs::remove_all(dir); }
};

TEST(CliTransfer, FlatBlanketMapsEveryTowWithItsFrameVfAndTies) {
  Fixture f;
  const fs::path out = f.dir / "transfer";
  const auto r = run_cli({"run", f.transfer_case.string(), "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  const auto drape = nlohmann::json::parse(slurp(f.dir / "drape" / "summary.json"));
  const std::size_t hexes = drape["elements"]["hex8"];
  EXPECT_EQ(s["stage"], "transfer");
  EXPECT_EQ(s["elements_mapped"].get<std::size_t>(), hexes);
  EXPECT_EQ(s["elements_lost"], 0);
  // The memory estimate made from the source frame within 25 % of the measured peak.
  if (!kSanitizedBuild) {
    EXPECT_NEAR(s["memory_estimate_MB"].get<double>(), s["peak_memory_MB"].get<double>(),
                0.25 * s["peak_memory_MB"].get<double>());
  }
  EXPECT_NEAR(s["vf_min"].get<double>(), 0.6, 1e-3);
  EXPECT_NEAR(s["vf_max"].get<double>(), 0.6, 1e-3);
  // Every ply-1 tow lies on ply 2 (its top faces tied, less the tow ends at the blanket's edge),
  // and each tow beside its neighbours.
  EXPECT_GT(s["tie_pairs_interply"].get<std::size_t>(), hexes / 2 * 8 / 10);
  EXPECT_GT(s["tie_pairs_intraply"].get<std::size_t>(), hexes / 4);
  EXPECT_EQ(s["stitches_kept"], 0);
  // Frames: orthonormal, axis 1 at +-45 deg in the plane, axis 3 through the thickness (z).
  const auto frame = fem::io::read_last_frame(out / "results.h5");
  const auto* a1 = frame.field("fibre_direction");
  const auto* a2 = frame.field("material_axis_2");
  const auto* a3 = frame.field("material_axis_3");
  ASSERT_TRUE(a1 && a2 && a3);
  for (std::size_t e = 0; e < hexes; ++e) {
    const double* u = &a1->values[3 * e];
    const double* v = &a2->values[3 * e];
    const double* w = &a3->values[3 * e];
    auto dotp = [](const double* p, const double* q) {
      return p[0] * q[0] + p[1] * q[1] + p[2] * q[2];
    };
    ASSERT_NEAR(dotp(u, u), 1.0, 1e-9);
    ASSERT_NEAR(dotp(v, v), 1.0, 1e-9);
    ASSERT_NEAR(dotp(u, v), 0.0, 1e-9);
    ASSERT_NEAR(dotp(u, w), 0.0, 1e-9);
    EXPECT_NEAR(std::abs(u[0]), std::sqrt(0.5), 1e-3) << e;
    EXPECT_NEAR(std::abs(u[1]), std::sqrt(0.5), 1e-3) << e;
    EXPECT_NEAR(std::abs(w[2]), 1.0, 1e-6) << e;
  }
  EXPECT_TRUE(fs::exists(out / "materials.csv"));
  EXPECT_TRUE(fs::exists(out / "vf_histogram.csv"));

  // Decks that read back with the model's counts.
  for (const std::string format : {"abaqus", "lsdyna"}) {
    const auto e = run_cli({"export", out.string(), "--format", format});
    ASSERT_EQ(e.code, 0) << e.output;
    const auto deck = transfer::read_deck(
        out / (format == "abaqus" ? "impregnated.inp" : "impregnated.k"), format);
    EXPECT_EQ(deck.elements, hexes) << format;
    EXPECT_EQ(deck.nodes, frame.n_points()) << format;
    EXPECT_EQ(deck.materials, s["material_classes"].get<std::size_t>()) << format;
    EXPECT_EQ(deck.ties, 2u) << format;  // the interply and intraply interfaces
  }
  EXPECT_EQ(run_cli({"export", (f.dir / "drape").string(), "--format", "abaqus"}).code, 2)
      << "a drape run is not a transfer run";
}

// Kept stitches (`[stitches] keep = true`): each drape stitch bar beside the kept tows stays a
// bar, its nodes where the drape left them (the same length), carrying the cured yarn's constants
// to the crush, which ties every stitch node to the nearest tow face, and to the decks (T3D2 /
// cable elements beside the hexahedra).
TEST(CliTransfer, KeptStitchesBecomeBarsBetweenTowNodes) {
  Fixture f;
  const fs::path tc = f.dir / "transfer_stitched.toml", out = f.dir / "transfer_stitched";
  std::ofstream(tc) << kTransfer << "[stitches]\nkeep = true\n";
  const auto r = run_cli({"run", tc.string(), "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = nlohmann::json::parse(slurp(out / "summary.json"));
  const auto drape = nlohmann::json::parse(slurp(f.dir / "drape" / "summary.json"));
  const std::size_t hexes = drape["elements"]["hex8"], bars = drape["elements"]["bar2"];
  const std::size_t kept = s["stitches_kept"];
  ASSERT_GT(bars, 0u);
  EXPECT_EQ(kept + s["stitches_dropped"].get<std::size_t>(), bars);
  // On the flat blanket the stitches lie on the tows, but for a few at the corners, where the
  // generator dropped the tows too short to hold a stitch.
  EXPECT_GT(kept, bars * 95 / 100) << r.output;

  const auto model = fem::io::read_last_frame(out / "results.h5");
  const auto source = fem::io::read_last_frame(f.dir / "drape" / "results.h5");
  ASSERT_EQ(model.mesh.n_bar(), kept);
  ASSERT_EQ(model.mesh.n_hex(), hexes);
  std::vector<char> hex_node(model.n_points(), 0);
  for (auto n : model.mesh.hex().conn) hex_node[static_cast<std::size_t>(n)] = 1;
  auto length = [](const fem::io::StageFrame& fr, std::size_t b) {
    double d2 = 0;
    for (std::size_t c = 0; c < 3; ++c) {
      const double d =
          fr.coordinates[3 * static_cast<std::size_t>(fr.mesh.bars().conn[2 * b + 1]) + c] -
          fr.coordinates[3 * static_cast<std::size_t>(fr.mesh.bars().conn[2 * b]) + c];
      d2 += d * d;
    }
    return std::sqrt(d2);
  };
  std::map<std::int64_t, std::size_t> source_bar;
  for (std::size_t b = 0; b < source.mesh.n_bar(); ++b)
    source_bar[source.mesh.bars().user_id[b]] = b;
  for (std::size_t b = 0; b < kept; ++b) {
    EXPECT_FALSE(hex_node[static_cast<std::size_t>(model.mesh.bars().conn[2 * b])] ||
                 hex_node[static_cast<std::size_t>(model.mesh.bars().conn[2 * b + 1])])
        << "bar " << b << ": the stitch nodes stay nodes of their own";
    const auto it = source_bar.find(model.mesh.bars().user_id[b]);
    ASSERT_NE(it, source_bar.end()) << "bar " << b << " is no stitch of the drape";
    EXPECT_NEAR(length(model, b), length(source, it->second), 1e-12) << b;
  }
  const auto* E = model.field("stitch_modulus_Pa");
  const auto* A = model.field("stitch_area_m2");
  ASSERT_TRUE(E && A);
  EXPECT_DOUBLE_EQ(E->values[hexes], 10e9);
  EXPECT_NEAR(A->values[hexes], 7.6e-6 / 1380, 1e-15);
  EXPECT_TRUE(std::isnan(E->values[0])) << "a hexahedron has no yarn modulus";

  for (const std::string format : {"abaqus", "lsdyna"}) {
    const auto e = run_cli({"export", out.string(), "--format", format});
    ASSERT_EQ(e.code, 0) << e.output;
    const auto deck = transfer::read_deck(
        out / (format == "abaqus" ? "impregnated.inp" : "impregnated.k"), format);
    EXPECT_EQ(deck.bars, kept) << format;
    EXPECT_EQ(deck.elements, hexes + kept) << format;
    EXPECT_EQ(deck.materials, s["material_classes"].get<std::size_t>() + 1) << format;
  }

  // The crush builds the bars with the cured yarn's tension-only law and ties every stitch node
  // to a tow face; pressed, it keeps its energy balance.
  const fs::path crush = f.dir / "crush";
  const auto c = run_cli({"run",   (kSource / "cases/hemisphere/crush.toml").string(),
                          "-o",    crush.string(),
                          "--set", "model.source=" + (out / "results.h5").string(),
                          "--set", "model.damage.fracture_energy.fibre_tension=300000.0",
                          "--set", "model.damage.fracture_energy.fibre_compression=110000.0",
                          "--set", "model.damage.fracture_energy.matrix_tension=1400.0",
                          "--set", "model.damage.fracture_energy.transverse_shear=1600.0",
                          "--set", "tool[0].point=[0.03,0.03,0.02551]",
                          "--set", "tool[0].ramp_time=1e-6",
                          "--set", "tool[1].seat_clearance=1e-5",
                          "--set", "time.end_time=1e-4",
                          "--set", "time.quasi_static_from=5e-5",
                          "--set", "output.figures=false",
                          "--set", "output.report=false"});
  ASSERT_EQ(c.code, 0) << c.output;
  const auto cs = nlohmann::json::parse(slurp(crush / "summary.json"));
  EXPECT_EQ(cs["elements"]["bar2"].get<std::size_t>(), kept);
  EXPECT_LT(cs["energy_balance_error"].get<double>(), 0.01);
  EXPECT_NE(c.output.find("stitch nodes tied to the nearest tow face"), std::string::npos);
  EXPECT_NE(c.output.find("(0 beside no face: free)"), std::string::npos) << c.output;
}

TEST(CliTransfer, BadInputNamesTheKey) {
  Fixture f;
  const struct {
    std::vector<std::string> sets;
    std::string key;
  } bad[] = {
      {{"source.results=nowhere/results.h5"}, "source.results"},
      {{"fibre.E1=0.0"}, "fibre.E1"},
      {{"impregnation.vf_undeformed=0.95"}, "impregnation.vf_undeformed"},
      {{"trim.radius=1e-4"}, "trim.radius"},
      {{"stitches.keep=true", "stitches.modulus=0.0"}, "stitches.modulus"},
      {{"stitches.keep=true", "stitches.capture_distance=-1e-3"}, "stitches.capture_distance"},
  };
  for (const auto& b : bad) {
    std::vector<std::string> args{"run", f.transfer_case.string(), "-o", (f.dir / "bad").string()};
    for (const auto& s : b.sets) args.insert(args.end(), {"--set", s});
    const auto r = run_cli(args);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(b.key), std::string::npos) << r.output;
  }
  // A transfer's (or a crush's) results are not a drape's: the record beside them says so.
  {
    const fs::path t1 = f.dir / "t1";
    auto ok = run_cli({"-q", "run", f.transfer_case.string(), "-o", t1.string()});
    ASSERT_EQ(ok.code, 0) << ok.output;
    const auto r = run_cli({"run", f.transfer_case.string(), "-o", (f.dir / "bad").string(),
                            "--set", "source.results=" + (t1 / "results.h5").string()});
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find("source.results"), std::string::npos) << r.output;
    EXPECT_NE(r.output.find("the result of a 'transfer' run"), std::string::npos) << r.output;
  }
  // An unfinished drape run (its summary says so) is refused.
  const fs::path summary = f.dir / "drape" / "summary.json";
  auto s = nlohmann::json::parse(slurp(summary));
  s["status"] = "interrupted";
  std::ofstream(summary) << s.dump();
  const auto r = run_cli({"run", f.transfer_case.string(), "-o", (f.dir / "bad").string()});
  EXPECT_EQ(r.code, 2) << r.output;
  EXPECT_NE(r.output.find("did not complete"), std::string::npos) << r.output;
}

}  // namespace
}  // namespace ncfsim::test
