// Results writers: XDMF/HDF5 and VTU series are read back through HDF5 and VTK.
#include <gtest/gtest.h>
#include <hdf5.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDataArray.h>
#include <vtkIdList.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkSmartPointer.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLDataElement.h>
#include <vtkXMLUnstructuredGridReader.h>
#include <vtkXMLUtilities.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "fem/io/result_reader.hpp"
#include "fem/io/result_writers.hpp"
#include "fem/io/stage_handoff.hpp"

namespace fs = std::filesystem;
using namespace ncfsim::fem::io;

namespace {

// --- Test data
// --------------------------------------------------------------------------------------

constexpr int NX = 3, NY = 2, NZ = 2;  // hexahedra per direction
constexpr int PX = NX + 1, PY = NY + 1, PZ = NZ + 1;
constexpr std::size_t kPoints = PX * PY * PZ;  // 36
constexpr std::size_t kHex = NX * NY * NZ;     // 12
constexpr std::size_t kBars = 4;
constexpr std::size_t kCells = kHex + kBars;

std::int64_t node(int i, int j, int k) { return i + PX * (j + PY * k); }

ResultMesh make_mesh(bool with_bars = true) {
  ResultMesh m;
  for (int k = 0; k < PZ; ++k)
    for (int j = 0; j < PY; ++j)
      for (int i = 0; i < PX; ++i) {
        m.points.insert(m.points.end(), {1.0 * i, 0.5 * j, 0.25 * k});
      }
  for (int k = 0; k < NZ; ++k)
    for (int j = 0; j < NY; ++j)
      for (int i = 0; i < NX; ++i) {
        m.hex().conn.insert(m.hex().conn.end(),
                            {node(i, j, k), node(i + 1, j, k), node(i + 1, j + 1, k),
                             node(i, j + 1, k), node(i, j, k + 1), node(i + 1, j, k + 1),
                             node(i + 1, j + 1, k + 1), node(i, j + 1, k + 1)});
        m.hex().part.push_back(i < 2 ? 0 : 1);
      }
  if (with_bars) {
    for (int i = 0; i < NX; ++i) {  // along x on the top front edge
      m.bars().conn.insert(m.bars().conn.end(), {node(i, 0, NZ), node(i + 1, 0, NZ)});
      m.bars().part.push_back(2);
    }
    m.bars().conn.insert(m.bars().conn.end(), {node(NX, 0, NZ), node(NX, 1, NZ)});  // along y
    m.bars().part.push_back(2);
  }
  m.part_names = {"matrix", "insert", "tows"};
  return m;
}

constexpr std::size_t kQuads = NX * NY;  // shells on one face of the block

// The shells of the top face (z = NZ), counter-clockwise seen from +z.
void add_top_shells(ResultMesh& m, std::int32_t part) {
  for (int j = 0; j < NY; ++j)
    for (int i = 0; i < NX; ++i) {
      m.shells().conn.insert(m.shells().conn.end(), {node(i, j, NZ), node(i + 1, j, NZ),
                                                     node(i + 1, j + 1, NZ), node(i, j + 1, NZ)});
      m.shells().part.push_back(part);
    }
}

// The shells of the bottom face (z = 0), counter-clockwise seen from -z (outward).
void add_bottom_shells(ResultMesh& m, std::int32_t part) {
  for (int j = 0; j < NY; ++j)
    for (int i = 0; i < NX; ++i) {
      m.shells().conn.insert(m.shells().conn.end(), {node(i, j, 0), node(i, j + 1, 0),
                                                     node(i + 1, j + 1, 0), node(i + 1, j, 0)});
      m.shells().part.push_back(part);
    }
}

// The per-shell hand-off arrays: user ids from 5001, every other shell without a material,
// thicknesses 1.0, 1.1, ... mm.
void add_shell_handoff(ResultMesh& m, std::int32_t material) {
  for (std::size_t q = 0; q < m.n_quad(); ++q) {
    m.shells().user_id.push_back(5001 + static_cast<std::int64_t>(q));
    m.shells().material.push_back(q % 2 == 0 ? material : -1);
    m.quad_thickness.push_back(1e-3 * (1.0 + 0.1 * static_cast<double>(q)));
  }
}

// Hexahedra, bars and a skin of shells over the top face (part 3), with every hand-off array.
ResultMesh make_mixed_mesh() {
  ResultMesh m = make_mesh();
  add_top_shells(m, 3);
  m.part_names.push_back("skin");
  m.material_names = {"resin", "ncf_shell"};
  add_shell_handoff(m, 1);
  return m;
}

// Shells alone: the top face (part 0) and the bottom face (part 1) over the block's 36 points
// (the middle layer of points belongs to no cell).
ResultMesh make_shell_mesh() {
  ResultMesh m = make_mesh(/*with_bars=*/false);
  m.hex().conn.clear();
  m.hex().part.clear();
  add_top_shells(m, 0);
  add_bottom_shells(m, 1);
  m.part_names = {"top", "bottom"};
  m.material_names = {"ncf_shell"};
  add_shell_handoff(m, 0);
  return m;
}

double frame_time(int f) { return 0.5 * f; }
int frame_cycle(int f) { return 100 * f; }

Frame make_frame(const ResultMesh& m, int f) {
  const double t = frame_time(f);
  const std::size_t np = m.n_points();
  const std::size_t nc = m.n_cells();
  Frame fr;
  fr.time = t;
  fr.cycle = frame_cycle(f);
  for (std::size_t n = 0; n < np; ++n) {
    fr.displacement.insert(fr.displacement.end(),
                           {0.1 * t * m.points[3 * n], -0.01 * t * m.points[3 * n + 1],
                            0.02 * t * m.points[3 * n + 2]});
  }
  FrameField temperature{"temperature", false, 1, {}};
  FrameField velocity{"velocity", false, 3, {}};
  for (std::size_t n = 0; n < np; ++n) {
    temperature.values.push_back(20.0 + 0.5 * n + t);
    velocity.values.insert(velocity.values.end(), {0.1 * t, 1.0 * n, -1.0 * n});
  }
  FrameField stress{"stress", true, 6, {}};
  FrameField eqps{"eqps", true, 1, {}};
  for (std::size_t c = 0; c < nc; ++c) {
    for (int k = 0; k < 6; ++k) stress.values.push_back(10.0 * c + k + t);
    eqps.values.push_back(0.001 * c + t);
  }
  fr.fields = {temperature, velocity, stress, eqps};
  return fr;
}

class TempDir {
 public:
  TempDir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    path_ = fs::temp_directory_path() / ("ncfsim_io_" + std::to_string(::getpid()) + "_" +
                                         info->test_suite_name() + "_" + info->name());
    fs::remove_all(path_);
    fs::create_directories(path_);
  }
  ~TempDir() {
    if (!::testing::Test::HasFailure()) fs::remove_all(path_);
  }
  const fs::path& path() const { return path_; }

 private:
  fs::path path_;
};

// --- HDF5 reading
// -------------------------------------------------------------------------------------

struct H5File {
  explicit H5File(const fs::path& p) : id(H5Fopen(p.c_str(), H5F_ACC_RDONLY, H5P_DEFAULT)) {}
  ~H5File() {
    if (id >= 0) H5Fclose(id);
  }
  hid_t id;
};

