// Off-screen figures with stock Debian VTK 9.1 on an OSMesa or a Mesa EGL surfaceless context.
//
// How it works (see /work/shared/rendering.md): make_gl_context makes a desktop-GL core context
// current (OSMesa or EGL, gl_context.hpp; the executable's GL entry points send VTK's calls to it,
// gl_forward.cpp); vtkGenericOpenGLRenderWindow is told that it is current and renders into it; the
// pixels come back through vtkWindowToImageFilter and are PNG-encoded in memory, written to a
// temporary file beside the destination and renamed over it. VTK calls glewInit, which the
// executable overrides (glew_shim.cpp) so that Debian's GLX-only GLEW does not fail.
//
// Layout of a mesh figure (fractions of the image, origin bottom-left): the model is drawn in the
// viewport [0, 0.82] x [0, 0.92]; the scalar bar stands at the right in [0.85, 0.985] x
// [0.06, 0.84] with its title above it; the figure title is centred at the top.
#include "render.hpp"

#include <unistd.h>
#include <vtkActor.h>
#include <vtkAxis.h>
#include <vtkBrush.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellType.h>
#include <vtkChartLegend.h>
#include <vtkChartXY.h>
#include <vtkCommand.h>
#include <vtkContextActor.h>
#include <vtkContextScene.h>
#include <vtkDoubleArray.h>
#include <vtkGenericOpenGLRenderWindow.h>
#include <vtkImageData.h>
#include <vtkLookupTable.h>
#include <vtkMath.h>
#include <vtkNew.h>
#include <vtkPNGWriter.h>
#include <vtkPen.h>
#include <vtkPlot.h>
#include <vtkPlotPoints.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSmartPointer.h>
#include <vtkTable.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkUnsignedCharArray.h>
#include <vtkVariant.h>
#include <vtkWindowToImageFilter.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <fstream>
#include <limits>
#include <memory>
#include <mutex>
#include <stdexcept>
#include <system_error>
#include <unordered_map>

#include "fem/elements/element_kind.hpp"
#include "gl_context.hpp"

// Defined in glew_shim.cpp. Referencing the marker makes the linker pull the shim's object file
// out of the static library into every executable that renders.
extern "C" const int ncfsim_render_glew_shim_marker;
extern "C" int ncfsim_render_glew_shim_active(void);

namespace ncfsim::render {
namespace {

// One render at a time per process: GLEW's function pointers, the GL routing (gl_forward.cpp) and
// the EGL display are global.
std::mutex& render_mutex() {
  static std::mutex m;
  return m;
}

constexpr double kBackground[3] = {1.0, 1.0, 1.0};
constexpr double kText[3] = {0.0, 0.0, 0.0};

[[noreturn]] void fail(const std::string& where, const std::string& what) {
  throw std::runtime_error(where + ": " + what);
}

// Collects VTK ErrorEvents of the objects it observes (instead of VTK printing them).
class VtkErrors {
 public:
  VtkErrors() {
    callback_->SetClientData(this);
    callback_->SetCallback([](vtkObject* caller, unsigned long, void* client, void* call) {
      auto* self = static_cast<VtkErrors*>(client);
      std::string text = call != nullptr ? static_cast<const char*>(call) : "unknown VTK error";
      while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) {
        text.pop_back();
      }
      self->messages_.push_back(std::string(caller != nullptr ? caller->GetClassName() : "vtk") +
                                ": " + text);
    });
  }
  void watch(vtkObject* object) { object->AddObserver(vtkCommand::ErrorEvent, callback_); }
  void throw_if_any(const std::string& where) const {
    if (messages_.empty()) {
      return;
    }
    std::string all;
    for (const auto& m : messages_) {
      all += (all.empty() ? "" : "; ") + m;
    }
    fail(where, "VTK reported an error: " + all);
  }

 private:
  vtkNew<vtkCallbackCommand> callback_;
  std::vector<std::string> messages_;
};

void check_shim(const std::string& where) {
  // Reading the marker keeps the reference alive under any optimisation level.
  if (ncfsim_render_glew_shim_marker != 1 || ncfsim_render_glew_shim_active() == 0) {
    fail(where,
         "the glewInit shim is not the process-wide glewInit, so VTK would reject the context "
         "(GLEW_ERROR_NO_GLX_DISPLAY); build the executable with the CMake function "
         "ncfsim_enable_offscreen_rendering(<target>) (ENABLE_EXPORTS ON)");
  }
}

void check_size(const std::string& where, int width, int height) {
  constexpr int kMax = 16384;
  if (width < 16 || height < 16 || width > kMax || height > kMax) {
    fail(where, "image size " + std::to_string(width) + "x" + std::to_string(height) +
                    " out of range [16, " + std::to_string(kMax) + "]");
  }
}

std::filesystem::path temp_path_for(const std::filesystem::path& png) {
  static std::atomic<unsigned> counter{0};
  // Built by appending (GCC 12 gives a false -Wrestrict on "." + std::string).
  std::string name(".");
  name.append(png.filename().string());
  name.append(".tmp-").append(std::to_string(::getpid()));
  name.append("-").append(std::to_string(counter.fetch_add(1)));
  return png.parent_path() / name;
}

// PNG-encodes the image in memory, writes it beside the destination, then renames it over it.
void write_png_atomically(vtkImageData* image, const std::filesystem::path& png,
                          const std::string& where) {
  if (png.filename().empty()) {
    fail(where, "output path '" + png.string() + "' names no file");
  }
  vtkNew<vtkPNGWriter> writer;
  VtkErrors errors;
  errors.watch(writer);
  writer->SetCompressionLevel(6);
  writer->WriteToMemoryOn();
  writer->SetInputData(image);
  writer->Write();
  errors.throw_if_any(where);
  vtkUnsignedCharArray* bytes = writer->GetResult();
  if (bytes == nullptr || bytes->GetNumberOfValues() == 0) {
    fail(where, "PNG encoding produced no data");
  }

  std::error_code ec;
  if (!png.parent_path().empty()) {
    std::filesystem::create_directories(png.parent_path(), ec);
    if (ec) {
      fail(where, "cannot create folder '" + png.parent_path().string() + "': " + ec.message());
    }
  }
  const std::filesystem::path tmp = temp_path_for(png);
  {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      fail(where, "cannot open '" + tmp.string() + "' for writing");
    }
    out.write(reinterpret_cast<const char*>(bytes->GetPointer(0)),
              static_cast<std::streamsize>(bytes->GetNumberOfValues()));
    out.close();
    if (!out) {
      std::filesystem::remove(tmp, ec);
      fail(where, "writing '" + tmp.string() + "' failed");
    }
  }
  std::filesystem::rename(tmp, png, ec);
  if (ec) {
    std::error_code ignored;
    std::filesystem::remove(tmp, ignored);
    fail(where, "cannot rename '" + tmp.string() + "' to '" + png.string() + "': " + ec.message());
  }
}

