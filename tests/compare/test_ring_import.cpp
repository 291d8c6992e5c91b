// Importing a macro drape result onto the ring (workflow/compare/ring_import.hpp).
//
// Analytic field used throughout: on the 156 mm hemisphere (radius R = 78 mm about the origin,
// axis z, the ring plane z = 0), the shear angle gamma(phi) = a + b cos(2 phi) with phi the
// azimuth from x. The ring at h = 40 mm meets the sphere at r = sqrt(R^2 - h^2) = 66.96 mm. The
// quadrant maxima (90 deg sectors centred on 0, 90, 180, 270 deg, boundaries counted in both) are
// for b > 0: q1 = q3 = a + b (at 0 and 180 deg), q2 = q4 = a (at the boundaries 45, 135, 225,
// 315 deg, where cos(2 phi) = 0).
#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "drape/fabric_measures.hpp"
#include "drape/ring_measure.hpp"
#include "fem/errors.hpp"
#include "workflow/compare/compare.hpp"
#include "workflow/compare/ring_import.hpp"

namespace fs = std::filesystem;
using namespace ncfsim;
using fem::V3;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kR = 0.078, kA = 10.0, kB = 8.0;

double gamma_at(double phi) { return kA + kB * std::cos(2 * phi); }
double gamma_at(const V3& p) { return gamma_at(std::atan2(p.y, p.x)); }

fs::path temp(const std::string& name) {
  return fs::temp_directory_path() / (std::to_string(::getpid()) + "_" + name);
}

// Point of the sphere of radius r at polar angle t from +z and azimuth p.
V3 sphere(double r, double t, double p) {
  return {r * std::sin(t) * std::cos(p), r * std::sin(t) * std::sin(p), r * std::cos(t)};
}

// A structured latitude-longitude grid on the sphere from the polar angle t0 to t1: (nt + 1) rows
// of np points (closed in azimuth), quadrilaterals n0 n1 n2 n3 counter-clockwise from outside.
struct Grid {
  std::vector<V3> points;
  std::vector<std::array<std::int32_t, 4>> quads;
};
Grid lat_long(double r, double t0, double t1, int nt, int np) {
  Grid g;
  for (int i = 0; i <= nt; ++i)
    for (int j = 0; j < np; ++j)
      g.points.push_back(sphere(r, t0 + (t1 - t0) * i / nt, 2 * kPi * (j + 0.37) / np));
  auto id = [&](int i, int j) { return static_cast<std::int32_t>(i * np + (j % np)); };
  for (int i = 0; i < nt; ++i)
    for (int j = 0; j < np; ++j)
      g.quads.push_back({id(i, j), id(i, j + 1), id(i + 1, j + 1), id(i + 1, j)});
  return g;
}

// The dome as a cloud of about 1 mm spacing with gamma, and an outer sheet 5 mm further out with
// 99 deg (the rays meet it second: it must not count).
std::pair<std::vector<V3>, std::vector<double>> dome_cloud() {
  std::vector<V3> pts;
  std::vector<double> v;
  const double h = 1e-3;
  for (double t = 0.2; t < 1.2; t += h / kR) {
    const int np = static_cast<int>(2 * kPi * kR * std::sin(t) / h);
    for (int j = 0; j < np; ++j) {
      const double p = 2 * kPi * (j + 0.5 * t / (h / kR)) / np;
      pts.push_back(sphere(kR, t, p));
      v.push_back(gamma_at(p));
      pts.push_back(sphere(kR + 5e-3, t, p));
      v.push_back(99.0);
    }
  }
  return {pts, v};
}

drape::RingSpec ring40() {
  drape::RingSpec r;
  r.height = 0.04;
  return r;
}

struct VtuArray {
  std::string name;
  bool on_cells;
  int components;
  std::vector<double> values;
};