/// Dimensions of dataset `path`, or nothing if there is no such dataset.
std::optional<std::vector<hsize_t>> dataset_dims(hid_t file, const std::string& path,
                                                 H5T_class_t* type_class = nullptr,
                                                 std::size_t* type_size = nullptr) {
  // Walk the path so that a missing intermediate group is "not found", not an error.
  std::string prefix;
  std::stringstream ss(path.substr(1));
  std::string part;
  while (std::getline(ss, part, '/')) {
    prefix += "/" + part;
    if (H5Lexists(file, prefix.c_str(), H5P_DEFAULT) <= 0) return std::nullopt;
  }
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (d < 0) return std::nullopt;
  const hid_t s = H5Dget_space(d);
  const int rank = H5Sget_simple_extent_ndims(s);
  std::vector<hsize_t> dims(static_cast<std::size_t>(rank));
  H5Sget_simple_extent_dims(s, dims.data(), nullptr);
  const hid_t t = H5Dget_type(d);
  if (type_class) *type_class = H5Tget_class(t);
  if (type_size) *type_size = H5Tget_size(t);
  H5Tclose(t);
  H5Sclose(s);
  H5Dclose(d);
  return dims;
}

template <class T>
std::vector<T> read_dataset(hid_t file, const std::string& path, hid_t mem_type) {
  const auto dims = dataset_dims(file, path);
  EXPECT_TRUE(dims.has_value()) << path;
  if (!dims) return {};
  std::size_t n = 1;
  for (hsize_t d : *dims) n *= d;
  std::vector<T> v(n);
  const hid_t d = H5Dopen2(file, path.c_str(), H5P_DEFAULT);
  if (n > 0) {
    EXPECT_GE(H5Dread(d, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), 0) << path;
  }
  H5Dclose(d);
  return v;
}

template <class T>
T read_attribute(hid_t loc, const std::string& obj, const char* name, hid_t mem_type) {
  T value{};
  const hid_t a = H5Aopen_by_name(loc, obj.c_str(), name, H5P_DEFAULT, H5P_DEFAULT);
  EXPECT_GE(a, 0) << obj << "@" << name;
  if (a >= 0) {
    EXPECT_GE(H5Aread(a, mem_type, &value), 0);
    H5Aclose(a);
  }
  return value;
}

// --- XML reading
// --------------------------------------------------------------------------------------

using XmlPtr = vtkSmartPointer<vtkXMLDataElement>;

XmlPtr read_xml(const fs::path& p) {
  XmlPtr root;
  root.TakeReference(vtkXMLUtilities::ReadElementFromFile(p.c_str()));
  return root;
}

std::vector<vtkXMLDataElement*> children(vtkXMLDataElement* e, const std::string& name) {
  std::vector<vtkXMLDataElement*> out;
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i) {
    if (name == e->GetNestedElement(i)->GetName()) out.push_back(e->GetNestedElement(i));
  }
  return out;
}

vtkXMLDataElement* child(vtkXMLDataElement* e, const std::string& name) {
  auto c = children(e, name);
  return c.size() == 1 ? c[0] : nullptr;
}

std::string attr(vtkXMLDataElement* e, const char* name) {
  const char* v = e->GetAttribute(name);
  return v ? v : "";
}

std::string trim(std::string s) {
  const auto b = s.find_first_not_of(" \t\r\n");
  if (b == std::string::npos) return "";
  const auto e = s.find_last_not_of(" \t\r\n");
  return s.substr(b, e - b + 1);
}

std::vector<hsize_t> parse_dims(const std::string& text) {
  std::vector<hsize_t> dims;
  std::istringstream in(text);
  hsize_t d;
  while (in >> d) dims.push_back(d);
  return dims;
}

void for_each_element(vtkXMLDataElement* e, const std::function<void(vtkXMLDataElement*)>& fn) {
  fn(e);
  for (int i = 0; i < e->GetNumberOfNestedElements(); ++i) {
    for_each_element(e->GetNestedElement(i), fn);
  }
}

// --- The checks
// -------------------------------------------------------------------------------------