// An OpenGL context plus a VTK window that renders into it. Renderers are added by the caller;
// capture() renders and returns a copy of the RGB pixels.
class OffscreenWindow {
 public:
  OffscreenWindow(int width, int height, const std::string& where)
      : where_(where), context_(detail::make_gl_context(width, height)) {
    check_shim(where_);
    window_->SetSize(width, height);
    window_->SetIsCurrent(true);  // make_gl_context made it current on this thread
    window_->SetReadyForRendering(true);
    window_->SetSupportsOpenGL(1);
    window_->SetIsDirect(1);
    window_->SetMapped(1);
    window_->SetMultiSamples(4);  // MSAA on llvmpipe: smooth edges, deterministic
    window_->SetAlphaBitPlanes(0);
    errors_.watch(window_);
  }
  ~OffscreenWindow() {
    // Release VTK's GL objects while the context is still current (context_ dies after this).
    window_->Finalize();
  }
  OffscreenWindow(const OffscreenWindow&) = delete;
  OffscreenWindow& operator=(const OffscreenWindow&) = delete;

  vtkGenericOpenGLRenderWindow* window() { return window_; }
  VtkErrors& errors() { return errors_; }

  vtkSmartPointer<vtkImageData> capture() {
    window_->Render();
    errors_.throw_if_any(where_);
    vtkNew<vtkWindowToImageFilter> grab;
    errors_.watch(grab);
    grab->SetInput(window_);
    grab->SetInputBufferTypeToRGB();
    grab->ReadFrontBufferOff();
    grab->ShouldRerenderOff();
    grab->Update();
    errors_.throw_if_any(where_);
    auto image = vtkSmartPointer<vtkImageData>::New();
    image->DeepCopy(grab->GetOutput());
    int dims[3] = {0, 0, 0};
    image->GetDimensions(dims);
    const int* size = window_->GetSize();
    if (dims[0] != size[0] || dims[1] != size[1]) {
      fail(where_, "read back a " + std::to_string(dims[0]) + "x" + std::to_string(dims[1]) +
                       " image from a " + std::to_string(size[0]) + "x" + std::to_string(size[1]) +
                       " window");
    }
    return image;
  }

 private:
  std::string where_;
  std::unique_ptr<detail::GlContext> context_;  // declared before the VTK objects: destroyed after
  VtkErrors errors_;
  vtkNew<vtkGenericOpenGLRenderWindow> window_;
};

// VTK's built-in "Arial" on Debian draws '[' and ']' as round brackets, which garbles units; use
// DejaVu Sans (fonts-dejavu-core, a dependency of fontconfig and so of VTK) when it is installed.
const char* dejavu_sans(bool bold) {
  static const bool have =
      std::filesystem::exists("/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf") &&
      std::filesystem::exists("/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf");
  if (!have) {
    return nullptr;
  }
  return bold ? "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf"
              : "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf";
}

void style_text(vtkTextProperty* p, int font_size, bool bold) {
  if (const char* file = dejavu_sans(bold); file != nullptr) {
    p->SetFontFamily(VTK_FONT_FILE);
    p->SetFontFile(file);
  } else {
    p->SetFontFamilyToArial();
  }
  p->SetFontSize(font_size);
  p->SetBold(bold ? 1 : 0);
  p->SetItalic(0);
  p->SetShadow(0);
  p->SetColor(kText[0], kText[1], kText[2]);
  p->SetOpacity(1.0);
}

int scaled_font(int height, double fraction, int minimum) {
  return std::max(minimum, static_cast<int>(std::lround(fraction * height)));
}

// ----------------------------------------------------------------------------------------------
// Mesh figures

struct Scalars {
  std::vector<double> values;  // one per point (on_cells = false) or per cell: hexes, bars, shells
  bool on_cells = false;
  std::string bar_title;  // "name [unit]", "name (x) [unit]", "name (magnitude) [unit]"
};

