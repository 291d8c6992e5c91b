// VtuSeriesWriter: frames/frame_NNNNN.vtu through vtkXMLUnstructuredGridWriter + results.pvd.
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkDoubleArray.h>
#include <vtkErrorCode.h>
#include <vtkIdTypeArray.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkUnstructuredGrid.h>
#include <vtkXMLUnstructuredGridWriter.h>

#include <cstdio>
#include <sstream>
#include <stdexcept>
#include <utility>

#include "fem/io/io_detail.hpp"
#include "fem/io/result_writers.hpp"

namespace ncfsim::fem::io {

namespace {

constexpr int kVtuFrameDigits = 5;
constexpr const char* kPvdName = "results.pvd";
constexpr const char* kFramesDir = "frames";

vtkSmartPointer<vtkDoubleArray> make_array(const std::string& name, int n_components,
                                           std::size_t n_tuples, const double* values) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name.c_str());
  a->SetNumberOfComponents(n_components);
  a->SetNumberOfTuples(static_cast<vtkIdType>(n_tuples));
  const std::size_t n = n_tuples * static_cast<std::size_t>(n_components);
  double* dst = a->GetPointer(0);
  for (std::size_t i = 0; i < n; ++i) dst[i] = values[i];
  return a;
}

}  // namespace

struct VtuSeriesWriter::Impl {
  struct Entry {
    double time;
    std::string file;  // relative to dir
  };
  std::filesystem::path dir, frames_dir, pvd;
  ResultMesh mesh;
  std::vector<Entry> entries;
  bool closed = false;

  // Mesh topology, built once and shared by every frame's grid.
  vtkSmartPointer<vtkCellArray> cells;
  vtkSmartPointer<vtkUnsignedCharArray> cell_types;
  vtkSmartPointer<vtkIntArray> part_id;

  void build_topology();
  std::string pvd_text() const;
  std::string frame_name(std::size_t index) const {
    return std::string("frame_") + detail::zero_padded(index, kVtuFrameDigits) + ".vtu";
  }
};

static_assert(element_output(ElementKind::Hex8).vtk_cell_type == VTK_HEXAHEDRON &&
              element_output(ElementKind::Bar2).vtk_cell_type == VTK_LINE &&
              element_output(ElementKind::Quad4).vtk_cell_type == VTK_QUAD);

void VtuSeriesWriter::Impl::build_topology() {
  const std::size_t n_cells = mesh.n_cells();
  std::size_t n_ids = 0;
  for (const ResultCells& kc : mesh.cells) n_ids += kc.conn.size();

  vtkNew<vtkIdTypeArray> offsets;
  offsets->SetNumberOfValues(static_cast<vtkIdType>(n_cells + 1));
  vtkNew<vtkIdTypeArray> connectivity;
  connectivity->SetNumberOfValues(static_cast<vtkIdType>(n_ids));
  cell_types = vtkSmartPointer<vtkUnsignedCharArray>::New();
  cell_types->SetNumberOfValues(static_cast<vtkIdType>(n_cells));
  part_id = vtkSmartPointer<vtkIntArray>::New();
  part_id->SetName("part_id");
  part_id->SetNumberOfValues(static_cast<vtkIdType>(n_cells));

  vtkIdType c = 0, k = 0;
  offsets->SetValue(0, 0);
  for (ElementKind kind : kElementKinds) {
    const ResultCells& kc = mesh.of(kind);
    const auto nodes = static_cast<std::size_t>(nodes_per_element(kind));
    const auto type = static_cast<unsigned char>(element_output(kind).vtk_cell_type);
    for (std::size_t e = 0; e < mesh.n_of(kind); ++e, ++c) {
      for (std::size_t j = 0; j < nodes; ++j) connectivity->SetValue(k++, kc.conn[nodes * e + j]);
      offsets->SetValue(c + 1, k);
      cell_types->SetValue(c, type);
      part_id->SetValue(c, kc.part[e]);
    }
  }
  cells = vtkSmartPointer<vtkCellArray>::New();
  cells->SetData(offsets, connectivity);
}

std::string VtuSeriesWriter::Impl::pvd_text() const {
  std::ostringstream x;
  x << "<?xml version=\"1.0\"?>\n"
    << "<VTKFile type=\"Collection\" version=\"0.1\" byte_order=\"LittleEndian\">\n"
    << "  <Collection>\n";
  for (const Entry& e : entries) {
    x << "    <DataSet timestep=\"" << detail::format_double(e.time)
      << "\" group=\"\" part=\"0\" file=\"" << detail::xml_escape(e.file) << "\"/>\n";
  }
  x << "  </Collection>\n"
    << "</VTKFile>\n";
  return x.str();
}

