#include "workflow/compare/ring_import.hpp"

#include <fmt/format.h>
#include <vtkCell.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkGenericCell.h>
#include <vtkIdList.h>
#include <vtkLogger.h>
#include <vtkNew.h>
#include <vtkOutputWindow.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkStringOutputWindow.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridReader.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <sstream>
#include <unordered_map>

#include "drape/kinematic_drape.hpp"
#include "fem/elements/element_kind.hpp"
#include "fem/errors.hpp"

namespace ncfsim::workflow {

namespace fs = std::filesystem;
using fem::V3;

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string lower(std::string s) {
  for (auto& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

std::string trim(const std::string& s) {
  std::size_t a = 0, b = s.size();
  while (a < b && (std::isspace(static_cast<unsigned char>(s[a])) || s[a] == '"')) ++a;
  while (b > a && (std::isspace(static_cast<unsigned char>(s[b - 1])) || s[b - 1] == '"')) --b;
  return s.substr(a, b - a);
}

std::string join(const std::vector<std::string>& v, const std::string& sep) {
  std::string s;
  for (const auto& x : v) s += (s.empty() ? "" : sep) + x;
  return s;
}

// The ring's frame: e1 the wale direction normal to the axis, e2 = axis x e1 (as ring_shear).
struct RingFrame {
  V3 e1, e2, origin;
  int n = 0;
  explicit RingFrame(const drape::RingSpec& r) {
    r.validate();
    e1 = normalized(r.zero_direction - dot(r.zero_direction, r.axis) * r.axis);
    e2 = cross(r.axis, e1);
    origin = r.centre + r.height * r.axis;
    n = static_cast<int>(std::lround(360.0 / r.step_deg));
  }
};

// The default search radius: 1.5 x the cloud's median spacing (a ray through a square grid of
// spacing a has about 7 points within 1.5 a), at most kMaxAutoTolerance (a sparse cloud is not
// "near" the ring at any distance).
constexpr double kMaxAutoTolerance = 0.01;  // m
double auto_tolerance(const std::vector<V3>& pts) {
  return std::min(1.5 * median_spacing(pts), kMaxAutoTolerance);
}

// Heights of the data above the ring's plane, for the message of a ring that meets nothing.
std::string height_span(const std::vector<V3>& pts, const drape::RingSpec& ring) {
  double lo = std::numeric_limits<double>::max(), hi = std::numeric_limits<double>::lowest();
  for (const auto& p : pts) {
    const double h = dot(p - ring.centre, ring.axis);
    lo = std::min(lo, h);
    hi = std::max(hi, h);
  }
  return pts.empty() ? std::string("no points")
                     : fmt::format(
                           "its points lie {:.4g} .. {:.4g} m above the reference plane "
                           "along the ring axis",
                           lo, hi);
}

void require_hits(const std::vector<drape::RingSample>& ring, const fs::path& file,
                  const std::vector<V3>& pts, const drape::RingSpec& spec, const std::string& how) {
  for (const auto& s : ring)
    if (s.hit) return;
  throw InputError(file.string(), "",
                   fmt::format("no azimuth of the ring (height {:.4g} m) meets the data ({}); {}",
                               spec.height, how, height_span(pts, spec)));
}

// The ring of a point cloud (a CSV, or a .vtu without surfaces): the search tolerance (given, or
// from the cloud's spacing), the ring, and at least one azimuth that meets the data.
void ring_of_cloud(ImportedRing& out, const std::vector<V3>& pts, const std::vector<double>& values,
                   const fs::path& file, const RingImportOptions& opt) {
  out.tolerance = opt.tolerance > 0 ? opt.tolerance : auto_tolerance(pts);
  if (!(out.tolerance > 0))
    throw InputError(
        file.string(), "",
        "fewer than two distinct points: no spacing to search the ring by (give --tolerance, m)");
  out.ring = ring_from_points(pts, values, opt.ring, out.tolerance);
  require_hits(out.ring, file, pts, opt.ring,
               fmt::format("no point within {:.3g} m of a ray", out.tolerance));
}

// ---------------------------------------------------------------------------------------------
// CSV

std::vector<std::string> split_csv(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream ss(line);
  for (std::string c; std::getline(ss, c, ',');) cells.push_back(trim(c));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

ImportedRing import_csv(const fs::path& file, const RingImportOptions& opt) {
  std::ifstream in(file);
  if (!in) throw InputError(file.string(), "", "cannot be read");
  std::string line;
  std::size_t line_no = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty() || line[0] == '#') continue;
    header = split_csv(line);
    break;
  }
  if (header.empty()) throw InputError(file.string(), "", "is empty (no header row)");
  auto find = [&](const std::vector<std::string>& names) -> long {
    for (const auto& n : names)
      for (std::size_t c = 0; c < header.size(); ++c)
        if (lower(header[c]) == lower(n)) return static_cast<long>(c);
    return -1;
  };
  const std::vector<std::string> shear_names =
      opt.field.empty() ? kShearNames : std::vector<std::string>{opt.field};
  const long cx = find(kCsvX), cy = find(kCsvY), cz = find(kCsvZ), cs = find(shear_names);
  std::vector<std::string> missing;
  if (cx < 0) missing.push_back("x (x | x_m)");
  if (cy < 0) missing.push_back("y (y | y_m)");
  if (cz < 0) missing.push_back("z (z | z_m)");
  if (cs < 0) missing.push_back("shear angle (" + join(shear_names, " | ") + ")");
  if (!missing.empty())
    throw InputError(
        file.string(), "",
        fmt::format("missing column{} {}; the header has: {} (columns x, y, z in m and "
                    "the shear angle in deg)",
                    missing.size() > 1 ? "s" : "", join(missing, ", "), join(header, ", ")));
  ImportedRing out;
  out.method = "points";
  out.location = "column";
  out.field = header[static_cast<std::size_t>(cs)];
  std::vector<V3> pts;
  std::vector<double> val;
  const std::size_t need =
      static_cast<std::size_t>(std::max({cx, cy, cz, cs})) + 1;  // cells a row must have
  while (std::getline(in, line)) {
    ++line_no;
    if (!line.empty() && line.back() == '\r') line.pop_back();
    if (trim(line).empty() || line[0] == '#') continue;
    const auto cells = split_csv(line);
    if (cells.size() < need)
      throw InputError(file.string(), "",
                       fmt::format("line {}: {} cells, the header names {}", line_no, cells.size(),
                                   header.size()));
    auto num = [&](long c, bool nan_ok) {
      const std::string& t = cells[static_cast<std::size_t>(c)];
      char* end = nullptr;
      const double v = std::strtod(t.c_str(), &end);
      if (t.empty() || end != t.c_str() + t.size() || (!nan_ok && !std::isfinite(v)))
        throw InputError(
            file.string(), "",
            fmt::format("line {}, column '{}': '{}' is not a {}number", line_no,
                        header[static_cast<std::size_t>(c)], t, nan_ok ? "" : "finite "));
      return v;
    };
    const double k = opt.length_scale;
    pts.push_back({k * num(cx, false), k * num(cy, false), k * num(cz, false)});
    // NaN: no value at that point (skipped); a signed shear (a macro code's, or ncfsim's own
    // shell field) counts by its magnitude, as the meso and kinematic rings measure it.
    val.push_back(std::abs(num(cs, true)));
  }
  if (pts.empty()) throw InputError(file.string(), "", "holds a header but no rows");
  if (std::none_of(val.begin(), val.end(), [](double v) { return std::isfinite(v); }))
    throw InputError(file.string(), "", "no finite shear angle in column '" + out.field + "'");
  out.points = pts.size();
  ring_of_cloud(out, pts, val, file, opt);
  return out;
}

// ---------------------------------------------------------------------------------------------
// .vtu

// Puts VTK's error and warning text into a string while a reader runs, instead of stderr (VTK
// 9 sends the text of its error macros both to its logger, stderr, and to the output window).
class CaptureVtkOutput {
 public:
  CaptureVtkOutput()
      : previous_(vtkOutputWindow::GetInstance()),
        verbosity_(vtkLogger::GetCurrentVerbosityCutoff()) {
    vtkOutputWindow::SetInstance(capture_);
    vtkLogger::SetStderrVerbosity(vtkLogger::VERBOSITY_OFF);
  }
  ~CaptureVtkOutput() {
    vtkLogger::SetStderrVerbosity(verbosity_);
    vtkOutputWindow::SetInstance(previous_);
  }
  CaptureVtkOutput(const CaptureVtkOutput&) = delete;
  CaptureVtkOutput& operator=(const CaptureVtkOutput&) = delete;
  // The first message VTK gave, on one line ("" when none).
  std::string first_message() const {
    std::stringstream ss(capture_->GetOutput());
    for (std::string l; std::getline(ss, l);) {
      const auto k = l.find("): ");
      if (k != std::string::npos && k + 3 < l.size()) return trim(l.substr(k + 3));
    }
    return trim(capture_->GetOutput());
  }

 private:
  vtkSmartPointer<vtkOutputWindow> previous_;
  vtkLogger::Verbosity verbosity_;
  vtkNew<vtkStringOutputWindow> capture_;
};

struct VtuField {
  vtkDataArray* shear = nullptr;  // one component
  vtkDataArray *fibre_a = nullptr, *fibre_b = nullptr;
  bool on_cells = false;
  std::string name;
};

vtkDataArray* find_array(vtkFieldData* data, const std::string& name) {
  for (int i = 0; i < data->GetNumberOfArrays(); ++i) {
    vtkDataArray* a = data->GetArray(i);
    if (a && a->GetName() && lower(a->GetName()) == lower(name)) return a;
  }
  return nullptr;
}

std::vector<std::string> array_names(vtkFieldData* data, const char* where) {
  std::vector<std::string> n;
  for (int i = 0; i < data->GetNumberOfArrays(); ++i)
    if (data->GetArray(i) && data->GetArray(i)->GetName())
      n.push_back(fmt::format("{} ({}, {} comp.)", data->GetArray(i)->GetName(), where,
                              data->GetArray(i)->GetNumberOfComponents()));
  return n;
}

VtuField find_field(vtkUnstructuredGrid* g, const fs::path& file, const RingImportOptions& opt) {
  VtuField f;
  const std::vector<std::string> names =
      opt.field.empty() ? kShearNames : std::vector<std::string>{opt.field};
  for (const auto& n : names)
    for (const bool cells : {false, true}) {
      vtkFieldData* d = cells ? static_cast<vtkFieldData*>(g->GetCellData())
                              : static_cast<vtkFieldData*>(g->GetPointData());
      if (vtkDataArray* a = find_array(d, n)) {
        if (a->GetNumberOfComponents() != 1)
          throw InputError(
              file.string(), opt.field.empty() ? "" : "--field",
              fmt::format("the {} field '{}' has {} components; a shear angle has 1",
                          cells ? "cell" : "point", a->GetName(), a->GetNumberOfComponents()));
        f.shear = a;
        f.on_cells = cells;
        f.name = a->GetName();
        return f;
      }
    }
  if (opt.field.empty())
    for (const auto& [na, nb] : kFibrePairs)
      for (const bool cells : {false, true}) {
        vtkFieldData* d = cells ? static_cast<vtkFieldData*>(g->GetCellData())
                                : static_cast<vtkFieldData*>(g->GetPointData());
        vtkDataArray *a = find_array(d, na), *b = find_array(d, nb);
        if (a && b && a->GetNumberOfComponents() == 3 && b->GetNumberOfComponents() == 3) {
          f.fibre_a = a;
          f.fibre_b = b;
          f.on_cells = cells;
          f.name = std::string(a->GetName()) + "/" + b->GetName();
          return f;
        }
      }
  auto have = array_names(g->GetPointData(), "point");
  const auto c = array_names(g->GetCellData(), "cell");
  have.insert(have.end(), c.begin(), c.end());
  std::vector<std::string> pairs;
  for (const auto& [na, nb] : kFibrePairs) pairs.push_back(na + " + " + nb);
  throw InputError(
      file.string(), opt.field.empty() ? "" : "--field",
      fmt::format("no shear-angle field: looked for a point or cell array named {}{}; the file "
                  "has {}",
                  join(names, " | "),
                  opt.field.empty() ? " or fibre directions " + join(pairs, " | ") : "",
                  have.empty() ? std::string("no arrays") : join(have, ", ")));
}

// Values of the field per point or per cell (the shear, or 90 deg minus the fibre lines' angle).
std::vector<double> field_values(const VtuField& f, vtkIdType n) {
  std::vector<double> v(static_cast<std::size_t>(n), kNaN);
  for (vtkIdType i = 0; i < n; ++i) {
    if (f.shear) {
      // by its magnitude, like the CSV's
      v[static_cast<std::size_t>(i)] = std::abs(f.shear->GetComponent(i, 0));
    } else {
      double a[3], b[3];
      f.fibre_a->GetTuple(i, a);
      f.fibre_b->GetTuple(i, b);
      const V3 fa{a[0], a[1], a[2]}, fb{b[0], b[1], b[2]};
      v[static_cast<std::size_t>(i)] =
          norm(fa) > 0 && norm(fb) > 0 ? drape::shear_angle_deg(fa, fb) : kNaN;
    }
  }
  return v;
}

using Tri = std::array<std::int32_t, 3>;

// Quadrilateral n0 n1 n2 n3 as two triangles, split as the meso measure splits hexahedron faces
// (drape::outer_face_triangles); a polygon as a fan from its first corner.
void add_polygon(const std::vector<std::int32_t>& p, std::vector<Tri>& tri) {
  for (std::size_t k = 1; k + 1 < p.size(); ++k) tri.push_back({p[0], p[k], p[k + 1]});
}

ImportedRing import_vtu(const fs::path& file, const RingImportOptions& opt) {
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  if (!fs::is_regular_file(file)) throw InputError(file.string(), "", "no such file");
  std::string why;
  {
    CaptureVtkOutput capture;
    if (!reader->CanReadFile(file.c_str()))
      throw InputError(
          file.string(), "",
          "cannot be read as a VTK XML unstructured grid (.vtu): " +
              (capture.first_message().empty() ? std::string("not a <VTKFile "
                                                             "type=\"UnstructuredGrid\">")
                                               : capture.first_message()));
    reader->SetFileName(file.c_str());
    reader->Update();
    why = capture.first_message();
  }
  vtkUnstructuredGrid* g = reader->GetOutput();
  if (reader->GetErrorCode() != 0 || !why.empty() || !g || g->GetNumberOfPoints() == 0)
    throw InputError(file.string(), "",
                     "cannot be read as a VTK XML unstructured grid (.vtu): " +
                         (why.empty() ? std::string("no points") : why));
  const VtuField f = find_field(g, file, opt);
  const vtkIdType n_points = g->GetNumberOfPoints(), n_cells = g->GetNumberOfCells();
  std::vector<V3> pts(static_cast<std::size_t>(n_points));
  for (vtkIdType i = 0; i < n_points; ++i) {
    double p[3];
    g->GetPoint(i, p);
    const double k = opt.length_scale;
    pts[static_cast<std::size_t>(i)] = {k * p[0], k * p[1], k * p[2]};
  }
  const std::vector<double> values = field_values(f, f.on_cells ? n_cells : n_points);

  ImportedRing out;
  out.field = f.name;
  out.location = f.on_cells ? "cell" : "point";
  out.points = pts.size();

  // The surface: 2D cells, and the faces of 3D cells that no other 3D cell shares. With a cell
  // field only the cells with a finite value take part (a meso frame: the plies' tows).
  std::vector<Tri> tri;
  std::map<std::vector<std::int32_t>, std::pair<int, std::vector<std::int32_t>>> faces;
  // Cell values summed at the points: of the surface's cells (2D, 3D), and of vertex cells (a
  // point cloud as vertices); lines (a meso frame's stitch bars) take no part.
  std::vector<double> sum(pts.size(), 0.0), vertex_sum(pts.size(), 0.0);
  std::vector<int> count(pts.size(), 0), vertex_count(pts.size(), 0);
  std::vector<std::int32_t> vertex_cells;  // cells of dimension 0
  vtkNew<vtkGenericCell> cell;
  for (vtkIdType c = 0; c < n_cells; ++c) {
    const double cv = f.on_cells ? values[static_cast<std::size_t>(c)] : 0.0;
    if (f.on_cells && !std::isfinite(cv)) continue;
    g->GetCell(c, cell);
    const int dim = cell->GetCellDimension();
    std::vector<std::int32_t> ids(static_cast<std::size_t>(cell->GetNumberOfPoints()));
    for (std::size_t k = 0; k < ids.size(); ++k)
      ids[k] = static_cast<std::int32_t>(cell->GetPointId(static_cast<vtkIdType>(k)));
    if (f.on_cells && dim != 1)
      for (auto id : ids) {
        const auto i = static_cast<std::size_t>(id);
        (dim == 0 ? vertex_sum : sum)[i] += cv;
        ++(dim == 0 ? vertex_count : count)[i];
      }
    if (dim == 0) vertex_cells.push_back(static_cast<std::int32_t>(c));
    if (dim == 2) {
      const int type = cell->GetCellType();
      if (type == VTK_PIXEL && ids.size() == 4) {
        add_polygon({ids[0], ids[1], ids[3], ids[2]}, tri);
      } else if (type == VTK_TRIANGLE_STRIP) {
        for (std::size_t k = 0; k + 2 < ids.size(); ++k)
          tri.push_back(k % 2 == 0 ? Tri{ids[k], ids[k + 1], ids[k + 2]}
                                   : Tri{ids[k + 1], ids[k], ids[k + 2]});
      } else {
        // Corner nodes of a (possibly quadratic) polygon: the cell's edges' first points.
        std::vector<std::int32_t> corners;
        for (int e = 0; e < cell->GetNumberOfEdges(); ++e)
          corners.push_back(static_cast<std::int32_t>(cell->GetEdge(e)->GetPointId(0)));
        add_polygon(corners, tri);
      }
    } else if (dim == 3) {
      std::vector<std::vector<std::int32_t>> cf;
      if (cell->GetCellType() == VTK_HEXAHEDRON) {
        for (const auto& face : fem::kHex8Faces) {
          const auto& hf = face.corner;
          cf.push_back({ids[static_cast<std::size_t>(hf[0])], ids[static_cast<std::size_t>(hf[1])],
                        ids[static_cast<std::size_t>(hf[2])],
                        ids[static_cast<std::size_t>(hf[3])]});
        }
      } else {
        for (int k = 0; k < cell->GetNumberOfFaces(); ++k) {
          vtkCell* face = cell->GetFace(k);
          std::vector<std::int32_t> fp;
          for (int e = 0; e < face->GetNumberOfEdges(); ++e)
            fp.push_back(static_cast<std::int32_t>(face->GetEdge(e)->GetPointId(0)));
          cf.push_back(std::move(fp));
        }
      }
      for (auto& fp : cf) {
        auto key = fp;
        std::sort(key.begin(), key.end());
        auto [it, fresh] = faces.try_emplace(std::move(key), 0, fp);
        ++it->second.first;
      }
    }
  }
  for (const auto& [key, fc] : faces)
    if (fc.first == 1) add_polygon(fc.second, tri);

  // Values at the points: the point field, or the mean of the cells' values at each point (the
  // surface's cells; without a surface, the vertex cells').
  std::vector<double> node_value = f.on_cells ? std::vector<double>(pts.size(), kNaN) : values;
  if (f.on_cells) {
    if (tri.empty()) sum.swap(vertex_sum), count.swap(vertex_count);
    for (std::size_t i = 0; i < pts.size(); ++i)
      if (count[i] > 0) node_value[i] = sum[i] / count[i];
  }

  if (!tri.empty()) {
    out.method = "surface";
    out.triangles = tri.size();
    out.ring = drape::ring_shear(pts, tri, node_value, opt.ring);
    for (auto& s : out.ring)  // a triangle without a value (NaN at a corner) does not count
      if (s.hit && !std::isfinite(s.shear_deg)) s.hit = false, s.shear_deg = 0;
    require_hits(out.ring, file, pts, opt.ring,
                 fmt::format("{} triangles of its surface{}", tri.size(),
                             f.on_cells ? " (cells with a finite value)" : ""));
    return out;
  }
  // No surface: the points as a cloud (a cell field only on vertex cells).
  if (f.on_cells && vertex_cells.empty())
    throw InputError(file.string(), "",
                     "the cell field '" + f.name +
                         "' lies on cells that are neither surfaces, volumes nor vertices");
  if (std::none_of(node_value.begin(), node_value.end(), [](double v) { return std::isfinite(v); }))
    throw InputError(file.string(), "", "no finite value in the field '" + f.name + "'");
  out.method = "points";
  ring_of_cloud(out, pts, node_value, file, opt);
  return out;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

double median_spacing(const std::vector<V3>& points) {
  const std::size_t n = points.size();
  if (n < 2) return 0;
  V3 lo = points[0], hi = points[0];
  for (const auto& p : points) {
    lo = {std::min(lo.x, p.x), std::min(lo.y, p.y), std::min(lo.z, p.z)};
    hi = {std::max(hi.x, p.x), std::max(hi.y, p.y), std::max(hi.z, p.z)};
  }
  const double diag = norm(hi - lo);
  if (!(diag > 0)) return 0;
  // Cells of about one spacing of a surface cloud (n points over an area ~ diag^2).
  const double h = std::max(diag / std::sqrt(static_cast<double>(n)), diag * 1e-6);
  auto key = [&](const V3& p) {
    return std::array<long, 3>{static_cast<long>(std::floor((p.x - lo.x) / h)),
                               static_cast<long>(std::floor((p.y - lo.y) / h)),
                               static_cast<long>(std::floor((p.z - lo.z) / h))};
  };
  auto hash = [](const std::array<long, 3>& k) {
    return static_cast<std::size_t>(k[0] * 73856093L ^ k[1] * 19349663L ^ k[2] * 83492791L);
  };
  std::unordered_map<std::array<long, 3>, std::vector<std::size_t>, decltype(hash)> grid(n, hash);
  for (std::size_t i = 0; i < n; ++i) grid[key(points[i])].push_back(i);
  const std::size_t stride = std::max<std::size_t>(1, n / 4000);
  std::vector<double> nearest;
  for (std::size_t i = 0; i < n; i += stride) {
    const auto k = key(points[i]);
    double best = std::numeric_limits<double>::max();
    for (long r = 1; r <= 64; ++r) {  // shells of cells until the nearest found is certain
      for (long a = -r; a <= r; ++a)
        for (long b = -r; b <= r; ++b)
          for (long c = -r; c <= r; ++c) {
            if (std::max({std::abs(a), std::abs(b), std::abs(c)}) < r - 1) continue;
            const auto it = grid.find({k[0] + a, k[1] + b, k[2] + c});
            if (it == grid.end()) continue;
            for (auto j : it->second) {
              const double d = norm(points[j] - points[i]);
              if (d > 0) best = std::min(best, d);
            }
          }
      if (best <= (r - 1) * h) break;  // nothing in a farther shell can be nearer
    }
    if (best < std::numeric_limits<double>::max()) nearest.push_back(best);
  }
  if (nearest.empty()) return 0;
  std::nth_element(nearest.begin(), nearest.begin() + static_cast<long>(nearest.size() / 2),
                   nearest.end());
  return nearest[nearest.size() / 2];
}

std::vector<drape::RingSample> ring_from_points(const std::vector<V3>& points,
                                                const std::vector<double>& values,
                                                const drape::RingSpec& ring, double tol) {
  const RingFrame fr(ring);
  if (!(tol > 0)) throw std::invalid_argument("ring_from_points: tolerance must be > 0");
  if (values.size() != points.size())
    throw std::invalid_argument("ring_from_points: one value per point expected");
  // Only points within tol of the ring's plane can be within tol of a ray.
  std::vector<std::size_t> band;
  for (std::size_t i = 0; i < points.size(); ++i)
    if (std::isfinite(values[i]) && std::abs(dot(points[i] - fr.origin, ring.axis)) <= tol)
      band.push_back(i);
  std::vector<drape::RingSample> out(static_cast<std::size_t>(fr.n));
  struct Near {
    double s, u, w, d, v;
  };
  std::vector<Near> near;
  for (int k = 0; k < fr.n; ++k) {
    drape::RingSample& smp = out[static_cast<std::size_t>(k)];
    smp.azimuth_deg = k * ring.step_deg;
    const double phi = smp.azimuth_deg * kPi / 180.0;
    const V3 d = std::cos(phi) * fr.e1 + std::sin(phi) * fr.e2;
    const V3 t = cross(ring.axis, d);  // across the ray, in the ring's plane
    near.clear();
    double s_min = std::numeric_limits<double>::max();
    for (auto i : band) {
      const V3 q = points[i] - fr.origin;
      const double s = dot(q, d);
      if (s <= 0) continue;
      const V3 perp = q - s * d;
      const double dist = norm(perp);
      if (dist > tol) continue;
      near.push_back({s, dot(perp, t), dot(perp, ring.axis), dist, values[i]});
      s_min = std::min(s_min, s);
    }
    // The sheet nearest the axis (the ray's first hit), then a weighted linear fit across the ray.
    std::erase_if(near, [&](const Near& p) { return p.s > s_min + tol; });
    if (near.empty()) continue;
    double W = 0, Ws = 0, Wv = 0;
    double A[3][3] = {}, b[3] = {};
    for (const auto& p : near) {
      const double r = p.d / tol, w = std::max((1 - r * r) * (1 - r * r), 1e-6);
      const double phi3[3] = {1.0, p.u / tol, p.w / tol};
      for (int i = 0; i < 3; ++i) {
        for (int j = 0; j < 3; ++j) A[i][j] += w * phi3[i] * phi3[j];
        b[i] += w * phi3[i] * p.v;
      }
      W += w;
      Ws += w * p.s;
      Wv += w * p.v;
    }
    const double det = A[0][0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                       A[0][1] * (A[1][0] * A[2][2] - A[1][2] * A[2][0]) +
                       A[0][2] * (A[1][0] * A[2][1] - A[1][1] * A[2][0]);
    // Points spread across the ray in both directions (the determinant of the scaled moment
    // matrix against its diagonal): the fit's value at the ray; otherwise the weighted mean.
    const bool spread = near.size() >= 3 && det > 1e-6 * A[0][0] * A[1][1] * A[2][2];
    double v = Wv / W;
    if (spread) {
      const double d0 = b[0] * (A[1][1] * A[2][2] - A[1][2] * A[2][1]) -
                        A[0][1] * (b[1] * A[2][2] - A[1][2] * b[2]) +
                        A[0][2] * (b[1] * A[2][1] - A[1][1] * b[2]);
      v = d0 / det;  // Cramer's rule, the constant term c0
      // No extrapolation past the neighbours' values (a fit on a lopsided neighbourhood).
      double lo = near[0].v, hi = near[0].v;
      for (const auto& p : near) lo = std::min(lo, p.v), hi = std::max(hi, p.v);
      v = std::isfinite(v) ? std::clamp(v, lo, hi) : Wv / W;
    }
    smp.hit = true;
    smp.shear_deg = v;
    smp.point = fr.origin + (Ws / W) * d;
  }
  return out;
}

ImportedRing import_ring(const fs::path& file, const RingImportOptions& opt) {
  if (!(opt.length_scale > 0) || !std::isfinite(opt.length_scale))
    throw InputError::out_of_range(file.string(), "--length-scale", opt.length_scale,
                                   Range::positive());
  const std::string ext = lower(file.extension().string());
  if (ext == ".vtu") return import_vtu(file, opt);
  if (ext == ".csv") {
    if (!fs::is_regular_file(file)) throw InputError(file.string(), "", "no such file");
    return import_csv(file, opt);
  }
  throw InputError(file.string(), "",
                   "'" + file.extension().string() +
                       "' is not an importable result; allowed: .vtu (VTK XML unstructured grid), "
                       ".csv (x, y, z, shear angle)");
}

}  // namespace ncfsim::workflow