void validate_mesh(const RenderMesh& mesh, const std::string& where) {
  if (mesh.points.empty() || mesh.points.size() % 3 != 0) {
    fail(where, "points must hold 3 coordinates per node and at least one node, got " +
                    std::to_string(mesh.points.size()) + " values");
  }
  const auto n_points = static_cast<std::int64_t>(mesh.points.size() / 3);
  for (fem::ElementKind k : fem::kElementKinds) {
    const auto& ids = mesh.of(k);
    const std::string name = fem::element_kind_name(k);
    const int nodes = fem::nodes_per_element(k);
    if (ids.size() % static_cast<std::size_t>(nodes) != 0) {
      fail(where, name + " must hold " + std::to_string(nodes) + " node ids per " +
                      fem::element_noun(k) + ", got " + std::to_string(ids.size()) + " ids");
    }
    for (std::size_t i = 0; i < ids.size(); ++i) {
      if (ids[i] < 0 || ids[i] >= n_points) {
        fail(where, name + " entry " + std::to_string(i) + " is node id " + std::to_string(ids[i]) +
                        ", outside [0, " + std::to_string(n_points) + ")");
      }
    }
  }
  if (mesh.n_cells() == 0) {
    fail(where, "the mesh has no hexahedra, no bars and no shells");
  }
  for (double c : mesh.points) {
    if (!std::isfinite(c)) {
      fail(where, "a node coordinate is not finite");
    }
  }
}

std::string component_name(int component, int n_components) {
  if (n_components <= 3) {
    return std::string(1, "xyz"[component]);
  }
  return std::to_string(component);
}

Scalars select_scalars(const RenderMesh& mesh, const MeshFigure& figure, const std::string& where) {
  const MeshField* field = nullptr;
  for (const auto& f : mesh.fields) {
    if (f.name == figure.field) {
      field = &f;
      break;
    }
  }
  if (field == nullptr) {
    std::string names;
    for (const auto& f : mesh.fields) {
      names += (names.empty() ? "" : ", ") + f.name;
    }
    fail(where, "unknown field '" + figure.field +
                    "' (the mesh has: " + (names.empty() ? std::string("no fields") : names) + ")");
  }
  const int n_comp = field->n_components;
  if (n_comp < 1) {
    fail(where, "field '" + field->name + "' has n_components = " + std::to_string(n_comp));
  }
  if (figure.component < -1 || figure.component >= n_comp) {
    fail(where, "component " + std::to_string(figure.component) + " of field '" + field->name +
                    "' out of range [-1, " + std::to_string(n_comp - 1) + "]");
  }
  const std::size_t n_entities = field->on_cells ? mesh.n_cells() : mesh.points.size() / 3;
  if (field->values.size() != n_entities * static_cast<std::size_t>(n_comp)) {
    fail(where, "field '" + field->name + "' has " + std::to_string(field->values.size()) +
                    " values, expected " + std::to_string(n_entities) + " " +
                    (field->on_cells ? "cells" : "points") + " x " + std::to_string(n_comp) +
                    " components");
  }

  Scalars s;
  s.on_cells = field->on_cells;
  s.values.resize(n_entities);
  for (std::size_t i = 0; i < n_entities; ++i) {
    const double* v = field->values.data() + i * static_cast<std::size_t>(n_comp);
    if (figure.component >= 0) {
      s.values[i] = v[figure.component];
    } else if (n_comp == 1) {
      s.values[i] = v[0];
    } else {
      double sum = 0.0;
      for (int c = 0; c < n_comp; ++c) {
        sum += v[c] * v[c];
      }
      s.values[i] = std::sqrt(sum);
    }
  }
  s.bar_title = field->name;
  if (n_comp > 1) {
    s.bar_title += figure.component < 0 ? " (magnitude)"
                                        : " (" + component_name(figure.component, n_comp) + ")";
  }
  if (!field->unit.empty()) {
    s.bar_title += " [" + field->unit + "]";
  }
  return s;
}

std::array<double, 2> colour_range(const Scalars& s, const MeshFigure& figure,
                                   const std::string& where) {
  double lo = 0.0, hi = 0.0;
  if (figure.range) {
    lo = (*figure.range)[0];
    hi = (*figure.range)[1];
    if (!std::isfinite(lo) || !std::isfinite(hi) || lo > hi) {
      fail(where, "colour range [" + std::to_string(lo) + ", " + std::to_string(hi) +
                      "] must be finite with min <= max");
    }
  } else {
    lo = std::numeric_limits<double>::infinity();
    hi = -lo;
    for (double v : s.values) {
      if (std::isfinite(v)) {
        lo = std::min(lo, v);
        hi = std::max(hi, v);
      }
    }
    if (lo > hi) {  // no finite value at all
      lo = 0.0;
      hi = 1.0;
    }
  }
  if (hi <= lo) {  // a uniform field: centre it in a small range so it maps to the middle colour
    const double pad = lo != 0.0 ? 0.01 * std::abs(lo) : 1.0;
    lo -= pad;
    hi += pad;
  }
  return {lo, hi};
}

// Blue (low) to red (high) through cyan, green, yellow: the usual FE contour map.
vtkSmartPointer<vtkLookupTable> make_lookup_table(const std::array<double, 2>& range) {
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  lut->SetNumberOfTableValues(256);
  lut->SetHueRange(0.6667, 0.0);
  lut->SetSaturationRange(1.0, 1.0);
  lut->SetValueRange(1.0, 1.0);
  lut->SetNanColor(0.5, 0.5, 0.5, 1.0);
  lut->SetTableRange(range[0], range[1]);
  lut->Build();
  return lut;
}

