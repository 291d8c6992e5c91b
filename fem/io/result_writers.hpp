#pragma once
// Results writers: plain data in, files out. Serial: one process writes (gather to rank 0 first).
//
// XdmfResultWriter: <out_dir>/results.h5 + <out_dir>/results.xdmf (XDMF 3, opens in ParaView with
// the "XDMF Reader"/Xdmf3 readers and in meshio/h5py). Layout of results.h5:
//
//   /mesh/points        float64 [n_points, 3]  reference coordinates
//   /mesh/hex8          int64   [n_hex, 8]     node ids, VTK/Abaqus ordering
//   /mesh/bar2          int64   [n_bar, 2]
//   /mesh/hex_part      int32   [n_hex]        part id per hexahedron
//   /mesh/bar_part      int32   [n_bar]
//   /mesh/part_names    string  [n_parts]      variable-length UTF-8, indexed by part id
//   Shells (only in a file whose mesh has them; a file without shells has none of these, so
//   hex/bar files are what they were before shells, and a reader treats a missing /mesh/quad4 as
//   no shells):
//   /mesh/quad4         int64   [n_quad, 4]    node ids, counter-clockwise (VTK_QUAD order; the
//                                              normal by the right-hand rule)
//   /mesh/quad_part     int32   [n_quad]
//   Stage hand-off (format_version 2; each written only when the mesh carries it, a reader
//   treats a missing one as unknown):
//   /mesh/node_user_id  int64   [n_points]     node number given by the user (messages, export)
//   /mesh/hex_user_id   int64   [n_hex]        element number given by the user
//   /mesh/bar_user_id   int64   [n_bar]
//   /mesh/quad_user_id  int64   [n_quad]
//   /mesh/hex_material  int32   [n_hex]        index into /mesh/material_names (-1: none)
//   /mesh/bar_material  int32   [n_bar]        index into /mesh/bar_law_names (-1: none)
//   /mesh/quad_material int32   [n_quad]       index into /mesh/material_names (-1: none)
//   /mesh/quad_thickness float64 [n_quad]      shell thickness, m
//   /mesh/material_names string [n_materials]  the case's [[material]] names, in case order
//   /mesh/bar_law_names string  [n_bar_laws]   the case's [[bar_law]] names, in case order
//   /mesh/hex_ply       int32   [n_hex]        fabric ply index within its blanket (-1: not a tow)
//   /mesh/hex_tow       int32   [n_hex]        fabric tow index within its ply (-1: not a tow)
//   /frames/NNNNNN                             group per frame, NNNNNN = frame index (0-based,
//                                              6 digits); attributes time (float64), cycle (int32)
//   /frames/NNNNNN/coordinates  float64 [n_points, 3]  current positions = points + displacement
//   /frames/NNNNNN/displacement float64 [n_points, 3]
//   /frames/NNNNNN/<nodal field>       float64 [n_points] or [n_points, n_components]
//   /frames/NNNNNN/hex8/<cell field>   float64 [n_hex]    or [n_hex, n_components]
//   /frames/NNNNNN/bar2/<cell field>   float64 [n_bar]    or [n_bar, n_components]
//   /frames/NNNNNN/quad4/<cell field>  float64 [n_quad]   or [n_quad, n_components] (with shells)
//   /                   attributes format = "ncfsim-results", format_version (int32, 2: shells
//                       did not change it, see docs/output.md), n_frames (int32, frames complete
//                       in the file)
//
// results.xdmf: Domain / Grid "results" (Collection, Temporal) / one Grid per frame (Collection,
// Spatial, with <Time Value>) holding Uniform grids "solids" (Hexahedron), "bars" (Polyline,
// NodesPerElement 2) and "shells" (Quadrilateral), in that order; an empty block is left out. All
// share the frame's coordinates (the deformed geometry) and carry every nodal field; cell fields
// and "part_id" are split into the hex, bar and shell slices.
//
// Crash consistency: results.h5 is opened, written, flushed and closed inside each write_frame, so
// between calls it is a closed, complete file that other processes may open read-only. The frame
// enters results.xdmf only after that, and results.xdmf is replaced atomically (temp + fsync +
// rename). A process killed between write_frame calls therefore leaves valid files holding every
// frame written so far; one killed inside write_frame leaves results.xdmf valid without that frame
// (results.h5 itself may be damaged in that case: HDF5 1.10 has no journal).
//
// VtuSeriesWriter: <out_dir>/frames/frame_NNNNN.vtu (vtkXMLUnstructuredGridWriter, appended raw
// binary, zlib, UInt64 headers; points = current coordinates; VTK_HEXAHEDRON cells, then VTK_LINE
// cells, then VTK_QUAD cells; point data "displacement" + nodal fields; cell data "part_id" + cell
// fields) and <out_dir>/results.pvd, a ParaView collection with one DataSet (timestep = time) per
// frame. Each .vtu is written under a temporary name and renamed; results.pvd is replaced
// atomically after.
//
// Errors: bad input -> std::invalid_argument; HDF5/VTK/file-system failure -> std::runtime_error
// naming the file (and HDF5 object); write_frame after close() -> std::logic_error.
#include <array>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "fem/elements/element_kind.hpp"

