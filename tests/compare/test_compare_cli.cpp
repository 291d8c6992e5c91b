// `ncfsim compare` end to end: the project's own results written as a .vtu and read back as an
// imported macro result give the run's own ring (ring_shear.csv) within 0.1 deg (issue #19's
// acceptance), the comparison files are written, and bad input exits 2 naming the file.
//
// Two results of the project: the kinematic drape of the hemisphere (cases/hemisphere/
// fishnet.toml, ~1 s: shear 0 .. 26 deg round the ring), whose net.csv the test writes as a .vtu
// of quadrilaterals with the point field shear_deg; and a brief meso run of a flat +-45 blanket
// (tests/flat_blanket_case.hpp) with frames as .vtu and a ring measure across its bottom face,
// whose last frame (hexahedra with the cell field shear_angle_deg) is imported as it is.
#include <gtest/gtest.h>
#include <vtkCellArray.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>

#include "tests/flat_blanket_case.hpp"
#include "tests/workflow/cli_test_support.hpp"

namespace ncfsim::test {
namespace {

using nlohmann::json;

// net.csv (i, j, x_m, y_m, z_m, shear_deg) as a .vtu of the net's quadrilaterals
// (i, j) (i+1, j) (i+1, j+1) (i, j+1), the point field shear_deg.
void net_to_vtu(const fs::path& net_csv, const fs::path& vtu) {
  const auto net = read_history(net_csv);
  const auto ci = net.column("i"), cj = net.column("j"), cx = net.column("x_m"),
             cy = net.column("y_m"), cz = net.column("z_m"), cs = net.column("shear_deg");
  ASSERT_LT(cs, net.columns.size());
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  vtkNew<vtkDoubleArray> shear;
  shear->SetName("shear_deg");
  std::map<std::pair<long, long>, vtkIdType> id;
  for (const auto& r : net.rows) {
    id[{std::lround(r[ci]), std::lround(r[cj])}] = pts->InsertNextPoint(r[cx], r[cy], r[cz]);
    shear->InsertNextValue(r[cs]);
  }
  vtkNew<vtkUnstructuredGrid> g;
  g->SetPoints(pts);
  g->GetPointData()->AddArray(shear);
  for (const auto& [ij, a] : id) {
    const auto [i, j] = ij;
    const auto b = id.find({i + 1, j}), c = id.find({i + 1, j + 1}), d = id.find({i, j + 1});
    if (b == id.end() || c == id.end() || d == id.end()) continue;
    const vtkIdType q[4] = {a, b->second, c->second, d->second};
    g->InsertNextCell(VTK_QUAD, 4, q);
  }
  vtkNew<vtkXMLUnstructuredGridWriter> w;
  w->SetFileName(vtu.c_str());
  w->SetInputData(g);
  ASSERT_EQ(w->Write(), 1);
}

const json& source(const json& s, const std::string& label) {
  for (const auto& e : s["sources"])
    if (e["label"] == label) return e;
  throw std::out_of_range("no source " + label);
}

const json& pair(const json& s, const std::string& a, const std::string& b) {
  for (const auto& e : s["pairs"])
    if (e["a"] == a && e["b"] == b) return e;
  throw std::out_of_range("no pair " + a + " - " + b);
}

TEST(CliCompare, FishnetReadBackAsAVtuGivesItsOwnRing) {
  const fs::path fish = fresh_dir("compare_fishnet"), out = fresh_dir("compare_out");
  auto r = run_cli(
      {"-q", "run", (kSource / "cases/hemisphere/fishnet.toml").string(), "-o", fish.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const fs::path vtu = fish.parent_path() / (fish.filename().string() + "_net.vtu");
  net_to_vtu(fish / "net.csv", vtu);
  ASSERT_FALSE(HasFatalFailure());
  r = run_cli({"compare", "fishnet=" + fish.string(), "macro=" + vtu.string(),
               "cloud=" + (fish / "net.csv").string(), "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(s["stage"], "compare");
  EXPECT_EQ(s["status"], "completed");
  const auto fsum = json::parse(slurp(fish / "summary.json"));
  const auto& f = source(s, "fishnet");
  const auto& m = source(s, "macro");
  EXPECT_EQ(f["kind"], "kinematic");
  EXPECT_EQ(m["kind"], "imported");
  EXPECT_EQ(m["method"], "surface");
  EXPECT_EQ(m["ring_samples_hit"], 360);
  for (int k = 1; k <= 4; ++k) {
    const std::string q = "max_shear_deg_q" + std::to_string(k);
    EXPECT_NEAR(f[q].get<double>(), fsum["kinematic_" + q].get<double>(), 1e-6) << q;
    EXPECT_NEAR(m[q].get<double>(), fsum["kinematic_" + q].get<double>(), 0.1) << q;
  }
  // The acceptance: the same ring values within 0.1 deg (the same triangles: to round-off).
  const auto& fm = pair(s, "fishnet", "macro");
  EXPECT_EQ(fm["azimuths_compared"], 360);
  EXPECT_LT(fm["max_abs_difference_deg"].get<double>(), 0.1);
  // The net's joints as a point cloud: the fit across each ray smooths the kink of |shear| on
  // the generators (45, 135, ... deg) by up to ~0.5 deg; elsewhere it follows the ring.
  const auto& fc = pair(s, "fishnet", "cloud");
  EXPECT_LT(fc["rms_difference_deg"].get<double>(), 0.1);
  EXPECT_LT(fc["max_abs_difference_deg"].get<double>(), 0.6);
  for (const char* file : {"comparison.csv", "pairs.csv", "comparison.md", "rings.csv",
                           "imported_macro.csv", "imported_cloud.csv", "log.txt"})
    EXPECT_TRUE(fs::exists(out / file)) << file;
  const auto rings = read_history(out / "rings.csv");
  EXPECT_EQ(rings.columns, (std::vector<std::string>{"azimuth_deg", "fishnet", "macro", "cloud"}));
  EXPECT_EQ(rings.rows.size(), 360u);
  if (s["figure"].is_null())  // no off-screen OpenGL here: said so, the rest written
    EXPECT_TRUE(s.contains("figure_error"));
  else
    EXPECT_TRUE(fs::exists(out / "figures/ring_shear_compared.png"));
  // A workflow folder gives the rings of its stages; the same net read twice is left out.
  const fs::path wf = fresh_dir("compare_workflow");
  fs::create_directories(wf);
  fs::copy(fish, wf / "fish", fs::copy_options::recursive);
  std::ofstream(wf / "summary.json")
      << R"({"stage": "workflow", "stages": [{"name": "fishnet", "kind": "kinematic_drape",
             "folder": "fish"}]})";
  const fs::path out2 = fresh_dir("compare_out_wf");
  r = run_cli({"compare", "wf=" + wf.string(), fish.string(), "-o", out2.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s2 = json::parse(slurp(out2 / "summary.json"));
  ASSERT_EQ(s2["sources"].size(), 1u) << r.output;
  EXPECT_EQ(s2["sources"][0]["label"], "wf/fishnet");
  EXPECT_NE(r.output.find("equals one already read; left out"), std::string::npos) << r.output;
  fs::remove_all(wf);
  fs::remove_all(out2);
  // A rerun into the same folder replaces it (the manifest), the output folder is no source.
  r = run_cli({"compare", fish.string(), "-o", out.string()});
  EXPECT_EQ(r.code, 0) << r.output;
  EXPECT_FALSE(fs::exists(out / "imported_macro.csv"));
  r = run_cli({"compare", fish.string(), "-o", fish.string()});
  EXPECT_EQ(r.code, 2) << r.output;
  fs::remove_all(fish);
  fs::remove_all(out);
  fs::remove(vtu);
}

TEST(CliCompare, MesoFrameVtuReadBackGivesTheRunsRing) {
  const fs::path run = fresh_dir("compare_meso"), out = fresh_dir("compare_meso_out");
  const fs::path toml = run.parent_path() / (run.filename().string() + ".toml");
  std::ofstream(toml) << "[case]\nname = \"ring_flat\"\n"
                      << kFlatBlanketBody << R"(
[time]
end_time = 2e-6
[output]
figures = false
frames = "vtu"
[[output.ring_shear]]
parts = ["ncf_ply1", "ncf_ply2"]
centre = [0.0, 0.03, -0.01]
axis = [1.0, 0.0, 0.0]
zero_direction = [0.0, 0.0, 1.0]
height = 0.03
)";
  auto r = run_cli({"-q", "run", toml.string(), "-o", run.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  fs::path last;
  for (const auto& e : fs::directory_iterator(run / "frames"))
    if (e.path().extension() == ".vtu" && e.path() > last) last = e.path();
  ASSERT_FALSE(last.empty());
  r = run_cli({"compare", "meso=" + run.string(), "frame=" + last.string(), "--ring-centre",
               "0,0.03,-0.01", "--ring-axis", "1,0,0", "--ring-zero-direction", "0,0,1",
               "--ring-height", "0.03", "-o", out.string()});
  ASSERT_EQ(r.code, 0) << r.output;
  const auto s = json::parse(slurp(out / "summary.json"));
  EXPECT_EQ(source(s, "meso")["kind"], "meso");
  EXPECT_EQ(source(s, "frame")["field_location"], "cell");
  const auto& p = pair(s, "meso", "frame");
  EXPECT_GT(p["azimuths_compared"].get<int>(), 100);  // the rays that meet the blanket
  EXPECT_EQ(p["azimuths_compared"], source(s, "meso")["ring_samples_hit"]);
  EXPECT_LT(p["max_abs_difference_deg"].get<double>(), 0.1);
  // Where the rays meet the plies: the same points.
  const auto a = read_history(run / "ring_shear.csv"), b = read_history(out / "imported_frame.csv");
  ASSERT_EQ(a.rows.size(), b.rows.size());
  for (std::size_t i = 0; i < a.rows.size(); ++i) {
    if (a.rows[i][a.column("hit")] < 0.5) continue;
    for (const char* c : {"x_m", "y_m", "z_m"})
      EXPECT_NEAR(a.rows[i][a.column(c)], b.rows[i][b.column(c)], 1e-9) << i << c;
  }
  fs::remove_all(run);
  fs::remove_all(out);
  fs::remove(toml);
}

TEST(CliCompareBadInput, ExitTwoWithOneLineNamingTheFile) {
  const fs::path out = fresh_dir("compare_bad"), dir = fresh_dir("compare_bad_inputs");
  fs::create_directories(dir);
  auto expect_bad = [&](const std::vector<std::string>& args, const std::string& file,
                        const std::string& why) {
    std::vector<std::string> all{"compare"};
    all.insert(all.end(), args.begin(), args.end());
    all.insert(all.end(), {"-o", out.string()});
    const auto r = run_cli(all);
    EXPECT_EQ(r.code, 2) << r.output;
    EXPECT_NE(r.output.find(file), std::string::npos) << r.output;
    EXPECT_NE(r.output.find(why), std::string::npos) << r.output;
    EXPECT_EQ(std::count(r.output.begin(), r.output.end(), '\n'), 1) << r.output;
    EXPECT_FALSE(fs::exists(out)) << "bad input must write no output folder";
  };
  const fs::path no_z = dir / "no_z.csv", far = dir / "far.csv", bad = dir / "bad.vtu";
  std::ofstream(no_z) << "x,y,shear_deg\n0.067,0,1\n";
  std::ofstream(far) << "x,y,z,shear_deg\n0.067,0,0.0,1\n0,0.067,0.0,2\n";  // all at z = 0
  std::ofstream(bad) << "<VTKFile type=\"UnstructuredGrid\"><Unstruc";
  expect_bad({no_z.string()}, no_z.string(), "missing column z");
  expect_bad({far.string()}, far.string(), "no azimuth of the ring");
  expect_bad({bad.string()}, bad.string(), "cannot be read as a VTK XML unstructured grid");
  expect_bad({(dir / "missing.vtu").string()}, "missing.vtu", "no such file");
  expect_bad({dir.string()}, dir.string(), "holds no ring_shear.csv");
  expect_bad({far.string(), "--ring-step", "0"}, "--ring-step", "out of range");
  fs::remove_all(dir);
}

}  // namespace
}  // namespace ncfsim::test
