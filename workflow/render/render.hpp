// ncfsim::render — off-screen figures: mesh pictures coloured by a field, and x-y curve plots.
//
// Plain-data inputs, no dependency on the rest of ncfsim. Rendering uses VTK on an OSMesa context
// or a Mesa EGL surfaceless context (RenderBackend; no X display needed, DISPLAY is never read).
// An executable that calls these functions must be set up with the CMake function
// ncfsim_enable_offscreen_rendering(<target>) (workflow/render/CMakeLists.txt), which links
// ncfsim_render and exports the glewInit shim and the GL entry points that reach OSMesa.
//
// Every function that renders throws std::runtime_error with a readable message on any failure
// (no OpenGL context, bad input, unknown field, VTK error, PNG not writable). PNGs are written
// atomically: a temporary file in the destination folder, then a rename.
#pragma once

#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "fem/elements/element_kind.hpp"

namespace ncfsim::render {

// Where the pictures are drawn; both are Mesa's llvmpipe software renderer, no GPU, no display.
//   OSMesa: an OSMesa context rendering into memory (libOSMesa.so.8, loaded at run time);
//   Egl:    a Mesa EGL surfaceless context with a pbuffer;
//   Auto:   OSMesa, or EGL when no OSMesa context can be made (offscreen_rendering_available
//           says which and why).
// The choice: set_render_backend if called, else the environment variable
// NCFSIM_RENDER_BACKEND = osmesa | egl | auto (unset or empty: auto; any other value: rendering
// fails naming it).
enum class RenderBackend { Auto, OSMesa, Egl };

// Overrides NCFSIM_RENDER_BACKEND for the contexts this process makes from now on; std::nullopt
// goes back to the variable.
void set_render_backend(std::optional<RenderBackend> backend);

// The back end asked for (set_render_backend, else NCFSIM_RENDER_BACKEND). Throws
// std::runtime_error naming the variable when it holds something else than osmesa, egl or auto.
RenderBackend requested_render_backend();

// One field on a RenderMesh. values: [n_components * n_entities], component fastest, where the
// entities are the points (on_cells = false) or the cells, hexes first, then bars, then shells
// (on_cells = true; the order of the results files). NaN values are drawn grey (e.g. a field of
// one element kind on the others).
struct MeshField {
  std::string name;
  std::string unit;
  bool on_cells = false;
  int n_components = 1;
  std::vector<double> values;
};

struct RenderMesh {
  std::vector<double> points;  // xyz interleaved, [3*n_points]
  // Node ids per element kind (fem/elements/element_kind.hpp, in kind order: hexahedra, bars,
  // shells), nodes_per_element per cell in VTK ordering (a shell's counter-clockwise).
  std::array<std::vector<std::int64_t>, fem::kElementKinds.size()> cells;
  std::vector<MeshField> fields;  // cell fields: values for the kinds' cells in kind order

  std::vector<std::int64_t>& of(fem::ElementKind k) { return cells[static_cast<std::size_t>(k)]; }
  const std::vector<std::int64_t>& of(fem::ElementKind k) const {
    return cells[static_cast<std::size_t>(k)];
  }
  std::size_t n_of(fem::ElementKind k) const {
    return of(k).size() / static_cast<std::size_t>(fem::nodes_per_element(k));
  }
  std::size_t first_cell(fem::ElementKind k) const {
    std::size_t n = 0;
    for (fem::ElementKind j : fem::kElementKinds) {
      if (j == k) break;
      n += n_of(j);
    }
    return n;
  }
  std::size_t n_cells() const {
    std::size_t n = 0;
    for (fem::ElementKind k : fem::kElementKinds) n += n_of(k);
    return n;
  }
};

// Top: looking down -z, +y up. Front: looking along +y, +z up. Iso: from the (+x, -y, +z) octant,
// direction (1, -1.2, 1.5) so that the three visible faces of a box shade differently, +z up.
// All use a parallel (orthographic) projection; the camera is then fitted with ResetCamera.
enum class CameraPreset { Top, Iso, Front };

struct MeshFigure {
  std::string field;   // name of a RenderMesh field; empty = plain grey geometry, no scalar bar
  int component = -1;  // -1 = magnitude (the value itself for a 1-component field)
  std::string title;   // drawn at the top centre; empty = no title
  CameraPreset camera = CameraPreset::Iso;
  int width = 1200, height = 900;
  std::optional<std::array<double, 2>> range;  // colour range; default = data range (finite values)
  // Box the camera fits (xmin xmax ymin ymax zmin zmax), e.g. the current bounds of a part the view
  // follows; default = the whole mesh.
  std::optional<std::array<double, 6>> focus_bounds;
  // A categorical field (integer values 0 .. n-1): one colour per value, the scalar bar names
  // them (e.g. the failed mode of a crush). Empty: a continuous field.
  std::vector<std::string> categories;
};

// The mesh without the cells marked in `drop` (one flag per cell: hexes, then bars, then shells;
// e.g. eroded elements, whose nodes may have flown off once nothing held them): their cell-field
// values go with them; the points and the point fields stay. Throws std::invalid_argument if
// `drop` does not hold one flag per cell.
RenderMesh without_cells(const RenderMesh& mesh, const std::vector<char>& drop);

// The same with one flag per hexahedron: the bars and the shells all stay.
RenderMesh without_hexes(const RenderMesh& mesh, const std::vector<char>& drop);

// Surface of the hexahedra, the shells as quadrilaterals (both sides lit) and the bars as lines,
// coloured by the field (blue = low, red = high; NaN grey), a scalar bar titled "name [unit]", the
// figure title, white background. A mesh of any one kind alone renders.
void render_mesh_png(const RenderMesh& mesh, const MeshFigure& figure,
                     const std::filesystem::path& png);

struct CurveSeries {
  std::string label;
  std::vector<double> x, y;
  bool dashed = false;
  bool markers_only = false;
};

// Line chart: one colour per series (tab10 palette, in order), legend, axis titles.
// Put the units in the labels, e.g. x_label = "punch displacement [mm]".
struct CurvePlot {
  std::string title, x_label, y_label;
  std::vector<CurveSeries> series;
  int width = 1000, height = 700;
};

void plot_curves_png(const CurvePlot& plot, const std::filesystem::path& png);

// True when an off-screen OpenGL context of the chosen back end can be created and VTK will accept
// it (OpenGL >= 3.2 core, glewInit shim exported by the executable). Then why, when given, names
// the back end and the driver ("OSMesa: OpenGL 4.5 (Core Profile) Mesa 22.3.6, renderer llvmpipe
// (...)", "EGL: ...", or "EGL (fallback; <why OSMesa failed>): ..."): log it. Otherwise false and
// the reason. Never throws.
bool offscreen_rendering_available(std::string* why = nullptr);

}  // namespace ncfsim::render