VtuSeriesWriter::VtuSeriesWriter(std::filesystem::path out_dir, ResultMesh mesh)
    : impl_(std::make_unique<Impl>()) {
  validate_mesh(mesh);
  impl_->dir = std::move(out_dir);
  impl_->frames_dir = impl_->dir / kFramesDir;
  impl_->pvd = impl_->dir / kPvdName;
  impl_->mesh = std::move(mesh);
  std::error_code ec;
  std::filesystem::create_directories(impl_->frames_dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create directory '" + impl_->frames_dir.string() +
                             "': " + ec.message());
  }
  impl_->build_topology();
  // An empty collection replaces any results.pvd of an earlier run before its frames are
  // overwritten.
  detail::atomic_write_text(impl_->pvd, impl_->pvd_text());
}

VtuSeriesWriter::~VtuSeriesWriter() = default;
VtuSeriesWriter::VtuSeriesWriter(VtuSeriesWriter&&) noexcept = default;
VtuSeriesWriter& VtuSeriesWriter::operator=(VtuSeriesWriter&&) noexcept = default;

void VtuSeriesWriter::write_frame(const Frame& frame) {
  if (!impl_) throw std::logic_error("VtuSeriesWriter: write_frame on a moved-from writer");
  if (impl_->closed) {
    throw std::logic_error("VtuSeriesWriter: write_frame after close() for '" +
                           impl_->pvd.string() + "'");
  }
  const ResultMesh& mesh = impl_->mesh;
  validate_frame(mesh, frame);
  const std::size_t n_points = mesh.n_points();
  const std::size_t n_cells = mesh.n_cells();  // hexes, bars, shells: the order of the cell fields

  const std::vector<double> x = detail::current_coordinates(mesh, frame);
  vtkNew<vtkPoints> points;
  points->SetData(make_array("Points", 3, n_points, x.data()));

  vtkNew<vtkUnstructuredGrid> grid;
  grid->SetPoints(points);
  grid->SetCells(impl_->cell_types, impl_->cells);
  grid->GetPointData()->AddArray(
      make_array("displacement", 3, n_points, frame.displacement.data()));
  grid->GetCellData()->AddArray(impl_->part_id);
  for (const FrameField& f : frame.fields) {
    const std::size_t n = f.on_cells ? n_cells : n_points;
    auto a = make_array(f.name, f.n_components, n, f.values.data());
    if (f.on_cells) {
      grid->GetCellData()->AddArray(a);
    } else {
      grid->GetPointData()->AddArray(a);
    }
  }

  const std::string name = impl_->frame_name(impl_->entries.size());
  const std::filesystem::path target = impl_->frames_dir / name;
  std::filesystem::path tmp = target;
  tmp += ".tmp";

  vtkNew<vtkXMLUnstructuredGridWriter> writer;
  writer->SetInputData(grid);
  writer->SetFileName(tmp.c_str());
  writer->SetDataModeToAppended();
  writer->EncodeAppendedDataOff();  // raw binary
  writer->SetCompressorTypeToZLib();
  writer->SetHeaderTypeToUInt64();
  writer->SetIdTypeToInt64();
  if (writer->Write() != 1 || writer->GetErrorCode() != vtkErrorCode::NoError) {
    const unsigned long code = writer->GetErrorCode();
    std::remove(tmp.c_str());
    throw std::runtime_error("vtkXMLUnstructuredGridWriter failed for '" + target.string() +
                             "': " + vtkErrorCode::GetStringFromErrorCode(code));
  }
  try {
    detail::fsync_file(tmp);
    detail::rename_replace(tmp, target);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
  impl_->entries.push_back({frame.time, std::string(kFramesDir) + "/" + name});
  try {
    detail::atomic_write_text(impl_->pvd, impl_->pvd_text());
  } catch (...) {
    impl_->entries.pop_back();
    throw;
  }
}

void VtuSeriesWriter::close() {
  if (impl_) impl_->closed = true;
}

void VtuSeriesWriter::keep_frames(const std::vector<double>& times) {
  if (!impl_) throw std::logic_error("VtuSeriesWriter: keep_frames on a moved-from writer");
  impl_->entries.clear();
  for (std::size_t k = 0; k < times.size(); ++k) {
    const std::string name = impl_->frame_name(k);
    if (!std::filesystem::is_regular_file(impl_->frames_dir / name))
      throw std::runtime_error("frame file '" + (impl_->frames_dir / name).string() +
                               "' of the resumed run is missing");
    impl_->entries.push_back({times[k], std::string(kFramesDir) + "/" + name});
  }
  for (std::size_t k = times.size();; ++k) {
    std::error_code ec;
    if (!std::filesystem::remove(impl_->frames_dir / impl_->frame_name(k), ec)) break;
  }
  detail::atomic_write_text(impl_->pvd, impl_->pvd_text());
}

std::size_t VtuSeriesWriter::frames_written() const { return impl_ ? impl_->entries.size() : 0; }
std::filesystem::path VtuSeriesWriter::frame_path(std::size_t index) const {
  return impl_->frames_dir / impl_->frame_name(index);
}

}  // namespace ncfsim::fem::io