vtkSmartPointer<vtkDoubleArray> make_array(const std::string& name, const double* values,
                                           std::size_t n) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name.c_str());
  a->SetNumberOfComponents(1);
  a->SetNumberOfTuples(static_cast<vtkIdType>(n));
  std::copy(values, values + n, a->GetPointer(0));
  return a;
}

void apply_camera(vtkRenderer* renderer, CameraPreset preset,
                  const std::optional<std::array<double, 6>>& focus) {
  vtkCamera* camera = renderer->GetActiveCamera();
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  switch (preset) {
    case CameraPreset::Top:
      camera->SetPosition(0.0, 0.0, 1.0);
      camera->SetViewUp(0.0, 1.0, 0.0);
      break;
    case CameraPreset::Front:
      camera->SetPosition(0.0, -1.0, 0.0);
      camera->SetViewUp(0.0, 0.0, 1.0);
      break;
    case CameraPreset::Iso:
      // Not the exact (1, -1, 1) diagonal: under the headlight its three visible faces of a box
      // would get the same brightness and merge into one flat shape.
      // Looking down at about 44 degrees so that top faces (sheets, drapes) are the brightest.
      camera->SetPosition(1.0, -1.2, 1.5);
      camera->SetViewUp(0.0, 0.0, 1.0);
      break;
  }
  camera->ParallelProjectionOn();
  if (focus) {
    double b[6];
    std::copy(focus->begin(), focus->end(), b);
    renderer->ResetCamera(b);  // fits the focus box (a followed part), keeps the direction
  } else {
    renderer->ResetCamera();  // keeps the direction, fits the bounds
  }
  renderer->ResetCameraClippingRange();
}

// Boundary faces of the hexahedra: the faces that belong to exactly one hexahedron, as quads
// in VTK's outward face ordering, each with the index of its hexahedron. Done here rather than
// with vtkDataSetSurfaceFilter / vtkGeometryFilter, whose VTK 9.1 versions leak an allocation
// per call (vtkGeometryFilterHelper::CharacterizeUnstructuredGrid), which fails ASan builds.
struct BoundaryQuads {
  std::vector<vtkIdType> nodes;  // [4 * n_faces]
  std::vector<std::size_t> hex;  // [n_faces]
};

BoundaryQuads boundary_quads(const std::vector<std::int64_t>& hex8) {
  constexpr const auto& kFaces = fem::kHex8Faces;
  struct Key {
    std::array<std::int64_t, 4> sorted;
    bool operator==(const Key& o) const { return sorted == o.sorted; }
  };
  struct KeyHash {
    std::size_t operator()(const Key& k) const {
      std::uint64_t h = 1469598103934665603ULL;
      for (std::int64_t v : k.sorted) {
        h = (h ^ static_cast<std::uint64_t>(v)) * 1099511628211ULL;
      }
      return static_cast<std::size_t>(h ^ (h >> 29));
    }
  };
  const std::size_t n_hex = hex8.size() / 8;
  // face id (6 * hex + local face) of the first occurrence, and how often the face was seen
  std::unordered_map<Key, std::pair<std::size_t, int>, KeyHash> seen;
  seen.reserve(3 * n_hex + 16);
  for (std::size_t e = 0; e < n_hex; ++e) {
    for (int f = 0; f < 6; ++f) {
      Key key;
      for (int k = 0; k < 4; ++k) {
        key.sorted[k] = hex8[8 * e + kFaces[f].corner[k]];
      }
      std::sort(key.sorted.begin(), key.sorted.end());
      auto [it, inserted] = seen.try_emplace(key, 6 * e + f, 0);
      ++it->second.second;
    }
  }
  std::vector<std::size_t> boundary;
  for (const auto& [key, value] : seen) {
    if (value.second == 1) {
      boundary.push_back(value.first);
    }
  }
  std::sort(boundary.begin(), boundary.end());  // deterministic order, independent of hashing
  BoundaryQuads out;
  out.nodes.reserve(4 * boundary.size());
  out.hex.reserve(boundary.size());
  for (std::size_t id : boundary) {
    const std::size_t e = id / 6;
    const int f = static_cast<int>(id % 6);
    for (int k = 0; k < 4; ++k) {
      out.nodes.push_back(static_cast<vtkIdType>(hex8[8 * e + kFaces[f].corner[k]]));
    }
    out.hex.push_back(e);
  }
  return out;
}

}  // namespace