namespace ncfsim::fem::io {

/// One element kind's cells (fem/elements/element_kind.hpp: its names in the files): the writers,
/// the reader and the renderer go over the kinds, so a new kind needs no field of its own here.
struct ResultCells {
  std::vector<std::int64_t> conn;  ///< nodes_per_element ids per cell (VTK ordering; a shell's
                                   ///< counter-clockwise, its normal by the right-hand rule)
  std::vector<std::int32_t> part;  ///< part id per cell
  // Stage hand-off (optional: empty = not known, not written; else one per cell).
  std::vector<std::int64_t> user_id;  ///< element number given by the user
  std::vector<std::int32_t>
      material;  ///< index into material_names (a bar: bar_law_names); -1: none
};

struct ResultMesh {
  std::vector<double> points;  ///< reference coordinates, xyz interleaved [3*n_points]
  std::array<ResultCells, kElementKinds.size()> cells;  ///< per ElementKind, in kind order
  std::vector<std::string> part_names;
  // Stage hand-off (optional: empty = not known, not written; else sized like its entities).
  std::vector<std::int64_t> node_user_id;  ///< per point
  std::vector<std::string> material_names;
  std::vector<std::string> bar_law_names;
  std::vector<std::int32_t> hex_ply;   ///< fabric ply per hexahedron (-1: not a tow)
  std::vector<std::int32_t> hex_tow;   ///< fabric tow per hexahedron (-1: not a tow)
  std::vector<double> quad_thickness;  ///< m per shell, > 0 (optional: empty = unknown)

  ResultCells& of(ElementKind k) { return cells[static_cast<std::size_t>(k)]; }
  const ResultCells& of(ElementKind k) const { return cells[static_cast<std::size_t>(k)]; }
  ResultCells& hex() { return of(ElementKind::Hex8); }
  const ResultCells& hex() const { return of(ElementKind::Hex8); }
  ResultCells& bars() { return of(ElementKind::Bar2); }
  const ResultCells& bars() const { return of(ElementKind::Bar2); }
  ResultCells& shells() { return of(ElementKind::Quad4); }
  const ResultCells& shells() const { return of(ElementKind::Quad4); }