/// Every DataItem of results.xdmf names a dataset of results.h5 with the stated dimensions and
/// number type; the series has `n_frames` frames with the written times; grids, element counts and
/// attribute centres/shapes agree with the mesh.
void check_xdmf_series(const fs::path& dir, const ResultMesh& mesh, int n_frames) {
  SCOPED_TRACE("check_xdmf_series(" + dir.string() + ", " + std::to_string(n_frames) + ")");
  ASSERT_FALSE(fs::exists(dir / "results.xdmf.tmp"));
  XmlPtr root = read_xml(dir / "results.xdmf");
  ASSERT_TRUE(root) << "results.xdmf does not parse";
  EXPECT_STREQ(root->GetName(), "Xdmf");
  EXPECT_EQ(attr(root, "Version"), "3.0");
  vtkXMLDataElement* domain = child(root, "Domain");
  ASSERT_TRUE(domain);
  vtkXMLDataElement* series = child(domain, "Grid");
  ASSERT_TRUE(series);
  EXPECT_EQ(attr(series, "GridType"), "Collection");
  EXPECT_EQ(attr(series, "CollectionType"), "Temporal");

  H5File h5(dir / "results.h5");
  ASSERT_GE(h5.id, 0) << "results.h5 does not open read-only";
  EXPECT_EQ(read_attribute<std::int32_t>(h5.id, "/", "n_frames", H5T_NATIVE_INT32), n_frames);

  // (1) Every DataItem resolves to a dataset with the stated shape and type.
  int n_items = 0;
  for_each_element(series, [&](vtkXMLDataElement* e) {
    if (std::string(e->GetName()) != "DataItem") return;
    ++n_items;
    const std::string text = trim(e->GetCharacterData() ? e->GetCharacterData() : "");
    SCOPED_TRACE("DataItem " + text);
    EXPECT_EQ(attr(e, "Format"), "HDF");
    const auto colon = text.find(':');
    ASSERT_NE(colon, std::string::npos);
    EXPECT_EQ(text.substr(0, colon), "results.h5");
    const std::string path = text.substr(colon + 1);
    H5T_class_t cls{};
    std::size_t size = 0;
    const auto dims = dataset_dims(h5.id, path, &cls, &size);
    ASSERT_TRUE(dims.has_value()) << "no dataset " << path;
    EXPECT_EQ(*dims, parse_dims(attr(e, "Dimensions")));
    const std::string number_type = attr(e, "NumberType");
    EXPECT_EQ(cls, number_type == "Float" ? H5T_FLOAT : H5T_INTEGER) << number_type;
    EXPECT_EQ(std::to_string(size), attr(e, "Precision"));
  });

  // (2) Frames, times, grids and counts.
  const auto frames = children(series, "Grid");
  ASSERT_EQ(frames.size(), static_cast<std::size_t>(n_frames));
  const std::set<std::string> expected_attributes = {"part_id",  "displacement", "temperature",
                                                     "velocity", "stress",       "eqps"};
  int expected_items = 0;
  for (int f = 0; f < n_frames; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    vtkXMLDataElement* fg = frames[static_cast<std::size_t>(f)];
    EXPECT_EQ(attr(fg, "GridType"), "Collection");
    EXPECT_EQ(attr(fg, "CollectionType"), "Spatial");
    vtkXMLDataElement* time = child(fg, "Time");
    ASSERT_TRUE(time);
    EXPECT_DOUBLE_EQ(std::stod(attr(time, "Value")), frame_time(f));
    char group[32];
    std::snprintf(group, sizeof group, "/frames/%06d", f);
    EXPECT_DOUBLE_EQ(read_attribute<double>(h5.id, group, "time", H5T_NATIVE_DOUBLE),
                     frame_time(f));
    EXPECT_EQ(read_attribute<std::int32_t>(h5.id, group, "cycle", H5T_NATIVE_INT32),
              frame_cycle(f));

    std::map<std::string, vtkXMLDataElement*> blocks;
    for (vtkXMLDataElement* g : children(fg, "Grid")) blocks[attr(g, "Name")] = g;
    std::map<std::string, std::size_t> expected_blocks;
    if (mesh.n_hex() > 0) expected_blocks["solids"] = mesh.n_hex();
    if (mesh.n_bar() > 0) expected_blocks["bars"] = mesh.n_bar();
    if (mesh.n_quad() > 0) expected_blocks["shells"] = mesh.n_quad();
    ASSERT_EQ(blocks.size(), expected_blocks.size());
    {  // the blocks in the kind order: solids, bars, shells
      std::vector<std::string> order, expected_order;
      for (vtkXMLDataElement* g : children(fg, "Grid")) order.push_back(attr(g, "Name"));
      for (const char* name : {"solids", "bars", "shells"})
        if (expected_blocks.count(name)) expected_order.push_back(name);
      EXPECT_EQ(order, expected_order);
    }
    for (const auto& [name, n_elements] : expected_blocks) {
      SCOPED_TRACE("block " + name);
      ASSERT_TRUE(blocks.count(name));
      vtkXMLDataElement* g = blocks[name];
      EXPECT_EQ(attr(g, "GridType"), "Uniform");
      vtkXMLDataElement* topo = child(g, "Topology");
      ASSERT_TRUE(topo);
      EXPECT_EQ(attr(topo, "NumberOfElements"), std::to_string(n_elements));
      const std::string kind = name == "solids" ? "hex8" : name == "bars" ? "bar2" : "quad4";
      const std::string part = name == "solids" ? "hex_part"
                               : name == "bars" ? "bar_part"
                                                : "quad_part";
      if (name == "solids") {
        EXPECT_EQ(attr(topo, "TopologyType"), "Hexahedron");
      } else if (name == "bars") {
        EXPECT_EQ(attr(topo, "TopologyType"), "Polyline");
        EXPECT_EQ(attr(topo, "NodesPerElement"), "2");
      } else {
        EXPECT_EQ(attr(topo, "TopologyType"), "Quadrilateral");
      }
      ASSERT_TRUE(child(topo, "DataItem"));
      EXPECT_EQ(trim(child(topo, "DataItem")->GetCharacterData()), "results.h5:/mesh/" + kind);
      vtkXMLDataElement* geom = child(g, "Geometry");
      ASSERT_TRUE(geom);
      EXPECT_EQ(attr(geom, "GeometryType"), "XYZ");
      ASSERT_TRUE(child(geom, "DataItem"));
      EXPECT_EQ(trim(child(geom, "DataItem")->GetCharacterData()),
                std::string("results.h5:") + group + "/coordinates");
      expected_items += 2;

      std::set<std::string> names;
      for (vtkXMLDataElement* a : children(g, "Attribute")) {
        const std::string aname = attr(a, "Name");
        SCOPED_TRACE("attribute " + aname);
        names.insert(aname);
        ++expected_items;
        vtkXMLDataElement* item = child(a, "DataItem");
        ASSERT_TRUE(item);
        const auto dims = parse_dims(attr(item, "Dimensions"));
        ASSERT_FALSE(dims.empty());
        const bool on_cells = aname == "part_id" || aname == "stress" || aname == "eqps";
        EXPECT_EQ(attr(a, "Center"), on_cells ? "Cell" : "Node");
        EXPECT_EQ(dims[0], on_cells ? n_elements : mesh.n_points());
        if (on_cells) {  // the kind's own slice of the cell data
          const std::string path = trim(item->GetCharacterData());
          EXPECT_EQ(path, aname == "part_id"
                              ? "results.h5:/mesh/" + part
                              : "results.h5:" + std::string(group) + "/" + kind + "/" + aname);
        }
        const std::string type = attr(a, "AttributeType");
        const hsize_t comps = dims.size() == 1 ? 1 : dims[1];
        EXPECT_EQ(comps, type == "Scalar" ? 1u : type == "Vector" ? 3u : 6u) << type;
      }
      EXPECT_EQ(names, expected_attributes);
    }
  }
  EXPECT_EQ(n_items, expected_items);  // nothing outside topology/geometry/attributes
}

/// results.pvd lists `n_frames` readable .vtu files with the written times; the last one holds the
/// deformed mesh with both cell types and the fields.
void check_vtu_series(const fs::path& dir, const ResultMesh& mesh, int n_frames) {
  SCOPED_TRACE("check_vtu_series(" + dir.string() + ", " + std::to_string(n_frames) + ")");
  ASSERT_FALSE(fs::exists(dir / "results.pvd.tmp"));
  XmlPtr root = read_xml(dir / "results.pvd");
  ASSERT_TRUE(root) << "results.pvd does not parse";
  EXPECT_EQ(attr(root, "type"), "Collection");
  vtkXMLDataElement* collection = child(root, "Collection");
  ASSERT_TRUE(collection);
  const auto sets = children(collection, "DataSet");
  ASSERT_EQ(sets.size(), static_cast<std::size_t>(n_frames));
  for (int f = 0; f < n_frames; ++f) {
    vtkXMLDataElement* ds = sets[static_cast<std::size_t>(f)];
    EXPECT_DOUBLE_EQ(std::stod(attr(ds, "timestep")), frame_time(f));
    char name[64];
    std::snprintf(name, sizeof name, "frames/frame_%05d.vtu", f);
    EXPECT_EQ(attr(ds, "file"), name);
    EXPECT_TRUE(fs::exists(dir / name)) << name;
    EXPECT_FALSE(fs::exists(dir / (std::string(name) + ".tmp")));
  }
  if (n_frames == 0) return;

  const int f = n_frames - 1;
  const Frame expected = make_frame(mesh, f);
  const fs::path file = dir / attr(sets.back(), "file");
  {
    std::ifstream in(file, std::ios::binary);
    std::string head(4096, '\0');
    in.read(head.data(), static_cast<std::streamsize>(head.size()));
    EXPECT_NE(head.find("compressor=\"vtkZLibDataCompressor\""), std::string::npos);
    EXPECT_NE(head.find("<AppendedData encoding=\"raw\">"), std::string::npos);
  }
  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(file.c_str());
  reader->Update();
  vtkUnstructuredGrid* ug = reader->GetOutput();
  ASSERT_TRUE(ug);
  const std::size_t n_cells = mesh.n_cells();
  ASSERT_EQ(static_cast<std::size_t>(ug->GetNumberOfPoints()), mesh.n_points());
  ASSERT_EQ(static_cast<std::size_t>(ug->GetNumberOfCells()), n_cells);
  // Cells in the kind order: hexahedra, then lines, then quads.
  const std::size_t first_bar = mesh.n_hex(), first_quad = mesh.n_hex() + mesh.n_bar();
  for (std::size_t c = 0; c < n_cells; ++c) {
    const bool hex = c < first_bar, bar = !hex && c < first_quad;
    ASSERT_EQ(ug->GetCellType(static_cast<vtkIdType>(c)), hex   ? VTK_HEXAHEDRON
                                                          : bar ? VTK_LINE
                                                                : VTK_QUAD)
        << c;
    vtkNew<vtkIdList> ids;
    ug->GetCellPoints(static_cast<vtkIdType>(c), ids);
    const std::size_t nn = hex ? 8 : bar ? 2 : 4;
    ASSERT_EQ(static_cast<std::size_t>(ids->GetNumberOfIds()), nn);
    for (std::size_t j = 0; j < nn; ++j) {
      const std::int64_t want = hex   ? mesh.hex().conn[8 * c + j]
                                : bar ? mesh.bars().conn[2 * (c - first_bar) + j]
                                      : mesh.shells().conn[4 * (c - first_quad) + j];
      EXPECT_EQ(ids->GetId(static_cast<vtkIdType>(j)), want) << "cell " << c;
    }
  }
  // Points are the deformed geometry.
  for (std::size_t n = 0; n < mesh.n_points(); ++n) {
    double x[3];
    ug->GetPoint(static_cast<vtkIdType>(n), x);
    for (int k = 0; k < 3; ++k) {
      EXPECT_DOUBLE_EQ(x[k], mesh.points[3 * n + k] + expected.displacement[3 * n + k]);
    }
  }
  vtkDataArray* disp = ug->GetPointData()->GetArray("displacement");
  ASSERT_TRUE(disp);
  EXPECT_EQ(disp->GetNumberOfComponents(), 3);
  EXPECT_DOUBLE_EQ(disp->GetComponent(35, 0), expected.displacement[3 * 35]);
  vtkDataArray* temperature = ug->GetPointData()->GetArray("temperature");
  ASSERT_TRUE(temperature);
  EXPECT_DOUBLE_EQ(temperature->GetComponent(7, 0), 20.0 + 0.5 * 7 + frame_time(f));
  vtkDataArray* velocity = ug->GetPointData()->GetArray("velocity");
  ASSERT_TRUE(velocity);
  EXPECT_DOUBLE_EQ(velocity->GetComponent(5, 2), -5.0);
  vtkDataArray* part = ug->GetCellData()->GetArray("part_id");
  ASSERT_TRUE(part);
  for (std::size_t c = 0; c < n_cells; ++c) {
    const int want = c < first_bar    ? mesh.hex().part[c]
                     : c < first_quad ? mesh.bars().part[c - first_bar]
                                      : mesh.shells().part[c - first_quad];
    EXPECT_EQ(part->GetComponent(static_cast<vtkIdType>(c), 0), want);
  }
  vtkDataArray* stress = ug->GetCellData()->GetArray("stress");
  ASSERT_TRUE(stress);
  EXPECT_EQ(stress->GetNumberOfComponents(), 6);
  const auto last = static_cast<vtkIdType>(n_cells - 1);  // a shell, else a bar when there are
  EXPECT_DOUBLE_EQ(stress->GetComponent(last, 4), 10.0 * (n_cells - 1) + 4 + frame_time(f));
  vtkDataArray* eqps = ug->GetCellData()->GetArray("eqps");
  ASSERT_TRUE(eqps);
  ASSERT_EQ(static_cast<std::size_t>(eqps->GetNumberOfTuples()), n_cells);
  for (std::size_t c = 0; c < n_cells; ++c) {  // every cell's own value, shells included
    EXPECT_DOUBLE_EQ(eqps->GetComponent(static_cast<vtkIdType>(c), 0), expected.fields[3].values[c])
        << "cell " << c;
  }
}