RenderMesh without_cells(const RenderMesh& mesh, const std::vector<char>& drop) {
  const std::size_t n_cells = mesh.n_cells();
  if (drop.size() != n_cells) {
    std::string counts;
    for (fem::ElementKind k : fem::kElementKinds)
      counts += (counts.empty() ? "" : ", ") + std::to_string(mesh.n_of(k)) + " " +
                fem::element_plural(k);
    throw std::invalid_argument("without_cells: " + std::to_string(drop.size()) + " flags for " +
                                std::to_string(n_cells) + " cells (" + counts + ")");
  }
  RenderMesh out;
  out.points = mesh.points;
  // Each kind's kept cells, whose flags are drop[first .. first + count).
  for (fem::ElementKind k : fem::kElementKinds) {
    const auto& from = mesh.of(k);
    const auto n_nodes = static_cast<std::size_t>(fem::nodes_per_element(k));
    const std::size_t first = mesh.first_cell(k);
    for (std::size_t e = 0; e < mesh.n_of(k); ++e)
      if (!drop[first + e])
        out.of(k).insert(out.of(k).end(), from.begin() + static_cast<std::ptrdiff_t>(n_nodes * e),
                         from.begin() + static_cast<std::ptrdiff_t>(n_nodes * (e + 1)));
  }
  for (const auto& f : mesh.fields) {
    if (!f.on_cells) {
      out.fields.push_back(f);
      continue;
    }
    MeshField g{f.name, f.unit, true, f.n_components, {}};
    const auto nc = static_cast<std::size_t>(std::max(f.n_components, 0));
    // A field of the wrong size is kept as far as it goes (render_mesh_png names the mismatch).
    for (std::size_t c = 0; c < n_cells && nc * (c + 1) <= f.values.size(); ++c)
      if (!drop[c])
        g.values.insert(g.values.end(), f.values.begin() + static_cast<std::ptrdiff_t>(nc * c),
                        f.values.begin() + static_cast<std::ptrdiff_t>(nc * (c + 1)));
    out.fields.push_back(std::move(g));
  }
  return out;
}

RenderMesh without_hexes(const RenderMesh& mesh, const std::vector<char>& drop) {
  const std::size_t n_hex = mesh.n_of(fem::ElementKind::Hex8);
  if (drop.size() != n_hex)
    throw std::invalid_argument("without_hexes: " + std::to_string(drop.size()) + " flags for " +
                                std::to_string(n_hex) + " hexahedra");
  std::vector<char> cells(drop);
  cells.resize(mesh.n_cells(), 0);
  return without_cells(mesh, cells);
}

namespace {

// One colour per category (the first, "none", light grey), named on the bar.
vtkSmartPointer<vtkLookupTable> category_lookup_table(const std::vector<std::string>& categories,
                                                      const std::array<double, 2>& range) {
  const auto n = static_cast<vtkIdType>(categories.size());
  auto lut = vtkSmartPointer<vtkLookupTable>::New();
  lut->SetNumberOfTableValues(n);
  lut->SetTableRange(range[0], range[1]);
  lut->Build();
  for (vtkIdType k = 0; k < n; ++k) {
    if (k == 0) {
      lut->SetTableValue(0, 0.85, 0.85, 0.85, 1.0);
    } else {
      double rgb[3];
      const double h =
          n > 2 ? 0.6667 * (1.0 - static_cast<double>(k - 1) / static_cast<double>(n - 2)) : 0.0;
      vtkMath::HSVToRGB(h, 1.0, 1.0, rgb, rgb + 1, rgb + 2);
      lut->SetTableValue(k, rgb[0], rgb[1], rgb[2], 1.0);
    }
    lut->SetAnnotation(vtkVariant(static_cast<double>(k)), categories[static_cast<std::size_t>(k)]);
  }
  lut->IndexedLookupOn();
  return lut;
}

// What the three kinds' actors share: the points, the colouring and its field.
struct MeshColouring {
  MeshColouring(const MeshFigure& f, const Scalars& s)
      : figure(f), coloured(!f.field.empty()), scalars(s) {}
  const MeshFigure& figure;
  bool coloured = false;
  const Scalars& scalars;
  std::array<double, 2> range{0.0, 1.0};
  vtkSmartPointer<vtkLookupTable> lut;
  vtkSmartPointer<vtkDoubleArray> point_scalars;  // a nodal field (null: a cell field or none)
  vtkSmartPointer<vtkPoints> points;