  std::size_t n_points() const { return points.size() / 3; }
  std::size_t n_of(ElementKind k) const {
    return of(k).conn.size() / static_cast<std::size_t>(nodes_per_element(k));
  }
  std::size_t n_hex() const { return n_of(ElementKind::Hex8); }
  std::size_t n_bar() const { return n_of(ElementKind::Bar2); }
  std::size_t n_quad() const { return n_of(ElementKind::Quad4); }
  /// Where kind k's cells start in the per-cell order (the kinds in order).
  std::size_t first_cell(ElementKind k) const {
    std::size_t n = 0;
    for (ElementKind j : kElementKinds) {
      if (j == k) break;
      n += n_of(j);
    }
    return n;
  }
  /// Cells of every kind: the length of a one-component cell field.
  std::size_t n_cells() const {
    std::size_t n = 0;
    for (ElementKind k : kElementKinds) n += n_of(k);
    return n;
  }
};

/// A nodal field has values [n_components * n_points]; a cell field [n_components * (n_hex +
/// n_bar + n_quad)], hexes first, then bars, then shells (the element kind order). Components are
/// interleaved per entity. Names use only letters, digits and _ - . + ( ) [ ] (no spaces), are
/// unique within a frame, and are not "coordinates", "displacement", "part_id", "hex8", "bar2",
/// "quad4". The set of fields may differ from frame to frame.
struct FrameField {
  std::string name;
  bool on_cells = false;
  int n_components = 1;
  std::vector<double> values;
};

struct Frame {
  double time = 0.0;
  int cycle = 0;
  std::vector<double> displacement;  ///< [3*n_points]
  std::vector<FrameField> fields;
};

/// Throws std::invalid_argument if the mesh is inconsistent (sizes, node ids out of range,
/// negative part ids, an optional per-element array neither empty nor sized like its elements, a
/// shell thickness not finite and > 0, a shell material below -1 or past material_names when
/// those are given). Part ids need not have a name.
void validate_mesh(const ResultMesh& mesh);
/// Throws std::invalid_argument if the frame does not fit the mesh.
void validate_frame(const ResultMesh& mesh, const Frame& frame);

/// What results.xdmf says of a frame already in results.h5 (XdmfResultWriter::reopen).
struct WrittenFrame {
  double time = 0.0;
  int cycle = 0;
  struct Field {
    std::string name;
    bool on_cells = false;
    int n_components = 1;
  };
  std::vector<Field> fields;  // in the order the frame had them
};

class XdmfResultWriter {
 public:
  /// Creates out_dir if needed, replaces results.xdmf by an empty time series, then creates
  /// results.h5 (truncating) with the mesh.
  XdmfResultWriter(std::filesystem::path out_dir, ResultMesh mesh);
  ~XdmfResultWriter();
  XdmfResultWriter(const XdmfResultWriter&) = delete;
  XdmfResultWriter& operator=(const XdmfResultWriter&) = delete;
  XdmfResultWriter(XdmfResultWriter&&) noexcept;
  XdmfResultWriter& operator=(XdmfResultWriter&&) noexcept;

  /// Appends a frame; on return both files are complete and hold it. On a throw the files still
  /// hold the earlier frames and a later call may retry.
  void write_frame(const Frame& frame);
  /// Finalises; further write_frame calls throw std::logic_error. Idempotent. Not required for
  /// valid files (the destructor does nothing that the files depend on).
  void close();

  std::size_t frames_written() const;
  /// The frames as results.xdmf lists them (what reopen takes back).
  std::vector<WrittenFrame> written_frames() const;

  /// Takes over the results.h5 an earlier writer of this mesh left in out_dir (a resumed run):
  /// keeps its first `frames.size()` frames (their groups as they are), deletes the groups of
  /// later ones, rewrites results.xdmf with the kept frames; write_frame goes on after them.
  /// Throws std::runtime_error naming the file when it cannot be opened, holds another mesh
  /// (number of points or cells) or fewer frames.
  static XdmfResultWriter reopen(std::filesystem::path out_dir, ResultMesh mesh,
                                 const std::vector<WrittenFrame>& frames);

 private:
  struct Impl;
  explicit XdmfResultWriter(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

class VtuSeriesWriter {
 public:
  /// Creates out_dir/frames if needed and replaces results.pvd by an empty collection.
  VtuSeriesWriter(std::filesystem::path out_dir, ResultMesh mesh);
  ~VtuSeriesWriter();
  VtuSeriesWriter(const VtuSeriesWriter&) = delete;
  VtuSeriesWriter& operator=(const VtuSeriesWriter&) = delete;
  VtuSeriesWriter(VtuSeriesWriter&&) noexcept;
  VtuSeriesWriter& operator=(VtuSeriesWriter&&) noexcept;

  /// Writes frames/frame_NNNNN.vtu (NNNNN = frame index) and rewrites results.pvd.
  void write_frame(const Frame& frame);
  void close();

  std::size_t frames_written() const;
  /// Path of the .vtu of frame `index` (0-based), whether or not it has been written yet.
  std::filesystem::path frame_path(std::size_t index) const;
  /// Takes over the frames 0..times.size()-1 an earlier writer wrote into this folder (a resumed
  /// run): results.pvd lists them again at these times, later frames' files are removed, and
  /// write_frame goes on after them. Throws std::runtime_error naming a kept frame's missing file.
  void keep_frames(const std::vector<double>& times);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace ncfsim::fem::io