// --- Tests
// --------------------------------------------------------------------------------------------

TEST(XdmfResultWriter, DataItemsResolveToDatasetsWithStatedDimensions) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  XdmfResultWriter writer(dir.path(), mesh);
  for (int f = 0; f < 3; ++f) writer.write_frame(make_frame(mesh, f));
  writer.close();
  EXPECT_EQ(writer.frames_written(), 3u);
  check_xdmf_series(dir.path(), mesh, 3);
}

TEST(XdmfResultWriter, H5HoldsMeshPartsAndFrames) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  {
    XdmfResultWriter writer(dir.path(), mesh);
    for (int f = 0; f < 3; ++f) writer.write_frame(make_frame(mesh, f));
    writer.close();
  }
  H5File h5(dir.path() / "results.h5");
  ASSERT_GE(h5.id, 0);
  EXPECT_EQ(read_dataset<double>(h5.id, "/mesh/points", H5T_NATIVE_DOUBLE), mesh.points);
  EXPECT_EQ(read_dataset<std::int64_t>(h5.id, "/mesh/hex8", H5T_NATIVE_INT64), mesh.hex().conn);
  EXPECT_EQ(read_dataset<std::int64_t>(h5.id, "/mesh/bar2", H5T_NATIVE_INT64), mesh.bars().conn);
  EXPECT_EQ(read_dataset<std::int32_t>(h5.id, "/mesh/hex_part", H5T_NATIVE_INT32), mesh.hex().part);
  EXPECT_EQ(read_dataset<std::int32_t>(h5.id, "/mesh/bar_part", H5T_NATIVE_INT32),
            mesh.bars().part);
  EXPECT_EQ(*dataset_dims(h5.id, "/mesh/points"), (std::vector<hsize_t>{kPoints, 3}));
  EXPECT_EQ(*dataset_dims(h5.id, "/mesh/hex8"), (std::vector<hsize_t>{kHex, 8}));
  EXPECT_EQ(*dataset_dims(h5.id, "/mesh/bar2"), (std::vector<hsize_t>{kBars, 2}));

  {  // part names: variable-length strings
    const hid_t d = H5Dopen2(h5.id, "/mesh/part_names", H5P_DEFAULT);
    ASSERT_GE(d, 0);
    const hid_t t = H5Tcopy(H5T_C_S1);
    H5Tset_size(t, H5T_VARIABLE);
    H5Tset_cset(t, H5T_CSET_UTF8);
    std::vector<char*> names(mesh.part_names.size());
    ASSERT_GE(H5Dread(d, t, H5S_ALL, H5S_ALL, H5P_DEFAULT, names.data()), 0);
    for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(names[i], mesh.part_names[i]);
    const hid_t s = H5Dget_space(d);
    H5Dvlen_reclaim(t, s, H5P_DEFAULT, names.data());
    H5Sclose(s);
    H5Tclose(t);
    H5Dclose(d);
  }

  const Frame fr = make_frame(mesh, 2);
  const std::vector<double> x =
      read_dataset<double>(h5.id, "/frames/000002/coordinates", H5T_NATIVE_DOUBLE);
  ASSERT_EQ(x.size(), mesh.points.size());
  for (std::size_t i = 0; i < x.size(); ++i) {
    EXPECT_DOUBLE_EQ(x[i], mesh.points[i] + fr.displacement[i]);
  }
  EXPECT_EQ(read_dataset<double>(h5.id, "/frames/000002/displacement", H5T_NATIVE_DOUBLE),
            fr.displacement);
  EXPECT_EQ(read_dataset<double>(h5.id, "/frames/000002/temperature", H5T_NATIVE_DOUBLE),
            fr.fields[0].values);
  EXPECT_EQ(*dataset_dims(h5.id, "/frames/000002/velocity"), (std::vector<hsize_t>{kPoints, 3}));
  // Cell fields are split at the hex/bar boundary.
  const std::vector<double>& stress = fr.fields[2].values;
  EXPECT_EQ(read_dataset<double>(h5.id, "/frames/000002/hex8/stress", H5T_NATIVE_DOUBLE),
            std::vector<double>(stress.begin(), stress.begin() + 6 * kHex));
  EXPECT_EQ(read_dataset<double>(h5.id, "/frames/000002/bar2/stress", H5T_NATIVE_DOUBLE),
            std::vector<double>(stress.begin() + 6 * kHex, stress.end()));
  EXPECT_EQ(*dataset_dims(h5.id, "/frames/000002/bar2/eqps"), (std::vector<hsize_t>{kBars}));
  EXPECT_EQ(*dataset_dims(h5.id, "/frames/000002/hex8/stress"), (std::vector<hsize_t>{kHex, 6}));
  EXPECT_FALSE(dataset_dims(h5.id, "/frames/000003/coordinates").has_value());
}

