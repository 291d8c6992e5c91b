#include "fem/io/stage_handoff.hpp"

#include <cmath>
#include <stdexcept>

#include "fem/io/result_reader.hpp"

namespace ncfsim::fem::io {

const FrameField* StageFrame::field(const std::string& name) const {
  for (const auto& f : fields)
    if (f.name == name) return &f;
  return nullptr;
}

namespace {

StageFrame make_stage_frame(const std::filesystem::path& h5, const ResultReader& reader,
                            std::size_t index) {
  StoredFrame sf = reader.frame(index);
  StageFrame out;
  out.file = h5;
  out.index = index;
  out.n_frames = reader.n_frames();
  out.time = sf.time;
  out.cycle = sf.cycle;
  out.mesh = reader.mesh();
  out.coordinates = std::move(sf.coordinates);
  out.fields = std::move(sf.fields);
  if (out.coordinates.size() != out.mesh.points.size())
    throw std::runtime_error(h5.string() + ": frame " + std::to_string(index) + " has " +
                             std::to_string(out.coordinates.size() / 3) + " points, the mesh " +
                             std::to_string(out.mesh.n_points()));
  return out;
}

}  // namespace

StageFrame read_frame(const std::filesystem::path& h5, std::size_t index) {
  const ResultReader reader(h5);
  if (index >= reader.n_frames())
    throw std::out_of_range(h5.string() + ": no frame " + std::to_string(index) +
                            " (the file holds " + std::to_string(reader.n_frames()) + ")");
  return make_stage_frame(h5, reader, index);
}

StageFrame read_frame_at_time(const std::filesystem::path& h5, double time) {
  const ResultReader reader(h5);
  const double tol = 1e-9 * std::max(1.0, std::abs(time));
  std::size_t found = reader.n_frames();
  for (std::size_t k = 0; k < reader.n_frames(); ++k) {
    if (reader.frame_time(k) > time + tol) break;
    found = k;
  }
  if (found == reader.n_frames())
    throw std::out_of_range(h5.string() + ": no frame at or before t = " + std::to_string(time) +
                            " s");
  return make_stage_frame(h5, reader, found);
}

StageFrame read_last_frame(const std::filesystem::path& h5) {
  const ResultReader reader(h5);
  if (reader.n_frames() == 0) throw std::runtime_error(h5.string() + ": holds no frame");
  return make_stage_frame(h5, reader, reader.n_frames() - 1);
}

}  // namespace ncfsim::fem::io