  void configure(vtkPolyDataMapper* mapper) const {
    if (!coloured) {
      mapper->ScalarVisibilityOff();
      return;
    }
    mapper->ScalarVisibilityOn();
    mapper->SetColorModeToMapScalars();
    mapper->SetLookupTable(lut);
    mapper->UseLookupTableScalarRangeOff();
    mapper->SetScalarRange(range[0], range[1]);
    if (scalars.on_cells) {
      mapper->SetScalarModeToUseCellData();
    } else {
      mapper->SetScalarModeToUsePointData();
      mapper->InterpolateScalarsBeforeMappingOn();  // colour bands follow the map, not RGB blends
    }
  }
  // The field on `poly`: the nodal array, or the cell field's values first_cell.. (+n).
  void colour(vtkPolyData* poly, std::size_t first_cell, std::size_t n) const {
    if (point_scalars)
      poly->GetPointData()->SetScalars(point_scalars);
    else if (coloured)
      poly->GetCellData()->SetScalars(
          make_array(figure.field, scalars.values.data() + first_cell, n));
  }
  vtkSmartPointer<vtkActor> actor_of(vtkPolyData* poly) const {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputData(poly);
    configure(mapper);
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(mapper);
    return actor;
  }
  // A lit surface (the hexahedra's faces, the shells): faces facing the camera show the colour
  // map's exact colours (0.25 + 0.75 = 1); oblique faces in the Iso view keep 60-80 % of their
  // brightness; the renderer's two-sided lighting (VTK's default) lights a shell seen from below
  // as one seen from above.
  vtkSmartPointer<vtkActor> surface_actor_of(vtkPolyData* poly) const {
    auto actor = actor_of(poly);
    vtkProperty* p = actor->GetProperty();
    p->SetAmbient(0.25);
    p->SetDiffuse(0.75);
    p->SetSpecular(0.0);
    if (!coloured) {
      p->SetColor(0.78, 0.80, 0.84);
    }
    return actor;
  }
};

// The hexahedra's boundary quads (the hexahedra are the first cells).
vtkSmartPointer<vtkActor> solid_actor(const RenderMesh& mesh, const MeshColouring& c) {
  const BoundaryQuads quads = boundary_quads(mesh.of(fem::ElementKind::Hex8));
  const auto n_faces = static_cast<vtkIdType>(quads.hex.size());
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(n_faces, 4 * n_faces);
  for (vtkIdType f = 0; f < n_faces; ++f) {
    polys->InsertNextCell(4, quads.nodes.data() + 4 * f);
  }
  vtkNew<vtkPolyData> solid;
  solid->SetPoints(c.points);
  solid->SetPolys(polys);
  if (c.point_scalars) {
    solid->GetPointData()->SetScalars(c.point_scalars);
  } else if (c.coloured) {  // each face its hexahedron's value
    std::vector<double> face_values(quads.hex.size());
    for (std::size_t f = 0; f < quads.hex.size(); ++f) {
      face_values[f] = c.scalars.values[quads.hex[f]];
    }
    solid->GetCellData()->SetScalars(
        make_array(c.figure.field, face_values.data(), face_values.size()));
  }
  return c.surface_actor_of(solid);
}

// The shells' mid-surfaces.
vtkSmartPointer<vtkActor> shell_actor(const RenderMesh& mesh, const MeshColouring& c) {
  const auto& quad4 = mesh.of(fem::ElementKind::Quad4);
  const std::size_t n_quad = mesh.n_of(fem::ElementKind::Quad4);
  vtkNew<vtkCellArray> polys;
  polys->AllocateExact(static_cast<vtkIdType>(n_quad), static_cast<vtkIdType>(4 * n_quad));
  for (std::size_t q = 0; q < n_quad; ++q) {
    vtkIdType ids[4];
    for (std::size_t k = 0; k < 4; ++k) {
      ids[k] = static_cast<vtkIdType>(quad4[4 * q + k]);
    }
    polys->InsertNextCell(4, ids);
  }
  vtkNew<vtkPolyData> shells;
  shells->SetPoints(c.points);
  shells->SetPolys(polys);
  c.colour(shells, mesh.first_cell(fem::ElementKind::Quad4), n_quad);
  return c.surface_actor_of(shells);
}

// The bars, as lines.
vtkSmartPointer<vtkActor> bar_actor(const RenderMesh& mesh, const MeshColouring& c) {
  const auto& bar2 = mesh.of(fem::ElementKind::Bar2);
  const std::size_t n_bar = mesh.n_of(fem::ElementKind::Bar2);
  vtkNew<vtkCellArray> lines;
  lines->AllocateExact(static_cast<vtkIdType>(n_bar), static_cast<vtkIdType>(2 * n_bar));
  for (std::size_t b = 0; b < n_bar; ++b) {
    const vtkIdType ids[2] = {static_cast<vtkIdType>(bar2[2 * b]),
                              static_cast<vtkIdType>(bar2[2 * b + 1])};
    lines->InsertNextCell(2, ids);
  }
  vtkNew<vtkPolyData> bars;
  bars->SetPoints(c.points);
  bars->SetLines(lines);
  c.colour(bars, mesh.first_cell(fem::ElementKind::Bar2), n_bar);
  auto actor = c.actor_of(bars);
  // Lines in front of coincident hex faces and shells (bars on a surface stay visible).
  actor->GetMapper()->SetResolveCoincidentTopologyToPolygonOffset();
  vtkProperty* p = actor->GetProperty();
  p->SetLineWidth(std::max(2.0f, static_cast<float>(c.figure.height) / 300.0f));
  p->LightingOff();
  if (!c.coloured) {
    p->SetColor(0.15, 0.15, 0.2);
  }
  return actor;
}

// Each kind's picture, in drawing order: the surfaces, then the lines drawn over them. A new
// element kind adds its row.
struct KindPicture {
  fem::ElementKind kind;
  vtkSmartPointer<vtkActor> (*actor)(const RenderMesh&, const MeshColouring&);
};
constexpr KindPicture kKindPictures[] = {{fem::ElementKind::Hex8, solid_actor},
                                         {fem::ElementKind::Quad4, shell_actor},
                                         {fem::ElementKind::Bar2, bar_actor}};
static_assert(std::size(kKindPictures) == fem::kElementKinds.size(), "a picture per kind");

// The annotation layer's title and scalar bar.
void add_title_and_scalar_bar(vtkRenderer* annotation, const MeshColouring& c) {
  const MeshFigure& figure = c.figure;
  const bool coloured = c.coloured;
  const Scalars& scalars = c.scalars;
  const vtkSmartPointer<vtkLookupTable>& lut = c.lut;
  vtkNew<vtkTextActor> title;
  if (!figure.title.empty()) {
    title->SetInput(figure.title.c_str());
    style_text(title->GetTextProperty(), scaled_font(figure.height, 0.032, 12), true);
    title->GetTextProperty()->SetJustificationToCentered();
    title->GetTextProperty()->SetVerticalJustificationToTop();
    title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    title->GetPositionCoordinate()->SetValue(0.5, 0.985);
    annotation->AddActor2D(title);
  }

  // Scalar bar at the right; its title is a separate text actor right-aligned to the image edge
  // (vtkScalarBarActor centres its title on the bar and would clip long ones at the border). The
  // title may reach left over the model's viewport only in its top-right corner, which lies
  // outside the bounding circle ResetCamera fits the model into, so they never overlap.
  vtkNew<vtkScalarBarActor> bar;
  vtkNew<vtkTextActor> bar_title;
  if (coloured) {
    bar->SetLookupTable(lut);
    bar->SetOrientationToVertical();
    bar->SetNumberOfLabels(6);
    bar->SetMaximumNumberOfColors(256);
    // VTK 9.1 right-aligns the labels 2*min(TextPad, bar/8) - 5 % of a label's width too far
    // right, onto the colour strip, when the font size is unconstrained: keep TextPad at 1 and
    // pad the labels with trailing spaces (they count in the text width).
    bar->SetLabelFormat("%#.4g  ");
    bar->SetTextPad(1);
    bar->SetTextPositionToPrecedeScalarBar();  // labels left of the colour strip
    bar->UnconstrainedFontSizeOn();            // keep the font sizes set below
    style_text(bar->GetLabelTextProperty(), scaled_font(figure.height, 0.019, 9), false);
    bar->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    bar->GetPositionCoordinate()->SetValue(0.85, 0.06);
    bar->GetPosition2Coordinate()->SetCoordinateSystemToNormalizedViewport();
    bar->GetPosition2Coordinate()->SetValue(0.135, 0.78);  // width, height (relative to Position)
    bar->SetBarRatio(0.32);
    if (!figure.categories.empty()) {
      bar->DrawAnnotationsOn();
      bar->SetNumberOfLabels(0);
      bar->SetTextPositionToSucceedScalarBar();  // the names left of the strip, inside the image
      style_text(bar->GetAnnotationTextProperty(), scaled_font(figure.height, 0.019, 9), false);
    }
    annotation->AddActor2D(bar);

    const int title_font = scaled_font(figure.height, 0.022, 10);
    std::string text = scalars.bar_title;
    // Two lines ("name" / "[unit]") when one would be much wider than the bar's column.
    const double column_px = 0.2 * figure.width;
    const auto unit_at = text.rfind(" [");
    if (unit_at != std::string::npos &&
        0.62 * title_font * static_cast<double>(text.size()) > column_px) {
      text[unit_at] = '\n';
    }
    bar_title->SetInput(text.c_str());
    style_text(bar_title->GetTextProperty(), title_font, true);
    bar_title->GetTextProperty()->SetJustificationToRight();
    bar_title->GetTextProperty()->SetVerticalJustificationToTop();
    bar_title->GetTextProperty()->SetLineSpacing(1.05);
    bar_title->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
    bar_title->GetPositionCoordinate()->SetValue(0.985, 0.915);
    annotation->AddActor2D(bar_title);
  }
}

}  // namespace