TEST(XdmfResultWriter, MeshWithoutBarsHasNoBarsBlock) {
  TempDir dir;
  const ResultMesh mesh = make_mesh(/*with_bars=*/false);
  XdmfResultWriter writer(dir.path(), mesh);
  for (int f = 0; f < 2; ++f) writer.write_frame(make_frame(mesh, f));
  writer.close();
  check_xdmf_series(dir.path(), mesh, 2);
}

TEST(XdmfResultWriter, EmptySeriesBeforeFirstFrame) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  XdmfResultWriter writer(dir.path(), mesh);
  check_xdmf_series(dir.path(), mesh, 0);
}

TEST(VtuSeriesWriter, ReadsBackThroughVtk) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  VtuSeriesWriter writer(dir.path(), mesh);
  for (int f = 0; f < 3; ++f) writer.write_frame(make_frame(mesh, f));
  writer.close();
  EXPECT_EQ(writer.frames_written(), 3u);
  EXPECT_EQ(writer.frame_path(2), dir.path() / "frames" / "frame_00002.vtu");
  check_vtu_series(dir.path(), mesh, 3);
}

// (3) Files are complete after each write_frame: results.h5 is closed between frames, so it opens
// read-only while the writer is alive, and nothing depends on close() or the destructor.
TEST(Consistency, FilesCompleteWhileWriterAliveAndWithoutClose) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  {
    XdmfResultWriter xdmf(dir.path(), mesh);
    VtuSeriesWriter vtu(dir.path(), mesh);
    for (int f = 0; f < 2; ++f) {
      xdmf.write_frame(make_frame(mesh, f));
      vtu.write_frame(make_frame(mesh, f));
      check_xdmf_series(dir.path(), mesh, f + 1);  // writer still alive
      check_vtu_series(dir.path(), mesh, f + 1);
    }
    // destroyed without close()
  }
  check_xdmf_series(dir.path(), mesh, 2);
  check_vtu_series(dir.path(), mesh, 2);
}

TEST(Consistency, ProcessKilledBetweenFramesLeavesValidFiles) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  const pid_t pid = ::fork();
  ASSERT_GE(pid, 0);
  if (pid == 0) {
    // Child: two frames, then exit without destructors, atexit handlers or HDF5 shutdown.
    int code = 0;
    try {
      XdmfResultWriter xdmf(dir.path(), mesh);
      VtuSeriesWriter vtu(dir.path(), mesh);
      for (int f = 0; f < 2; ++f) {
        xdmf.write_frame(make_frame(mesh, f));
        vtu.write_frame(make_frame(mesh, f));
      }
      std::_Exit(0);
    } catch (...) {
      code = 1;
    }
    std::_Exit(code);
  }
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  ASSERT_EQ(WEXITSTATUS(status), 0);
  check_xdmf_series(dir.path(), mesh, 2);
  check_vtu_series(dir.path(), mesh, 2);
}

TEST(Consistency, NewWriterReplacesEarlierSeries) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  {
    XdmfResultWriter xdmf(dir.path(), mesh);
    VtuSeriesWriter vtu(dir.path(), mesh);
    for (int f = 0; f < 3; ++f) {
      xdmf.write_frame(make_frame(mesh, f));
      vtu.write_frame(make_frame(mesh, f));
    }
  }
  XdmfResultWriter xdmf(dir.path(), mesh);
  VtuSeriesWriter vtu(dir.path(), mesh);
  xdmf.write_frame(make_frame(mesh, 0));
  vtu.write_frame(make_frame(mesh, 0));
  check_xdmf_series(dir.path(), mesh, 1);
  check_vtu_series(dir.path(), mesh, 1);
}

TEST(Errors, BadInputIsRejected) {
  TempDir dir;
  ResultMesh bad = make_mesh();
  bad.hex().conn[3] = 999;
  EXPECT_THROW(XdmfResultWriter(dir.path(), bad), std::invalid_argument);
  bad = make_mesh();
  bad.bars().part.pop_back();
  EXPECT_THROW(VtuSeriesWriter(dir.path(), bad), std::invalid_argument);

  const ResultMesh mesh = make_mesh();
  XdmfResultWriter xdmf(dir.path(), mesh);
  VtuSeriesWriter vtu(dir.path(), mesh);
  Frame fr = make_frame(mesh, 0);
  fr.displacement.pop_back();
  EXPECT_THROW(xdmf.write_frame(fr), std::invalid_argument);
  EXPECT_THROW(vtu.write_frame(fr), std::invalid_argument);
  fr = make_frame(mesh, 0);
  fr.fields[2].values.pop_back();
  EXPECT_THROW(xdmf.write_frame(fr), std::invalid_argument);
  fr = make_frame(mesh, 0);
  fr.fields[0].name = "part_id";
  EXPECT_THROW(xdmf.write_frame(fr), std::invalid_argument);
  fr = make_frame(mesh, 0);
  fr.fields[1].name = "temperature";
  EXPECT_THROW(vtu.write_frame(fr), std::invalid_argument);
  for (const char* bad_name : {"a/b", "", "T \"q\"", "von mises", "a:b", "x<y"}) {
    fr.fields[1].name = bad_name;
    EXPECT_THROW(xdmf.write_frame(fr), std::invalid_argument) << bad_name;
    EXPECT_THROW(vtu.write_frame(fr), std::invalid_argument) << bad_name;
  }
  fr.fields[1].name = "S(1,1)";  // ',' is not allowed either
  EXPECT_THROW(xdmf.write_frame(fr), std::invalid_argument);
  fr.fields[1].name = "S[11]_max-1.5+(a)";
  EXPECT_NO_THROW(validate_frame(mesh, fr));
  EXPECT_EQ(xdmf.frames_written(), 0u);
  EXPECT_EQ(vtu.frames_written(), 0u);

  xdmf.write_frame(make_frame(mesh, 0));
  xdmf.close();
  EXPECT_THROW(xdmf.write_frame(make_frame(mesh, 1)), std::logic_error);
  vtu.close();
  EXPECT_THROW(vtu.write_frame(make_frame(mesh, 1)), std::logic_error);
}

TEST(Errors, Hdf5FailureNamesTheFileAndKeepsEarlierFrames) {
  TempDir dir;
  const ResultMesh mesh = make_mesh();
  XdmfResultWriter xdmf(dir.path(), mesh);
  xdmf.write_frame(make_frame(mesh, 0));
  const fs::path saved = dir.path() / "saved.h5";
  fs::rename(dir.path() / "results.h5", saved);
  {
    std::ofstream garbage(dir.path() / "results.h5");
    garbage << "not an HDF5 file\n";
  }
  try {
    xdmf.write_frame(make_frame(mesh, 1));
    FAIL() << "expected std::runtime_error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("results.h5"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("H5Fopen"), std::string::npos) << e.what();
  }
  fs::rename(saved, dir.path() / "results.h5");
  check_xdmf_series(dir.path(), mesh, 1);  // the failed frame never entered results.xdmf
  xdmf.write_frame(make_frame(mesh, 1));   // and the writer carries on
  check_xdmf_series(dir.path(), mesh, 2);
}

