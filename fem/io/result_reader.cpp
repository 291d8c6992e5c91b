#include "fem/io/result_reader.hpp"

#include <hdf5.h>

#include <algorithm>
#include <limits>
#include <map>
#include <stdexcept>

#include "fem/io/io_detail.hpp"

namespace ncfsim::fem::io {

namespace {

struct Handle {
  hid_t id = -1;
  herr_t (*close)(hid_t) = nullptr;
  Handle(hid_t i, herr_t (*c)(hid_t)) : id(i), close(c) {}
  ~Handle() {
    if (id >= 0 && close) close(id);
  }
  Handle(const Handle&) = delete;
  Handle& operator=(const Handle&) = delete;
};

// Read-only access that takes no HDF5 file lock, so that reading a running simulation's results
// never blocks its writer (which opens and closes the file at every frame).
hid_t open_unlocked(const std::filesystem::path& file) {
  const hid_t fapl = H5Pcreate(H5P_FILE_ACCESS);
#if H5_VERSION_GE(1, 10, 7)
  H5Pset_file_locking(fapl, 0, 1);
#endif
  const hid_t f = H5Fopen(file.c_str(), H5F_ACC_RDONLY, fapl);
  H5Pclose(fapl);
  return f;
}

[[noreturn]] void fail(const std::filesystem::path& file, const std::string& what) {
  throw std::runtime_error(file.string() + ": " + what);
}

// Reads a dataset of rank 1 or 2 as doubles (or int64 with `as_int`); returns dims.
std::vector<hsize_t> read_dataset(const std::filesystem::path& file, hid_t loc,
                                  const std::string& name, hid_t mem_type,
                                  void* (*resize)(void*, std::size_t), void* target) {
  if (H5Lexists(loc, name.c_str(), H5P_DEFAULT) <= 0) fail(file, "no dataset '" + name + "'");
  Handle d(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.id < 0) fail(file, "cannot open dataset '" + name + "'");
  Handle s(H5Dget_space(d.id), H5Sclose);
  const int rank = H5Sget_simple_extent_ndims(s.id);
  std::vector<hsize_t> dims(static_cast<std::size_t>(std::max(rank, 0)));
  H5Sget_simple_extent_dims(s.id, dims.data(), nullptr);
  std::size_t count = 1;
  for (auto v : dims) count *= v;
  void* buf = resize(target, count);
  if (count && H5Dread(d.id, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, buf) < 0)
    fail(file, "cannot read dataset '" + name + "'");
  return dims;
}

template <class T>
void* resize_vec(void* v, std::size_t n) {
  auto* vec = static_cast<std::vector<T>*>(v);
  vec->resize(n);
  return vec->data();
}

std::vector<std::string> list_links(hid_t group) {
  std::vector<std::string> names;
  H5Literate(
      group, H5_INDEX_NAME, H5_ITER_INC, nullptr,
      [](hid_t, const char* name, const H5L_info_t*, void* data) -> herr_t {
        static_cast<std::vector<std::string>*>(data)->push_back(name);
        return 0;
      },
      &names);
  return names;
}

bool is_group(hid_t loc, const std::string& name) {
  H5O_info_t info;
  if (H5Oget_info_by_name2(loc, name.c_str(), &info, H5O_INFO_BASIC, H5P_DEFAULT) < 0) return false;
  return info.type == H5O_TYPE_GROUP;
}

// A rank-1 variable-length string dataset (as write_string_dataset writes them).
std::vector<std::string> read_strings(const std::filesystem::path& file, hid_t loc,
                                      const std::string& name) {
  Handle d(H5Dopen2(loc, name.c_str(), H5P_DEFAULT), H5Dclose);
  if (d.id < 0) fail(file, "cannot open dataset '" + name + "'");
  Handle s(H5Dget_space(d.id), H5Sclose);
  hsize_t n = 0;
  if (H5Sget_simple_extent_ndims(s.id) != 1) fail(file, "dataset '" + name + "' is not a list");
  H5Sget_simple_extent_dims(s.id, &n, nullptr);
  Handle type(H5Tcopy(H5T_C_S1), H5Tclose);
  H5Tset_size(type.id, H5T_VARIABLE);
  H5Tset_cset(type.id, H5T_CSET_UTF8);
  std::vector<char*> raw(n, nullptr);
  if (n && H5Dread(d.id, type.id, H5S_ALL, H5S_ALL, H5P_DEFAULT, raw.data()) < 0)
    fail(file, "cannot read dataset '" + name + "'");
  std::vector<std::string> out;
  out.reserve(n);
  for (char* c : raw) out.emplace_back(c ? c : "");
  if (n) H5Dvlen_reclaim(type.id, s.id, H5P_DEFAULT, raw.data());
  return out;
}

// The group of frame `index` (< n_frames), with the file held open while it lives.
struct FrameGroup {
  FrameGroup(const std::filesystem::path& file, std::size_t n_frames, std::size_t index)
      : name(group_name(file, n_frames, index)),
        f(open_unlocked(file), H5Fclose),
        g(f.id >= 0 ? H5Gopen2(f.id, name.c_str(), H5P_DEFAULT) : -1, H5Gclose) {
    if (f.id < 0) fail(file, "not a readable HDF5 file");
    if (g.id < 0) fail(file, "no group " + name);
  }
  static std::string group_name(const std::filesystem::path& file, std::size_t n_frames,
                                std::size_t index) {
    if (index >= n_frames) fail(file, "frame " + std::to_string(index) + " not in the file");
    return "/frames/" + detail::zero_padded(index, 6);
  }
  std::string name;
  Handle f, g;
};

template <class T>
void read_optional(const std::filesystem::path& file, hid_t loc, const char* name, hid_t mem_type,
                   std::vector<T>& target) {
  if (H5Lexists(loc, name, H5P_DEFAULT) > 0)
    read_dataset(file, loc, name, mem_type, resize_vec<T>, &target);
}

// A kind's cells of /mesh, present where the file has its connectivity (shells only in a file
// whose mesh has them).
void read_cells(const std::filesystem::path& file, hid_t g, ElementKind k, ResultMesh& mesh) {
  const char* name = element_kind_name(k);
  if (H5Lexists(g, name, H5P_DEFAULT) <= 0) return;
  ResultCells& c = mesh.of(k);
  const auto dims =
      read_dataset(file, g, name, H5T_NATIVE_INT64, resize_vec<std::int64_t>, &c.conn);
  const auto nodes = static_cast<hsize_t>(nodes_per_element(k));
  const ElementOutput out = element_output(k);
  if (dims.size() != 2 || dims[1] != nodes) {
    const std::string count =
        "n_" + std::string(out.part).substr(0, std::string(out.part).find('_'));
    fail(file, std::string("dataset '/mesh/") + name + "' is not [" + count + ", " +
                   std::to_string(nodes) + "] (" + std::to_string(nodes) + " node ids per " +
                   element_noun(k) + ")");
  }
  if (H5Lexists(g, out.part, H5P_DEFAULT) <= 0)
    fail(file, std::string("dataset '/mesh/") + name + "' without '/mesh/" + out.part + "'");
  read_dataset(file, g, out.part, H5T_NATIVE_INT32, resize_vec<std::int32_t>, &c.part);
  // The stage hand-off datasets (format_version 2; absent in older files).
  read_optional(file, g, out.user_id, H5T_NATIVE_INT64, c.user_id);
  read_optional(file, g, out.material, H5T_NATIVE_INT32, c.material);
}

}  // namespace

ResultReader::ResultReader(std::filesystem::path h5) : path_(std::move(h5)) {
  if (!std::filesystem::exists(path_)) fail(path_, "no such file");
  Handle f(open_unlocked(path_), H5Fclose);
  if (f.id < 0) fail(path_, "not a readable HDF5 file");
  {
    Handle a(H5Aopen(f.id, "n_frames", H5P_DEFAULT), H5Aclose);
    if (a.id < 0) fail(path_, "no attribute n_frames (not an ncfsim results file)");
    std::int32_t nf = 0;
    H5Aread(a.id, H5T_NATIVE_INT32, &nf);
    n_frames_ = static_cast<std::size_t>(std::max(nf, 0));
  }
  Handle g(H5Gopen2(f.id, "mesh", H5P_DEFAULT), H5Gclose);
  if (g.id < 0) fail(path_, "no group /mesh");
  read_dataset(path_, g.id, "points", H5T_NATIVE_DOUBLE, resize_vec<double>, &mesh_.points);
  for (ElementKind k : kElementKinds) read_cells(path_, g.id, k, mesh_);
  if (H5Lexists(g.id, "part_names", H5P_DEFAULT) > 0)
    mesh_.part_names = read_strings(path_, g.id, "part_names");
  read_optional(path_, g.id, "node_user_id", H5T_NATIVE_INT64, mesh_.node_user_id);
  read_optional(path_, g.id, "hex_ply", H5T_NATIVE_INT32, mesh_.hex_ply);
  read_optional(path_, g.id, "hex_tow", H5T_NATIVE_INT32, mesh_.hex_tow);
  read_optional(path_, g.id, "quad_thickness", H5T_NATIVE_DOUBLE, mesh_.quad_thickness);
  if (H5Lexists(g.id, "material_names", H5P_DEFAULT) > 0)
    mesh_.material_names = read_strings(path_, g.id, "material_names");
  if (H5Lexists(g.id, "bar_law_names", H5P_DEFAULT) > 0)
    mesh_.bar_law_names = read_strings(path_, g.id, "bar_law_names");
  // What the writer checked before writing, checked again on what came back (a damaged or foreign
  // file fails here, naming the file, rather than in a later stage's indexing).
  try {
    validate_mesh(mesh_);
  } catch (const std::invalid_argument& e) {
    fail(path_, std::string("inconsistent /mesh: ") + e.what());
  }
}

double ResultReader::frame_time(std::size_t index) const {
  const FrameGroup fg(path_, n_frames_, index);
  double t = 0;
  Handle a(H5Aopen(fg.g.id, "time", H5P_DEFAULT), H5Aclose);
  if (a.id < 0 || H5Aread(a.id, H5T_NATIVE_DOUBLE, &t) < 0)
    fail(path_, "no attribute time on " + fg.name);
  return t;
}

StoredFrame ResultReader::frame(std::size_t index) const {
  const FrameGroup fg(path_, n_frames_, index);
  const hid_t gid = fg.g.id;
  StoredFrame fr;
  {
    Handle a(H5Aopen(gid, "time", H5P_DEFAULT), H5Aclose);
    if (a.id >= 0) H5Aread(a.id, H5T_NATIVE_DOUBLE, &fr.time);
    Handle c(H5Aopen(gid, "cycle", H5P_DEFAULT), H5Aclose);
    if (c.id >= 0) H5Aread(c.id, H5T_NATIVE_INT, &fr.cycle);
  }
  read_dataset(path_, gid, "coordinates", H5T_NATIVE_DOUBLE, resize_vec<double>, &fr.coordinates);
  const std::size_t n_cells = mesh_.n_cells();
  for (const auto& name : list_links(gid)) {
    if (name == "coordinates" || is_group(gid, name)) continue;
    FrameField ff;
    ff.name = name;
    const auto dims =
        read_dataset(path_, gid, name, H5T_NATIVE_DOUBLE, resize_vec<double>, &ff.values);
    ff.n_components = dims.size() > 1 ? static_cast<int>(dims[1]) : 1;
    fr.fields.push_back(std::move(ff));
  }
  // Cell fields: join the kinds' slices in kind order (missing slice -> NaN).
  std::map<std::string, FrameField> cells;
  for (ElementKind k : kElementKinds) {
    const char* kind = element_kind_name(k);
    if (H5Lexists(gid, kind, H5P_DEFAULT) <= 0) continue;
    Handle cg(H5Gopen2(gid, kind, H5P_DEFAULT), H5Gclose);
    for (const auto& name : list_links(cg.id)) {
      std::vector<double> vals;
      const auto dims =
          read_dataset(path_, cg.id, name, H5T_NATIVE_DOUBLE, resize_vec<double>, &vals);
      const int nc = dims.size() > 1 ? static_cast<int>(dims[1]) : 1;
      auto& ff = cells[name];
      if (ff.values.empty()) {
        ff.name = name, ff.on_cells = true, ff.n_components = nc;
        ff.values.assign(static_cast<std::size_t>(nc) * n_cells,
                         std::numeric_limits<double>::quiet_NaN());
      }
      if (nc != ff.n_components) continue;
      const std::size_t offset = static_cast<std::size_t>(nc) * mesh_.first_cell(k);
      for (std::size_t i = 0; i < vals.size() && offset + i < ff.values.size(); ++i)
        ff.values[offset + i] = vals[i];
    }
  }
  for (auto& [name, ff] : cells) fr.fields.push_back(std::move(ff));
  return fr;
}

}  // namespace ncfsim::fem::io