void write_vtu(const fs::path& file, const std::vector<V3>& pts,
               const std::vector<std::pair<int, std::vector<std::int32_t>>>& cells,
               const std::vector<VtuArray>& arrays) {
  vtkNew<vtkUnstructuredGrid> g;
  vtkNew<vtkPoints> p;
  p->SetDataTypeToDouble();
  for (const auto& x : pts) p->InsertNextPoint(x.x, x.y, x.z);
  g->SetPoints(p);
  for (const auto& [type, ids] : cells) {
    std::vector<vtkIdType> v(ids.begin(), ids.end());
    g->InsertNextCell(type, static_cast<vtkIdType>(v.size()), v.data());
  }
  for (const auto& a : arrays) {
    vtkNew<vtkDoubleArray> d;
    d->SetName(a.name.c_str());
    d->SetNumberOfComponents(a.components);
    d->SetNumberOfTuples(static_cast<vtkIdType>(a.values.size() / a.components));
    for (std::size_t i = 0; i < a.values.size(); ++i)
      d->SetValue(static_cast<vtkIdType>(i), a.values[i]);
    if (a.on_cells)
      g->GetCellData()->AddArray(d);
    else
      g->GetPointData()->AddArray(d);
  }
  vtkNew<vtkXMLUnstructuredGridWriter> w;
  w->SetFileName(file.c_str());
  w->SetInputData(g);
  ASSERT_EQ(w->Write(), 1) << file;
}

std::vector<std::array<std::int32_t, 3>> split(const std::vector<std::array<std::int32_t, 4>>& q) {
  std::vector<std::array<std::int32_t, 3>> t;
  for (const auto& f : q) {
    t.push_back({f[0], f[1], f[2]});
    t.push_back({f[0], f[2], f[3]});
  }
  return t;
}