void render_mesh_png(const RenderMesh& mesh, const MeshFigure& figure,
                     const std::filesystem::path& png) {
  const std::string where = "render_mesh_png('" + png.string() + "')";
  check_size(where, figure.width, figure.height);
  validate_mesh(mesh, where);
  Scalars scalars;
  MeshColouring c(figure, scalars);
  if (c.coloured) {
    scalars = select_scalars(mesh, figure, where);
    c.range = colour_range(scalars, figure, where);
    if (!figure.categories.empty())
      c.range = {0.0, static_cast<double>(figure.categories.size() - 1)};
  }

  std::lock_guard lock(render_mutex());
  OffscreenWindow ow(figure.width, figure.height, where);

  // Geometry: the same points for the solid part, the bars and the shells.
  const std::size_t n_points = mesh.points.size() / 3;
  c.points = vtkSmartPointer<vtkPoints>::New();
  c.points->SetDataTypeToDouble();
  c.points->SetNumberOfPoints(static_cast<vtkIdType>(n_points));
  for (std::size_t i = 0; i < n_points; ++i) {
    c.points->SetPoint(static_cast<vtkIdType>(i), mesh.points.data() + 3 * i);
  }
  c.lut = figure.categories.empty() ? make_lookup_table(c.range)
                                    : category_lookup_table(figure.categories, c.range);
  if (c.coloured && !scalars.on_cells) {
    c.point_scalars = make_array(figure.field, scalars.values.data(), n_points);
  }

  vtkNew<vtkRenderer> scene;
  scene->SetViewport(0.0, 0.0, 0.82, 0.92);
  scene->SetLayer(1);  // drawn over the annotation layer's background, no clear of its own
  scene->SetBackground(kBackground[0], kBackground[1], kBackground[2]);
  scene->UseFXAAOff();
  for (const KindPicture& p : kKindPictures)
    if (mesh.n_of(p.kind) > 0) scene->AddActor(p.actor(mesh, c));
  apply_camera(scene, figure.camera, figure.focus_bounds);

  // Annotation layer: full window, owns the background, holds the title and the scalar bar.
  vtkNew<vtkRenderer> annotation;
  annotation->SetViewport(0.0, 0.0, 1.0, 1.0);
  annotation->SetLayer(0);
  annotation->SetBackground(kBackground[0], kBackground[1], kBackground[2]);
  annotation->InteractiveOff();
  add_title_and_scalar_bar(annotation, c);

  vtkGenericOpenGLRenderWindow* window = ow.window();
  window->SetNumberOfLayers(2);
  window->AddRenderer(annotation);
  window->AddRenderer(scene);
  ow.errors().watch(scene);
  ow.errors().watch(annotation);
  vtkSmartPointer<vtkImageData> image = ow.capture();
  write_png_atomically(image, png, where);
}