// --- Shells (quad4)
// ------------------------------------------------------------------------------------

/// Every object path in an HDF5 file ("/mesh", "/mesh/points", ...), sorted.
std::set<std::string> h5_object_paths(hid_t file) {
  std::set<std::string> paths;
  H5Lvisit(
      file, H5_INDEX_NAME, H5_ITER_INC,
      [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::set<std::string>*>(data)->insert(std::string("/") + name);
        return 0;
      },
      &paths);
  return paths;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The cells [first, first + n) of a cell field (n_components values each).
std::vector<double> cell_slice(const FrameField& f, std::size_t first, std::size_t n) {
  const auto nc = static_cast<std::size_t>(f.n_components);
  return std::vector<double>(f.values.begin() + static_cast<std::ptrdiff_t>(nc * first),
                             f.values.begin() + static_cast<std::ptrdiff_t>(nc * (first + n)));
}

/// What ResultReader and the stage hand-off give back equals what was written: the mesh with
/// every shell array, and the cell fields joined in the kind order (hexes, bars, shells).
void check_read_back(const fs::path& h5, const ResultMesh& mesh, int n_frames) {
  SCOPED_TRACE("check_read_back(" + h5.string() + ")");
  const ResultReader reader(h5);
  const ResultMesh& r = reader.mesh();
  ASSERT_EQ(reader.n_frames(), static_cast<std::size_t>(n_frames));
  EXPECT_EQ(r.n_hex(), mesh.n_hex());
  EXPECT_EQ(r.n_bar(), mesh.n_bar());
  EXPECT_EQ(r.n_quad(), mesh.n_quad());
  EXPECT_EQ(r.points, mesh.points);
  EXPECT_EQ(r.hex().conn, mesh.hex().conn);
  EXPECT_EQ(r.bars().conn, mesh.bars().conn);
  EXPECT_EQ(r.shells().conn, mesh.shells().conn);
  EXPECT_EQ(r.hex().part, mesh.hex().part);
  EXPECT_EQ(r.bars().part, mesh.bars().part);
  EXPECT_EQ(r.shells().part, mesh.shells().part);
  EXPECT_EQ(r.shells().user_id, mesh.shells().user_id);
  EXPECT_EQ(r.shells().material, mesh.shells().material);
  EXPECT_EQ(r.quad_thickness, mesh.quad_thickness);  // float64 both ways: bitwise
  EXPECT_EQ(r.part_names, mesh.part_names);
  EXPECT_EQ(r.material_names, mesh.material_names);

  const StageFrame last = read_last_frame(h5);
  EXPECT_EQ(last.index, static_cast<std::size_t>(n_frames - 1));
  EXPECT_EQ(last.mesh.shells().conn, mesh.shells().conn);
  EXPECT_EQ(last.mesh.quad_thickness, mesh.quad_thickness);
  const Frame written = make_frame(mesh, n_frames - 1);
  for (const FrameField& w : written.fields) {
    SCOPED_TRACE("field " + w.name);
    const FrameField* got = last.field(w.name);
    ASSERT_TRUE(got);
    EXPECT_EQ(got->on_cells, w.on_cells);
    EXPECT_EQ(got->n_components, w.n_components);
    EXPECT_EQ(got->values, w.values);  // each kind's slice back at its place
  }
}

// A mesh with hexahedra, bars and shells: /mesh/quad4 and the per-shell arrays hold what was
// given, each cell field is split at the hex / bar / shell boundaries (/frames/N/quad4/ holds the
// shells' slice), results.xdmf has a third Uniform grid "shells" (Quadrilateral, 6 cells, "6 4"
// connectivity), and the reader and the stage hand-off join the slices back into the same values.
TEST(Shells, MixedMeshWritesQuadCellsBesideHexesAndBarsAndReadsBack) {
  TempDir dir;
  const ResultMesh mesh = make_mixed_mesh();
  ASSERT_EQ(mesh.n_quad(), kQuads);
  {
    XdmfResultWriter writer(dir.path(), mesh);
    for (int f = 0; f < 2; ++f) writer.write_frame(make_frame(mesh, f));
  }
  check_xdmf_series(dir.path(), mesh, 2);

  {  // closed before the reader opens the file (HDF5 refuses a second open with other locking)
    H5File h5(dir.path() / "results.h5");
    ASSERT_GE(h5.id, 0);
    EXPECT_EQ(*dataset_dims(h5.id, "/mesh/quad4"), (std::vector<hsize_t>{kQuads, 4}));
    EXPECT_EQ(read_dataset<std::int64_t>(h5.id, "/mesh/quad4", H5T_NATIVE_INT64),
              mesh.shells().conn);
    EXPECT_EQ(read_dataset<std::int32_t>(h5.id, "/mesh/quad_part", H5T_NATIVE_INT32),
              mesh.shells().part);
    EXPECT_EQ(read_dataset<std::int64_t>(h5.id, "/mesh/quad_user_id", H5T_NATIVE_INT64),
              mesh.shells().user_id);
    EXPECT_EQ(read_dataset<std::int32_t>(h5.id, "/mesh/quad_material", H5T_NATIVE_INT32),
              mesh.shells().material);
    EXPECT_EQ(read_dataset<double>(h5.id, "/mesh/quad_thickness", H5T_NATIVE_DOUBLE),
              mesh.quad_thickness);
    EXPECT_EQ(read_attribute<std::int32_t>(h5.id, "/", "format_version", H5T_NATIVE_INT32), 2);

    const Frame fr = make_frame(mesh, 1);
    const FrameField& stress = fr.fields[2];
    EXPECT_EQ(read_dataset<double>(h5.id, "/frames/000001/hex8/stress", H5T_NATIVE_DOUBLE),
              cell_slice(stress, 0, kHex));
    EXPECT_EQ(read_dataset<double>(h5.id, "/frames/000001/bar2/stress", H5T_NATIVE_DOUBLE),
              cell_slice(stress, kHex, kBars));
    EXPECT_EQ(read_dataset<double>(h5.id, "/frames/000001/quad4/stress", H5T_NATIVE_DOUBLE),
              cell_slice(stress, kHex + kBars, kQuads));
    EXPECT_EQ(*dataset_dims(h5.id, "/frames/000001/quad4/stress"),
              (std::vector<hsize_t>{kQuads, 6}));
    EXPECT_EQ(*dataset_dims(h5.id, "/frames/000001/quad4/eqps"), (std::vector<hsize_t>{kQuads}));
  }

  // The XDMF text itself, as ParaView's reader sees it.
  const std::string xdmf = read_text(dir.path() / "results.xdmf");
  EXPECT_NE(xdmf.find("<Grid Name=\"shells\" GridType=\"Uniform\">"), std::string::npos);
  EXPECT_NE(xdmf.find("<Topology TopologyType=\"Quadrilateral\" NumberOfElements=\"6\">"),
            std::string::npos);
  EXPECT_NE(xdmf.find("<DataItem Dimensions=\"6 4\" NumberType=\"Int\" Precision=\"8\" "
                      "Format=\"HDF\">results.h5:/mesh/quad4</DataItem>"),
            std::string::npos);

  check_read_back(dir.path() / "results.h5", mesh, 2);
}

// The VTU frames hold VTK_QUAD cells after the VTK_HEXAHEDRON and VTK_LINE cells, with the
// shells' part ids and cell data (check_vtu_series reads them through
// vtkXMLUnstructuredGridReader, cell by cell).
TEST(Shells, VtuHoldsQuadCellsAfterHexesAndLines) {
  TempDir dir;
  const ResultMesh mesh = make_mixed_mesh();
  VtuSeriesWriter writer(dir.path(), mesh);
  for (int f = 0; f < 2; ++f) writer.write_frame(make_frame(mesh, f));
  check_vtu_series(dir.path(), mesh, 2);

  vtkNew<vtkXMLUnstructuredGridReader> reader;
  reader->SetFileName(writer.frame_path(1).c_str());
  reader->Update();
  vtkUnstructuredGrid* ug = reader->GetOutput();
  std::map<int, std::size_t> count;
  for (vtkIdType c = 0; c < ug->GetNumberOfCells(); ++c) ++count[ug->GetCellType(c)];
  EXPECT_EQ(count, (std::map<int, std::size_t>{
                       {VTK_HEXAHEDRON, kHex}, {VTK_LINE, kBars}, {VTK_QUAD, kQuads}}));
}

// A mesh of shells alone: results.xdmf has only the "shells" grid, results.h5 keeps its empty
// /mesh/hex8 and /mesh/bar2 (as a hex-only file keeps an empty bar2), the VTU holds only quads,
// and everything reads back.
TEST(Shells, ShellsOnlyMesh) {
  TempDir dir;
  const ResultMesh mesh = make_shell_mesh();
  ASSERT_EQ(mesh.n_hex() + mesh.n_bar(), 0u);
  ASSERT_EQ(mesh.n_quad(), 2 * kQuads);
  {
    XdmfResultWriter xdmf(dir.path(), mesh);
    VtuSeriesWriter vtu(dir.path(), mesh);
    for (int f = 0; f < 3; ++f) {
      xdmf.write_frame(make_frame(mesh, f));
      vtu.write_frame(make_frame(mesh, f));
    }
  }
  check_xdmf_series(dir.path(), mesh, 3);
  check_vtu_series(dir.path(), mesh, 3);
  {
    H5File h5(dir.path() / "results.h5");
    ASSERT_GE(h5.id, 0);
    EXPECT_EQ(*dataset_dims(h5.id, "/mesh/hex8"), (std::vector<hsize_t>{0, 8}));
    EXPECT_EQ(*dataset_dims(h5.id, "/frames/000002/quad4/stress"),
              (std::vector<hsize_t>{2 * kQuads, 6}));
  }
  const std::string text = read_text(dir.path() / "results.xdmf");
  EXPECT_EQ(text.find("Hexahedron"), std::string::npos);
  EXPECT_EQ(text.find("Polyline"), std::string::npos);
  check_read_back(dir.path() / "results.h5", mesh, 3);
}

// A mesh without shells writes exactly the objects it wrote before shells existed (no quad4
// dataset or frame group, format_version still 2), results.xdmf names no shells grid, and the
// reader gives empty shell arrays and cell fields of n_hex + n_bar cells.
TEST(Shells, FilesWithoutShellsKeepTheirLayout) {
  TempDir dir;
  ResultMesh mesh = make_mesh();
  mesh.hex().user_id.resize(mesh.n_hex(), 7);
  mesh.hex().material.resize(mesh.n_hex(), 0);
  mesh.material_names = {"resin"};
  {
    XdmfResultWriter writer(dir.path(), mesh);
    writer.write_frame(make_frame(mesh, 0));
  }
  {
    H5File h5(dir.path() / "results.h5");
    ASSERT_GE(h5.id, 0);
    const std::set<std::string> expected = {"/frames",
                                            "/frames/000000",
                                            "/frames/000000/bar2",
                                            "/frames/000000/bar2/eqps",
                                            "/frames/000000/bar2/stress",
                                            "/frames/000000/coordinates",
                                            "/frames/000000/displacement",
                                            "/frames/000000/hex8",
                                            "/frames/000000/hex8/eqps",
                                            "/frames/000000/hex8/stress",
                                            "/frames/000000/temperature",
                                            "/frames/000000/velocity",
                                            "/mesh",
                                            "/mesh/bar2",
                                            "/mesh/bar_part",
                                            "/mesh/hex8",
                                            "/mesh/hex_material",
                                            "/mesh/hex_part",
                                            "/mesh/hex_user_id",
                                            "/mesh/material_names",
                                            "/mesh/part_names",
                                            "/mesh/points"};
    EXPECT_EQ(h5_object_paths(h5.id), expected);
    EXPECT_EQ(read_attribute<std::int32_t>(h5.id, "/", "format_version", H5T_NATIVE_INT32), 2);
  }
  const std::string text = read_text(dir.path() / "results.xdmf");
  EXPECT_EQ(text.find("shells"), std::string::npos);
  EXPECT_EQ(text.find("Quadrilateral"), std::string::npos);

  const StageFrame fr = read_last_frame(dir.path() / "results.h5");
  EXPECT_EQ(fr.mesh.n_quad(), 0u);
  EXPECT_TRUE(fr.mesh.shells().part.empty() && fr.mesh.shells().user_id.empty() &&
              fr.mesh.shells().material.empty() && fr.mesh.quad_thickness.empty());
  ASSERT_TRUE(fr.field("stress"));
  EXPECT_EQ(fr.field("stress")->values.size(), 6 * kCells);
}

// results.xdmf of a mesh without shells, byte for byte as the writer wrote it before shells (the
// text below was written from that code): one hexahedron, one bar, one frame with a nodal and a
// cell field.
TEST(Shells, XdmfTextWithoutShellsIsUnchanged) {
  TempDir dir;
  ResultMesh mesh;
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i)
        mesh.points.insert(mesh.points.end(), {1.0 * i, 1.0 * j, 1.0 * k});
  mesh.hex().conn = {0, 1, 3, 2, 4, 5, 7, 6};
  mesh.hex().part = {0};
  mesh.bars().conn = {0, 7};
  mesh.bars().part = {1};
  mesh.part_names = {"block", "tie"};
  Frame fr;
  fr.time = 0.5;
  fr.cycle = 3;
  fr.displacement.assign(3 * mesh.n_points(), 0.0);
  fr.fields.push_back({"temperature", false, 1, std::vector<double>(mesh.n_points(), 20.0)});
  fr.fields.push_back({"stress", true, 6, std::vector<double>(6 * mesh.n_cells(), 1.0)});
  {
    XdmfResultWriter writer(dir.path(), mesh);
    writer.write_frame(fr);
  }
  const std::string item = "            <DataItem Dimensions=\"";
  const std::string tail = "\" Format=\"HDF\">results.h5:";
  auto grid = [&](const std::string& name, const std::string& topology, const std::string& conn,
                  const std::string& kind, const std::string& part) {
    return "        <Grid Name=\"" + name + "\" GridType=\"Uniform\">\n" + "          <Topology " +
           topology + " NumberOfElements=\"1\">\n" + item + conn +
           "\" NumberType=\"Int\" Precision=\"8" + tail + "/mesh/" + kind + "</DataItem>\n" +
           "          </Topology>\n" + "          <Geometry GeometryType=\"XYZ\">\n" + item +
           "8 3\" NumberType=\"Float\" Precision=\"8" + tail +
           "/frames/000000/coordinates</DataItem>\n" + "          </Geometry>\n" +
           "          <Attribute Name=\"part_id\" AttributeType=\"Scalar\" Center=\"Cell\">\n" +
           item + "1\" NumberType=\"Int\" Precision=\"4" + tail + "/mesh/" + part +
           "</DataItem>\n" + "          </Attribute>\n" +
           "          <Attribute Name=\"displacement\" AttributeType=\"Vector\" "
           "Center=\"Node\">\n" +
           item + "8 3\" NumberType=\"Float\" Precision=\"8" + tail +
           "/frames/000000/displacement</DataItem>\n" + "          </Attribute>\n" +
           "          <Attribute Name=\"temperature\" AttributeType=\"Scalar\" Center=\"Node\">\n" +
           item + "8\" NumberType=\"Float\" Precision=\"8" + tail +
           "/frames/000000/temperature</DataItem>\n" + "          </Attribute>\n" +
           "          <Attribute Name=\"stress\" AttributeType=\"Tensor6\" Center=\"Cell\">\n" +
           item + "1 6\" NumberType=\"Float\" Precision=\"8" + tail + "/frames/000000/" + kind +
           "/stress</DataItem>\n" + "          </Attribute>\n" + "        </Grid>\n";
  };
  const std::string expected =
      "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
      "<Xdmf xmlns:xi=\"http://www.w3.org/2001/XInclude\" Version=\"3.0\">\n"
      "  <Domain>\n"
      "    <Grid Name=\"results\" GridType=\"Collection\" CollectionType=\"Temporal\">\n"
      "      <Grid Name=\"frame_000000\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
      "        <Time Value=\"0.5\"/>\n"
      "        <Information Name=\"cycle\" Value=\"3\"/>\n" +
      grid("solids", "TopologyType=\"Hexahedron\"", "1 8", "hex8", "hex_part") +
      grid("bars", "TopologyType=\"Polyline\" NodesPerElement=\"2\"", "1 2", "bar2", "bar_part") +
      "      </Grid>\n"
      "    </Grid>\n"
      "  </Domain>\n"
      "</Xdmf>\n";
  EXPECT_EQ(read_text(dir.path() / "results.xdmf"), expected);
}