std::string error_of(const fs::path& file, const workflow::RingImportOptions& opt) {
  try {
    workflow::import_ring(file, opt);
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

}  // namespace

// A CSV point cloud (1 mm spacing) of the dome with gamma = a + b cos(2 phi), and an outer sheet
// 5 mm further out with 99 deg that the rays meet second (it must not count): every azimuth reads
// gamma within 0.05 deg and the quadrant maxima are a + b, a, a + b, a within 0.05 deg.
TEST(RingImportVerification, Cos2FieldOnADomeCloudGivesItsQuadrantMaxima) {
  const fs::path csv = temp("dome_cloud.csv");
  {
    std::ofstream out(csv);
    out << "# analytic dome\nX,Y,Z,shear_angle_deg\n";
    const auto [pts, v] = dome_cloud();
    for (std::size_t i = 0; i < pts.size(); ++i)
      out << pts[i].x << "," << pts[i].y << "," << pts[i].z << "," << v[i] << "\n";
  }
  workflow::RingImportOptions opt;
  opt.ring = ring40();
  const auto r = workflow::import_ring(csv, opt);
  EXPECT_EQ(r.method, "points");
  EXPECT_EQ(r.field, "shear_angle_deg");
  EXPECT_NEAR(r.tolerance, 1.5e-3, 0.5e-3);  // 1.5 x the ~1 mm spacing
  ASSERT_EQ(r.ring.size(), 360u);
  const double r_ring = std::sqrt(kR * kR - 0.04 * 0.04);
  for (const auto& s : r.ring) {
    ASSERT_TRUE(s.hit) << s.azimuth_deg;
    EXPECT_NEAR(s.shear_deg, gamma_at(s.azimuth_deg * kPi / 180), 0.05) << s.azimuth_deg;
    EXPECT_NEAR(std::hypot(s.point.x, s.point.y), r_ring, 1e-3) << s.azimuth_deg;
    EXPECT_NEAR(s.point.z, 0.04, 1e-12);
  }
  const auto q = drape::quadrant_maxima(r.ring);
  EXPECT_NEAR(q.max_shear_deg[0], kA + kB, 0.05);
  EXPECT_NEAR(q.max_shear_deg[1], kA, 0.05);
  EXPECT_NEAR(q.max_shear_deg[2], kA + kB, 0.05);
  EXPECT_NEAR(q.max_shear_deg[3], kA, 0.05);
  fs::remove(csv);
}

// The same cloud as a .vtu of vertex cells in mm (--length-scale 1e-3) with gamma as a cell
// field: read as a cloud, the same ring (within 0.05 deg of gamma).
TEST(RingImportVerification, VertexVtuInMillimetresIsReadAsACloud) {
  auto [pts, v] = dome_cloud();
  for (auto& p : pts) p = 1e3 * p;
  std::vector<std::pair<int, std::vector<std::int32_t>>> cells;
  for (std::size_t i = 0; i < pts.size(); ++i)
    cells.push_back({VTK_VERTEX, {static_cast<std::int32_t>(i)}});
  const fs::path vtu = temp("dome_vertices.vtu");
  write_vtu(vtu, pts, cells, {{"shear", true, 1, v}});
  workflow::RingImportOptions opt;
  opt.ring = ring40();
  opt.length_scale = 1e-3;
  const auto r = workflow::import_ring(vtu, opt);
  EXPECT_EQ(r.method, "points");
  EXPECT_EQ(r.location, "cell");
  for (const auto& s : r.ring) {
    ASSERT_TRUE(s.hit);
    EXPECT_NEAR(s.shear_deg, gamma_at(s.azimuth_deg * kPi / 180), 0.05) << s.azimuth_deg;
  }
  fs::remove(vtu);
}

// A quadrilateral shell mesh of the dome in a .vtu with gamma as a point field: the import is the
// ring measure itself (drape::ring_shear) on the quadrilaterals split n0 n1 n2 / n0 n2 n3, to
// round-off; against the analytic field within the linear interpolation's error on 2 mm cells
// (b (2 dphi)^2 / 8 ~ 0.01 deg, bounded here by 0.05 deg).
TEST(RingImportVerification, ShellVtuWithAPointFieldIsTheRingMeasureOnItsTriangles) {
  const Grid g = lat_long(kR, 0.3, 1.3, 40, 210);
  std::vector<double> v;
  for (const auto& p : g.points) v.push_back(gamma_at(p));
  std::vector<std::pair<int, std::vector<std::int32_t>>> cells;
  for (const auto& q : g.quads) cells.push_back({VTK_QUAD, {q.begin(), q.end()}});
  const fs::path vtu = temp("dome_shell.vtu");
  write_vtu(vtu, g.points, cells, {{"shear_deg", false, 1, v}});
  workflow::RingImportOptions opt;
  opt.ring = ring40();
  const auto r = workflow::import_ring(vtu, opt);
  EXPECT_EQ(r.method, "surface");
  EXPECT_EQ(r.location, "point");
  EXPECT_EQ(r.triangles, 2 * g.quads.size());
  const auto expect = drape::ring_shear(g.points, split(g.quads), v, opt.ring);
  ASSERT_EQ(r.ring.size(), expect.size());
  for (std::size_t k = 0; k < expect.size(); ++k) {
    ASSERT_TRUE(r.ring[k].hit);
    EXPECT_NEAR(r.ring[k].shear_deg, expect[k].shear_deg, 1e-9);
    EXPECT_NEAR(r.ring[k].shear_deg, gamma_at(r.ring[k].azimuth_deg * kPi / 180), 0.05);
  }
  fs::remove(vtu);
}

// Two layers of hexahedra on the dome (a meso frame's plies) with gamma as a cell field, and a
// third layer with NaN (a part without the field: not on the surface): the import is the meso
// ring measure's own chain (drape::outer_face_triangles of the cells with a value,
// drape::element_to_node_mean, drape::ring_shear) to round-off.
TEST(RingImport, HexCellFieldReadsAsTheMesoMeasure) {
  const int nt = 30, np = 160;
  std::vector<V3> pts;
  for (int layer = 0; layer <= 3; ++layer) {
    const Grid g = lat_long(kR + 0.5e-3 * layer, 0.35, 1.25, nt, np);
    pts.insert(pts.end(), g.points.begin(), g.points.end());
  }
  const Grid g0 = lat_long(kR, 0.35, 1.25, nt, np);
  const auto per_layer = static_cast<std::int32_t>(g0.points.size());
  std::vector<std::array<std::int32_t, 8>> conn;
  std::vector<double> cv;
  std::vector<std::pair<int, std::vector<std::int32_t>>> cells;
  for (int layer = 0; layer < 3; ++layer)
    for (const auto& q : g0.quads) {
      std::array<std::int32_t, 8> h{};
      for (int k = 0; k < 4; ++k) {
        h[static_cast<std::size_t>(k)] = q[static_cast<std::size_t>(k)] + layer * per_layer;
        h[static_cast<std::size_t>(k + 4)] =
            q[static_cast<std::size_t>(k)] + (layer + 1) * per_layer;
      }
      V3 c{};
      for (auto n : h) c += 0.125 * pts[static_cast<std::size_t>(n)];
      conn.push_back(h);
      cv.push_back(layer < 2 ? gamma_at(c) : std::nan(""));
      cells.push_back({VTK_HEXAHEDRON, {h.begin(), h.end()}});
    }
  // A line cell (a stitch bar) with a value at two surface nodes: lines take no part.
  std::size_t at_ring = 0;  // a hexahedron of the inner layer that the ring's plane cuts
  while (!(pts[static_cast<std::size_t>(conn[at_ring][0])].z > 0.04 &&
           pts[static_cast<std::size_t>(conn[at_ring][3])].z < 0.04))
    ++at_ring;
  cells.push_back({VTK_LINE, {conn[at_ring][0], conn[at_ring][3]}});
  cv.push_back(1000.0);
  const fs::path vtu = temp("dome_hex.vtu");
  write_vtu(vtu, pts, cells, {{"shear_angle_deg", true, 1, cv}});
  cv.pop_back();
  workflow::RingImportOptions opt;
  opt.ring = ring40();
  const auto r = workflow::import_ring(vtu, opt);
  EXPECT_EQ(r.location, "cell");
  std::vector<std::int32_t> plies;
  for (std::size_t e = 0; e < conn.size(); ++e)
    if (std::isfinite(cv[e])) plies.push_back(static_cast<std::int32_t>(e));
  const auto node = drape::element_to_node_mean(conn, plies, cv, pts.size());
  const auto expect =
      drape::ring_shear(pts, drape::outer_face_triangles(conn, plies), node, opt.ring);
  ASSERT_EQ(r.ring.size(), expect.size());
  for (std::size_t k = 0; k < expect.size(); ++k) {
    ASSERT_EQ(r.ring[k].hit, expect[k].hit) << k;
    EXPECT_NEAR(r.ring[k].shear_deg, expect[k].shear_deg, 1e-9) << k;
    EXPECT_NEAR(norm(r.ring[k].point - expect[k].point), 0.0, 1e-12) << k;
  }
  fs::remove(vtu);
}

// Two fibre directions per cell at 90 deg - gamma to each other: the import reads gamma
// (90 deg minus the angle between the fibre lines, drape::shear_angle_deg); a ring cell's value
// is the mean of the cells round its corners, so within the cells' variation (0.3 deg here).
TEST(RingImport, FibreDirectionsGiveTheShearAngle) {
  const Grid g = lat_long(kR, 0.3, 1.3, 40, 240);
  std::vector<double> f1, f2;
  std::vector<std::pair<int, std::vector<std::int32_t>>> cells;
  for (const auto& q : g.quads) {
    cells.push_back({VTK_QUAD, {q.begin(), q.end()}});
    V3 c{};
    for (auto n : q) c += 0.25 * g.points[static_cast<std::size_t>(n)];
    const double gm = gamma_at(c) * kPi / 180, phi = std::atan2(c.y, c.x);
    // In the tangent plane: e_phi and the meridian; fibres at +-(45 - gamma/2) deg from e_phi.
    const V3 ep{-std::sin(phi), std::cos(phi), 0}, em = normalized(cross(ep, c));
    const double half = kPi / 4 - gm / 2;
    const V3 a = std::cos(half) * ep + std::sin(half) * em,
             b = std::cos(half) * ep - std::sin(half) * em;
    f1.insert(f1.end(), {a.x, a.y, a.z});
    f2.insert(f2.end(), {b.x, b.y, b.z});
  }
  const fs::path vtu = temp("dome_fibres.vtu");
  write_vtu(vtu, g.points, cells,
            {{"fibre_direction_1", true, 3, f1}, {"fibre_direction_2", true, 3, f2}});
  workflow::RingImportOptions opt;
  opt.ring = ring40();
  const auto r = workflow::import_ring(vtu, opt);
  EXPECT_EQ(r.field, "fibre_direction_1/fibre_direction_2");
  for (const auto& s : r.ring) {
    ASSERT_TRUE(s.hit);
    EXPECT_NEAR(s.shear_deg, gamma_at(s.azimuth_deg * kPi / 180), 0.3) << s.azimuth_deg;
  }
  fs::remove(vtu);
}

// The pair differences: a - b = 1 + 2 cos(phi) at phi = 0, 1, ..., 359 deg except 90 deg (b has
// no hit there): sum (a - b) = 360 - 1, sum (a - b)^2 = 360 + 4 * 180 - 1 (sum cos = 0,
// sum cos^2 = 180), so RMS = sqrt(1079 / 359), mean = 1, largest 3 at phi = 0.
TEST(RingImport, PairDifferenceOfTwoRings) {
  std::vector<drape::RingSample> a(360), b(360);
  for (int k = 0; k < 360; ++k) {
    a[static_cast<std::size_t>(k)] = {1.0 * k, true, 5 + 1.0 + 2.0 * std::cos(k * kPi / 180), {}};
    b[static_cast<std::size_t>(k)] = {1.0 * k, true, 5.0, {}};
  }
  b[90].hit = false;  // compared only where both hit
  const auto d = workflow::ring_difference(a, b);
  EXPECT_EQ(d.azimuths, 359);
  EXPECT_NEAR(d.rms_deg, std::sqrt(1079.0 / 359.0), 1e-12);
  EXPECT_NEAR(d.mean_deg, 1.0, 1e-12);
  EXPECT_NEAR(d.max_abs_deg, 3.0, 1e-12);
  EXPECT_EQ(d.max_at_azimuth_deg, 0.0);
}

// A macro drape's folder (ring_shear.csv column macro_shear_deg, summary.json
// macro_max_shear_deg_q1..q4) reads as a macro source with its summary keys beside.
TEST(RingImport, MacroRunFolderReadsAsMacro) {
  const fs::path dir = temp("macro_run");
  fs::create_directories(dir);
  std::string csv = "azimuth_deg,macro_shear_deg,hit,x_m,y_m,z_m\n";
  for (int k = 0; k < 360; ++k)
    csv += std::to_string(k) + "," + std::to_string(gamma_at(k * kPi / 180)) + ",1,0,0,0.04\n";
  std::ofstream(dir / "ring_shear.csv") << csv;
  std::ofstream(dir / "summary.json") << R"({"stage": "engine", "macro_max_shear_deg_q1": 18.0})";
  const auto src = workflow::read_run_folder(dir, "macro");
  ASSERT_EQ(src.size(), 1u);
  EXPECT_EQ(src[0].kind, "macro");
  EXPECT_EQ(src[0].column, "macro_shear_deg");
  EXPECT_EQ(src[0].summary_maxima["macro_max_shear_deg_q1"], 18.0);
  EXPECT_NEAR(drape::quadrant_maxima(src[0].ring).max_shear_deg[0], kA + kB, 1e-5);
  fs::remove_all(dir);
}

TEST(RingImportBadInput, EveryBadFileNamesItselfAndWhy) {
  workflow::RingImportOptions opt;
  opt.ring = ring40();
  const fs::path csv = temp("no_z.csv");
  std::ofstream(csv) << "x,y,shear_deg\n0.05,0,1\n";
  auto e = error_of(csv, opt);
  EXPECT_NE(e.find(csv.string()), std::string::npos) << e;
  EXPECT_NE(e.find("missing column z"), std::string::npos) << e;
  std::ofstream(csv) << "x,y,z,angle\n0.05,0,0.04,1\n";  // no shear column by an accepted name
  e = error_of(csv, opt);
  EXPECT_NE(e.find("shear angle (shear_angle_deg | shear_deg"), std::string::npos) << e;
  std::ofstream(csv) << "x,y,z,shear_deg\n0.05,0,0.0,1\n0.06,0,0.0,1\n";  // far below the ring
  e = error_of(csv, opt);
  EXPECT_NE(e.find("no azimuth of the ring"), std::string::npos) << e;
  opt.length_scale = 0;
  e = error_of(csv, opt);
  EXPECT_NE(e.find("--length-scale"), std::string::npos) << e;
  opt.length_scale = 1;
  std::ofstream(csv) << "x,y,z,shear_deg\n0.05,0,abc,1\n";
  e = error_of(csv, opt);
  EXPECT_NE(e.find("line 2"), std::string::npos) << e;
  const fs::path vtu = temp("garbage.vtu");
  std::ofstream(vtu) << "<VTKFile type=\"UnstructuredGrid\" version=\"0.1\">\n<Unstr";
  e = error_of(vtu, opt);
  EXPECT_NE(e.find(vtu.string() + ": cannot be read as a VTK XML unstructured grid"),
            std::string::npos)
      << e;
  std::ofstream(vtu) << "not xml at all";
  e = error_of(vtu, opt);
  EXPECT_NE(e.find("cannot be read"), std::string::npos) << e;
  write_vtu(vtu, {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}}, {{VTK_TRIANGLE, {0, 1, 2}}},
            {{"thickness", false, 1, {1, 1, 1}}});
  e = error_of(vtu, opt);
  EXPECT_NE(e.find("no shear-angle field"), std::string::npos) << e;
  EXPECT_NE(e.find("thickness (point, 1 comp.)"), std::string::npos) << e;
  EXPECT_NE(error_of(temp("result.txt"), opt).find("not an importable result"), std::string::npos);
  fs::remove(csv);
  fs::remove(vtu);
}