// ----------------------------------------------------------------------------------------------
// Curve plots

namespace {

// matplotlib's tab10: distinct, colour-blind-friendlier than pure RGB.
constexpr unsigned char kPalette[10][3] = {
    {31, 119, 180}, {255, 127, 14},  {44, 160, 44},   {214, 39, 40},  {148, 103, 189},
    {140, 86, 75},  {227, 119, 194}, {127, 127, 127}, {188, 189, 34}, {23, 190, 207}};

}  // namespace

void plot_curves_png(const CurvePlot& plot, const std::filesystem::path& png) {
  const std::string where = "plot_curves_png('" + png.string() + "')";
  check_size(where, plot.width, plot.height);
  if (plot.series.empty()) {
    fail(where, "the plot has no series");
  }
  for (const auto& s : plot.series) {
    if (s.x.size() != s.y.size()) {
      fail(where, "series '" + s.label + "' has " + std::to_string(s.x.size()) + " x and " +
                      std::to_string(s.y.size()) + " y values");
    }
    if (s.x.empty()) {
      fail(where, "series '" + s.label + "' has no points");
    }
  }

  std::lock_guard lock(render_mutex());
  OffscreenWindow ow(plot.width, plot.height, where);

  vtkNew<vtkRenderer> renderer;
  renderer->SetBackground(kBackground[0], kBackground[1], kBackground[2]);
  vtkNew<vtkContextActor> actor;
  vtkNew<vtkContextScene> context_scene;
  vtkNew<vtkChartXY> chart;
  context_scene->SetRenderer(renderer);
  context_scene->AddItem(chart);
  actor->SetScene(context_scene);
  renderer->AddActor(actor);

  const int h = plot.height;
  chart->SetTitle(plot.title);
  style_text(chart->GetTitleProperties(), scaled_font(h, 0.032, 12), true);
  chart->SetShowLegend(true);
  chart->GetLegend()->SetHorizontalAlignment(vtkChartLegend::LEFT);  // curves mostly rise
  chart->GetLegend()->SetVerticalAlignment(vtkChartLegend::TOP);
  style_text(chart->GetLegend()->GetLabelProperties(), scaled_font(h, 0.022, 9), false);
  chart->GetLegend()->GetBrush()->SetColor(255, 255, 255, 230);
  chart->GetLegend()->GetPen()->SetColor(160, 160, 160, 255);

  const std::pair<int, const std::string*> axes[2] = {{vtkAxis::BOTTOM, &plot.x_label},
                                                      {vtkAxis::LEFT, &plot.y_label}};
  for (const auto& [which, label] : axes) {
    vtkAxis* axis = chart->GetAxis(which);
    axis->SetTitle(*label);
    style_text(axis->GetTitleProperties(), scaled_font(h, 0.025, 10), true);
    style_text(axis->GetLabelProperties(), scaled_font(h, 0.021, 9), false);
    axis->GetGridPen()->SetColor(220, 220, 220, 255);
    axis->GetPen()->SetColor(60, 60, 60, 255);
  }

  std::vector<vtkSmartPointer<vtkTable>> tables;
  for (std::size_t i = 0; i < plot.series.size(); ++i) {
    const CurveSeries& s = plot.series[i];
    auto table = vtkSmartPointer<vtkTable>::New();
    table->AddColumn(make_array("x", s.x.data(), s.x.size()));
    table->AddColumn(make_array("y", s.y.data(), s.y.size()));
    tables.push_back(table);

    vtkPlot* p = chart->AddPlot(s.markers_only ? vtkChart::POINTS : vtkChart::LINE);
    p->SetInputData(table, 0, 1);
    p->SetLabel(s.label);
    const unsigned char* c = kPalette[i % 10];
    p->SetColor(c[0], c[1], c[2], 255);
    p->SetWidth(std::max(2.0f, static_cast<float>(h) / 280.0f));
    if (s.dashed) {
      p->GetPen()->SetLineType(vtkPen::DASH_LINE);
    }
    if (auto* points_plot = vtkPlotPoints::SafeDownCast(p); points_plot != nullptr) {
      if (s.markers_only) {
        points_plot->SetMarkerStyle(vtkPlotPoints::CIRCLE);
        points_plot->SetMarkerSize(std::max(6.0f, static_cast<float>(h) / 90.0f));
      }
    }
  }

  vtkGenericOpenGLRenderWindow* window = ow.window();
  window->AddRenderer(renderer);
  ow.errors().watch(renderer);
  ow.errors().watch(chart);
  vtkSmartPointer<vtkImageData> image = ow.capture();
  write_png_atomically(image, png, where);
}

// ----------------------------------------------------------------------------------------------

bool offscreen_rendering_available(std::string* why) {
  try {
    std::lock_guard lock(render_mutex());
    const std::unique_ptr<detail::GlContext> context = detail::make_gl_context(16, 16);
    if (ncfsim_render_glew_shim_marker != 1 || ncfsim_render_glew_shim_active() == 0) {
      check_shim("offscreen_rendering_available");
    }
    if (why != nullptr) {
      *why = context->description();
    }
    return true;
  } catch (const std::exception& e) {
    if (why != nullptr) {
      *why = e.what();
    }
    return false;
  }
}

}  // namespace ncfsim::render
