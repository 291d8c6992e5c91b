#pragma once
// Reads back what XdmfResultWriter wrote (results.h5): the mesh and one frame, for figures and
// post-processing. Throws std::runtime_error naming the file and dataset on any failure.
#include <filesystem>
#include <string>
#include <vector>

#include "fem/io/result_writers.hpp"

namespace ncfsim::fem::io {

struct StoredFrame {
  double time = 0;
  int cycle = 0;
  std::vector<double> coordinates;  // [3*n_points] current positions
  /// Nodal fields, then cell fields: the hex, bar and shell slices joined in that order
  /// ([n_components * n_cells()]), NaN where a kind's slice is missing.
  std::vector<FrameField> fields;
};

class ResultReader {
 public:
  explicit ResultReader(std::filesystem::path h5);
  const ResultMesh& mesh() const { return mesh_; }
  std::size_t n_frames() const { return n_frames_; }
  /// Frame `index` (0-based, < n_frames()).
  StoredFrame frame(std::size_t index) const;
  /// Time of frame `index` without reading its fields.
  double frame_time(std::size_t index) const;

 private:
  std::filesystem::path path_;
  ResultMesh mesh_;
  std::size_t n_frames_ = 0;
};

}  // namespace ncfsim::fem::io
