#pragma once
// Stage hand-off: what a later stage (transfer, crush, a second forming step) builds its model
// from, read from the results.h5 of an earlier run. Plain data, no solver types: the stage that
// reads it decides what to rebuild (the mesh in the current or the reference shape, which fields
// become its initial state). Layout of the file: fem/io/result_writers.hpp; written by the run
// (workflow/run/result_mesh.cpp) for every case.
//
// Element order is the writer's (the solver's blocks: by part, then by the engine's locality
// order): match elements across stages by their user id, not their position. Nodes keep the
// engine's numbering (node_user_id gives the user's).
#include <cstddef>
#include <filesystem>
#include <string>
#include <vector>

#include "fem/io/result_writers.hpp"

namespace ncfsim::fem::io {

struct StageFrame {
  std::filesystem::path file;  ///< the results.h5 it came from
  std::size_t index = 0;       ///< frame index in the file (0-based)
  std::size_t n_frames = 0;    ///< frames in the file
  double time = 0;             ///< s
  int cycle = 0;
  /// Connectivity per kind (hex8, bar2, quad4), per-element part / material / user / ply / tow
  /// ids, shell thicknesses, part and material names, reference coordinates (mesh.points).
  /// Optional ids the file does not hold (written before format_version 2) are empty; a file
  /// without shells gives an empty quad4.
  ResultMesh mesh;
  std::vector<double> coordinates;  ///< current positions of the frame [3*n_points]
  /// The frame's nodal fields (displacement, velocity, ...: [n_components * n_points]) and cell
  /// fields ([n_components * (n_hex + n_bar + n_quad)]: hexahedra, bars, then shells; NaN where a
  /// kind lacks it).
  std::vector<FrameField> fields;

  std::size_t n_points() const { return mesh.n_points(); }
  const std::vector<double>& reference_coordinates() const { return mesh.points; }
  /// The field called `name` (nullptr when the frame has none).
  const FrameField* field(const std::string& name) const;
};

/// Frame `index` of `h5` (0-based). Throws std::runtime_error naming the file when it cannot be
/// read, std::out_of_range when the file has no such frame.
StageFrame read_frame(const std::filesystem::path& h5, std::size_t index);
/// The last frame of `h5` whose time is at or before `time` (+ 1e-9 relative); std::out_of_range
/// when the first frame is already later.
StageFrame read_frame_at_time(const std::filesystem::path& h5, double time);
/// The last complete frame of `h5` (what a stage hands the next one). std::runtime_error when the
/// file holds no frame.
StageFrame read_last_frame(const std::filesystem::path& h5);

}  // namespace ncfsim::fem::io