// validate_mesh and validate_frame check the shell arrays like the others: sizes, node ids,
// part ids, the optional per-shell arrays, thickness > 0 and the material index; a cell field
// sized for hexes and bars alone is refused on a mesh with shells, naming the three counts.
TEST(Shells, BadShellInputIsRejected) {
  const ResultMesh good = make_mixed_mesh();
  EXPECT_NO_THROW(validate_mesh(good));
  auto rejected = [](const ResultMesh& m, const std::string& words) {
    try {
      validate_mesh(m);
      ADD_FAILURE() << "no error, expected one naming '" << words << "'";
    } catch (const std::invalid_argument& e) {
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  ResultMesh m = good;
  m.shells().conn.pop_back();
  rejected(m, "quad4 has 23 node ids, not a multiple of 4");
  m = good;
  m.shells().conn[9] = static_cast<std::int64_t>(kPoints);
  rejected(m, "shell 2 has node id 36 outside [0, 36)");
  m = good;
  m.shells().conn[0] = -1;
  rejected(m, "shell 0 has node id -1");
  m = good;
  m.shells().part.pop_back();
  rejected(m, "quad_part has 5 entries for 6 shells");
  m = good;
  m.shells().part[4] = -2;
  rejected(m, "shell 4 has negative part id -2");
  m = good;
  m.shells().user_id.pop_back();
  rejected(m, "quad_user_id has 5 entries for 6 shells");
  m = good;
  m.shells().material.push_back(0);
  rejected(m, "quad_material has 7 entries for 6 shells");
  m = good;
  m.shells().material[3] = 2;  // two material names
  rejected(m, "shell 3 has material index 2, allowed -1 (none) or [0, 2)");
  m = good;
  m.shells().material[3] = -5;
  rejected(m, "shell 3 has material index -5");
  m = good;
  m.quad_thickness.resize(2);
  rejected(m, "quad_thickness has 2 entries for 6 shells");
  m = good;
  m.quad_thickness[1] = 0.0;
  rejected(m, "shell 1 has thickness 0 m, not a finite value > 0");
  m = good;
  m.quad_thickness[1] = std::numeric_limits<double>::quiet_NaN();
  rejected(m, "shell 1 has thickness NaN m");
  m = good;  // the optional arrays may be left out
  m.shells().user_id.clear(), m.shells().material.clear(), m.quad_thickness.clear();
  EXPECT_NO_THROW(validate_mesh(m));

  TempDir dir;
  m = good;
  m.shells().part.clear();
  EXPECT_THROW(XdmfResultWriter(dir.path(), m), std::invalid_argument);
  EXPECT_THROW(VtuSeriesWriter(dir.path(), m), std::invalid_argument);

  Frame fr = make_frame(make_mesh(), 0);  // cell fields for hexes and bars only
  try {
    validate_frame(good, fr);
    ADD_FAILURE() << "a cell field without the shells' values was accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("expected 132 (6 x 22 cells: 12 hexahedra, 4 bars, 6 "
                                         "shells, in that order)"),
              std::string::npos)
        << e.what();
  }
  fr = make_frame(good, 0);
  fr.fields[0].name = "quad4";  // the frame group of the shells' cell fields
  EXPECT_THROW(validate_frame(good, fr), std::invalid_argument);
}

// A results.h5 whose shells lost their part ids, or whose quad4 is not [n, 4], is refused by the
// reader with an error naming the file and the dataset, not read into a mesh that fails later.
TEST(Shells, ReaderRefusesDamagedShellDatasets) {
  TempDir dir;
  const ResultMesh mesh = make_mixed_mesh();
  {
    XdmfResultWriter writer(dir.path(), mesh);
    writer.write_frame(make_frame(mesh, 0));
  }
  const fs::path h5 = dir.path() / "results.h5";
  auto refused = [&](const std::string& words) {
    try {
      ResultReader reader(h5);
      ADD_FAILURE() << "read without error";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find(h5.string()), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(words), std::string::npos) << e.what();
    }
  };
  {  // quad_thickness with one value too few
    const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "/mesh/quad_thickness", H5P_DEFAULT), 0);
    const hsize_t n = kQuads - 1;
    const hid_t space = H5Screate_simple(1, &n, nullptr);
    const hid_t d = H5Dcreate2(f, "/mesh/quad_thickness", H5T_IEEE_F64LE, space, H5P_DEFAULT,
                               H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(
        H5Dwrite(d, H5T_NATIVE_DOUBLE, H5S_ALL, H5S_ALL, H5P_DEFAULT, mesh.quad_thickness.data()),
        0);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  refused("quad_thickness has 5 entries for 6 shells");
  {
    const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "/mesh/quad_part", H5P_DEFAULT), 0);
    H5Fclose(f);
  }
  refused("without '/mesh/quad_part'");
  {  // quad4 as [n * 2, 2]
    const hid_t f = H5Fopen(h5.c_str(), H5F_ACC_RDWR, H5P_DEFAULT);
    ASSERT_GE(f, 0);
    ASSERT_GE(H5Ldelete(f, "/mesh/quad4", H5P_DEFAULT), 0);
    const hsize_t dims[2] = {2 * kQuads, 2};
    const hid_t space = H5Screate_simple(2, dims, nullptr);
    const hid_t d =
        H5Dcreate2(f, "/mesh/quad4", H5T_STD_I64LE, space, H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT);
    ASSERT_GE(
        H5Dwrite(d, H5T_NATIVE_INT64, H5S_ALL, H5S_ALL, H5P_DEFAULT, mesh.shells().conn.data()), 0);
    H5Dclose(d);
    H5Sclose(space);
    H5Fclose(f);
  }
  refused("'/mesh/quad4' is not [n_quad, 4]");
}

}  // namespace
