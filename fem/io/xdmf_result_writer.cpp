// XdmfResultWriter: results.h5 (HDF5, serial sec2 driver) + results.xdmf (XDMF 3).
// Layout and consistency rules: see result_writers.hpp.
#include <hdf5.h>

#include <array>
#include <chrono>
#include <cstdint>
#include <sstream>
#include <stdexcept>
#include <thread>
#include <utility>

#include "fem/io/io_detail.hpp"
#include "fem/io/result_writers.hpp"

namespace ncfsim::fem::io {

namespace {

// 2: the stage hand-off datasets (user ids, materials, ply/tow). Shells (quad4) did not change it:
// their datasets are only added, only to a file that has shells (docs/output.md).
constexpr int kFormatVersion = 2;
constexpr int kH5FrameDigits = 6;
constexpr const char* kH5Name = "results.h5";
constexpr const char* kXdmfName = "results.xdmf";

// --- HDF5 plumbing -------------------------------------------------------------------------------

/// Turns off HDF5's automatic error-stack printing for its lifetime; failures are reported through
/// the exceptions instead (with the stack's messages in them).
class SilenceH5Errors {
 public:
  SilenceH5Errors() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~SilenceH5Errors() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  SilenceH5Errors(const SilenceH5Errors&) = delete;
  SilenceH5Errors& operator=(const SilenceH5Errors&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// The messages on HDF5's current error stack, outermost first, then clears it.
std::string h5_error_stack_text() {
  std::vector<std::string> lines;
  auto walk = [](unsigned, const H5E_error2_t* err, void* client) -> herr_t {
    auto* out = static_cast<std::vector<std::string>*>(client);
    std::string line = err->func_name ? err->func_name : "?";
    if (err->desc && *err->desc) line += std::string(": ") + err->desc;
    out->push_back(std::move(line));
    return 0;
  };
  H5Ewalk2(H5E_DEFAULT, H5E_WALK_DOWNWARD, walk, &lines);
  H5Eclear2(H5E_DEFAULT);
  if (lines.empty()) return "no HDF5 error message";
  std::string text = lines.front();
  if (lines.size() > 1) text += " ... " + lines.back();
  return text;
}

/// Owns one HDF5 identifier and closes it with the matching H5?close.
class H5Id {
 public:
  using Closer = herr_t (*)(hid_t);
  H5Id() = default;
  H5Id(hid_t id, Closer closer) : id_(id), closer_(closer) {}
  ~H5Id() { reset(); }
  H5Id(H5Id&& o) noexcept : id_(std::exchange(o.id_, H5I_INVALID_HID)), closer_(o.closer_) {}
  H5Id& operator=(H5Id&& o) noexcept {
    if (this != &o) {
      reset();
      id_ = std::exchange(o.id_, H5I_INVALID_HID);
      closer_ = o.closer_;
    }
    return *this;
  }
  H5Id(const H5Id&) = delete;
  H5Id& operator=(const H5Id&) = delete;

  hid_t get() const { return id_; }
  /// Closes now and reports whether HDF5 accepted it.
  herr_t close() {
    herr_t status = 0;
    if (id_ >= 0 && closer_) status = closer_(id_);
    id_ = H5I_INVALID_HID;
    return status;
  }
  void reset() { (void)close(); }

 private:
  hid_t id_ = H5I_INVALID_HID;
  Closer closer_ = nullptr;
};

/// Context for error messages: the file and the object inside it.
struct H5Where {
  const std::filesystem::path& file;
  std::string object;
};

[[noreturn]] void throw_h5(const H5Where& where, const char* call) {
  std::string msg = std::string("HDF5 error: ") + call + " failed for file '" +
                    where.file.string() + "', object '" + where.object + "'";
  msg += ": " + h5_error_stack_text();
  throw std::runtime_error(msg);
}

hid_t h5_check_id(hid_t id, const H5Where& where, const char* call) {
  if (id < 0) throw_h5(where, call);
  return id;
}

void h5_check(herr_t status, const H5Where& where, const char* call) {
  if (status < 0) throw_h5(where, call);
}

H5Id make_fapl(const std::filesystem::path& file) {
  const H5Where where{file, "(file access properties)"};
  H5Id fapl(h5_check_id(H5Pcreate(H5P_FILE_ACCESS), where, "H5Pcreate(H5P_FILE_ACCESS)"), H5Pclose);
  // SEMI: H5Fclose fails rather than leaving the file open behind a leaked object handle.
  h5_check(H5Pset_fclose_degree(fapl.get(), H5F_CLOSE_SEMI), where, "H5Pset_fclose_degree");
#if H5_VERSION_GE(1, 10, 7)
  // Keep HDF5's file locking but do not fail on file systems without flock (NFS, Lustre).
  h5_check(H5Pset_file_locking(fapl.get(), 1, 1), where, "H5Pset_file_locking");
#endif
  return fapl;
}

/// Writes a new dataset `name` under `loc`: rank-1 [dims0] or rank-2 [dims0, dims1].
void write_dataset(hid_t loc, const std::string& name, hid_t file_type, hid_t mem_type,
                   std::vector<hsize_t> dims, const void* data, const H5Where& where) {
  H5Id space(h5_check_id(H5Screate_simple(static_cast<int>(dims.size()), dims.data(), nullptr),
                         where, "H5Screate_simple"),
             H5Sclose);
  H5Id dset(h5_check_id(H5Dcreate2(loc, name.c_str(), file_type, space.get(), H5P_DEFAULT,
                                   H5P_DEFAULT, H5P_DEFAULT),
                        where, "H5Dcreate2"),
            H5Dclose);
  hsize_t count = 1;
  for (hsize_t d : dims) count *= d;
  if (count > 0) {
    h5_check(H5Dwrite(dset.get(), mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, data), where,
             "H5Dwrite");
  }
  h5_check(dset.close(), where, "H5Dclose");
}

template <class T>
void write_scalar_attribute(hid_t loc, const char* name, hid_t file_type, hid_t mem_type,
                            const T& value, const H5Where& where) {
  const htri_t exists = H5Aexists(loc, name);
  h5_check(exists < 0 ? -1 : 0, where, "H5Aexists");
  H5Id attr;
  if (exists > 0) {
    attr = H5Id(h5_check_id(H5Aopen(loc, name, H5P_DEFAULT), where, "H5Aopen"), H5Aclose);
  } else {
    H5Id space(h5_check_id(H5Screate(H5S_SCALAR), where, "H5Screate"), H5Sclose);
    attr = H5Id(h5_check_id(H5Acreate2(loc, name, file_type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                            where, "H5Acreate2"),
                H5Aclose);
  }
  h5_check(H5Awrite(attr.get(), mem_type, &value), where, "H5Awrite");
  h5_check(attr.close(), where, "H5Aclose");
}

void write_string_attribute(hid_t loc, const char* name, const std::string& value,
                            const H5Where& where) {
  H5Id type(h5_check_id(H5Tcopy(H5T_C_S1), where, "H5Tcopy"), H5Tclose);
  h5_check(H5Tset_size(type.get(), value.empty() ? 1 : value.size()), where, "H5Tset_size");
  h5_check(H5Tset_strpad(type.get(), H5T_STR_NULLPAD), where, "H5Tset_strpad");
  h5_check(H5Tset_cset(type.get(), H5T_CSET_UTF8), where, "H5Tset_cset");
  H5Id space(h5_check_id(H5Screate(H5S_SCALAR), where, "H5Screate"), H5Sclose);
  H5Id attr(h5_check_id(H5Acreate2(loc, name, type.get(), space.get(), H5P_DEFAULT, H5P_DEFAULT),
                        where, "H5Acreate2"),
            H5Aclose);
  const std::string padded = value.empty() ? std::string(1, '\0') : value;
  h5_check(H5Awrite(attr.get(), type.get(), padded.data()), where, "H5Awrite");
  h5_check(attr.close(), where, "H5Aclose");
}

void write_string_dataset(hid_t loc, const std::string& name,
                          const std::vector<std::string>& values, const H5Where& where) {
  H5Id type(h5_check_id(H5Tcopy(H5T_C_S1), where, "H5Tcopy"), H5Tclose);
  h5_check(H5Tset_size(type.get(), H5T_VARIABLE), where, "H5Tset_size");
  h5_check(H5Tset_cset(type.get(), H5T_CSET_UTF8), where, "H5Tset_cset");
  std::vector<const char*> ptrs;
  ptrs.reserve(values.size());
  for (const std::string& s : values) ptrs.push_back(s.c_str());
  write_dataset(loc, name, type.get(), type.get(), {static_cast<hsize_t>(values.size())},
                ptrs.data(), where);
}

H5Id create_group(hid_t loc, const std::string& name, const H5Where& where) {
  return H5Id(h5_check_id(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT),
                          where, "H5Gcreate2"),
              H5Gclose);
}

/// Shape of a field dataset: [n] for one component, [n, c] otherwise.
std::vector<hsize_t> field_dims(std::size_t n, int n_components) {
  if (n_components == 1) return {static_cast<hsize_t>(n)};
  return {static_cast<hsize_t>(n), static_cast<hsize_t>(n_components)};
}

std::string dims_text(std::size_t n, int n_components) {
  if (n_components == 1) return std::to_string(n);
  return std::to_string(n) + " " + std::to_string(n_components);
}

const char* attribute_type(int n_components) {
  switch (n_components) {
    case 1:
      return "Scalar";
    case 3:
      return "Vector";
    case 6:
      return "Tensor6";
    case 9:
      return "Tensor";
    default:
      return "Matrix";
  }
}

}  // namespace

// --- Writer
// ----------------------------------------------------------------------------------------

struct XdmfResultWriter::Impl {
  struct FieldRecord {
    std::string name;
    bool on_cells;
    int n_components;
  };
  struct FrameRecord {
    double time;
    int cycle;
    std::string group;  // "/frames/NNNNNN"
    std::vector<FieldRecord> fields;
  };

  std::filesystem::path dir, h5, xdmf;
  ResultMesh mesh;
  std::vector<FrameRecord> frames;
  bool closed = false;

  H5Where at(std::string object) const { return H5Where{h5, std::move(object)}; }
  void create_h5() const;
  void write_handoff_datasets(hid_t mesh_group) const;
  void write_frame_h5(const Frame& frame, const std::string& group) const;
  std::string xdmf_text() const;
  /// One Uniform grid of a frame: a kind's cells, their parts and fields.
  void append_uniform_grid(std::ostringstream& x, const FrameRecord& fr, ElementKind k) const;
};

void XdmfResultWriter::Impl::create_h5() const {
  SilenceH5Errors silence;
  const H5Where root = at("/");
  H5Id fapl = make_fapl(h5);
  H5Id file(
      h5_check_id(H5Fcreate(h5.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), root, "H5Fcreate"),
      H5Fclose);
  write_string_attribute(file.get(), "format", "ncfsim-results", root);
  const std::int32_t version = kFormatVersion;
  write_scalar_attribute(file.get(), "format_version", H5T_STD_I32LE, H5T_NATIVE_INT32, version,
                         root);
  const std::int32_t n_frames = 0;
  write_scalar_attribute(file.get(), "n_frames", H5T_STD_I32LE, H5T_NATIVE_INT32, n_frames, root);
  {
    H5Id g = create_group(file.get(), "mesh", at("/mesh"));
    const auto nd = static_cast<hsize_t>(mesh.n_points());
    write_dataset(g.get(), "points", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {nd, 3}, mesh.points.data(),
                  at("/mesh/points"));
    // A kind written only with cells (shells) keeps a file without them as it was before it.
    auto cells = [&](ElementKind k) {
      const auto n = static_cast<hsize_t>(mesh.n_of(k));
      const char* name = element_kind_name(k);
      write_dataset(g.get(), name, H5T_STD_I64LE, H5T_NATIVE_INT64,
                    {n, static_cast<hsize_t>(nodes_per_element(k))}, mesh.of(k).conn.data(),
                    at(std::string("/mesh/") + name));
      const char* part = element_output(k).part;
      write_dataset(g.get(), part, H5T_STD_I32LE, H5T_NATIVE_INT32, {n}, mesh.of(k).part.data(),
                    at(std::string("/mesh/") + part));
    };
    for (ElementKind k : kElementKinds)
      if (element_output(k).always_in_file) cells(k);
    write_string_dataset(g.get(), "part_names", mesh.part_names, at("/mesh/part_names"));
    for (ElementKind k : kElementKinds)
      if (!element_output(k).always_in_file && mesh.n_of(k) > 0) cells(k);
    write_handoff_datasets(g.get());
  }
  create_group(file.get(), "frames", at("/frames"));
  h5_check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), root, "H5Fflush");
  h5_check(file.close(), root, "H5Fclose");
}

// The stage hand-off datasets of /mesh, each only when the mesh carries it.
void XdmfResultWriter::Impl::write_handoff_datasets(hid_t g) const {
  auto ids64 = [&](const char* name, const std::vector<std::int64_t>& v) {
    if (v.empty()) return;
    write_dataset(g, name, H5T_STD_I64LE, H5T_NATIVE_INT64, {static_cast<hsize_t>(v.size())},
                  v.data(), at(std::string("/mesh/") + name));
  };
  auto ids32 = [&](const char* name, const std::vector<std::int32_t>& v) {
    if (v.empty()) return;
    write_dataset(g, name, H5T_STD_I32LE, H5T_NATIVE_INT32, {static_cast<hsize_t>(v.size())},
                  v.data(), at(std::string("/mesh/") + name));
  };
  ids64("node_user_id", mesh.node_user_id);
  for (ElementKind k : kElementKinds) {
    ids64(element_output(k).user_id, mesh.of(k).user_id);
    ids32(element_output(k).material, mesh.of(k).material);
  }
  ids32("hex_ply", mesh.hex_ply);
  ids32("hex_tow", mesh.hex_tow);
  if (!mesh.quad_thickness.empty()) {
    write_dataset(g, "quad_thickness", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                  {static_cast<hsize_t>(mesh.quad_thickness.size())}, mesh.quad_thickness.data(),
                  at("/mesh/quad_thickness"));
  }
  if (!mesh.material_names.empty())
    write_string_dataset(g, "material_names", mesh.material_names, at("/mesh/material_names"));
  if (!mesh.bar_law_names.empty())
    write_string_dataset(g, "bar_law_names", mesh.bar_law_names, at("/mesh/bar_law_names"));
}

void XdmfResultWriter::Impl::write_frame_h5(const Frame& frame, const std::string& group) const {
  SilenceH5Errors silence;
  const H5Where root = at("/");
  H5Id fapl = make_fapl(h5);
  // A reader that holds the file between frames (ParaView, h5py) keeps HDF5's lock: wait for it
  // (up to ~10 s) rather than losing the frame.
  hid_t fid = H5Fopen(h5.c_str(), H5F_ACC_RDWR, fapl.get());
  for (int attempt = 0; fid < 0 && attempt < 200; ++attempt) {
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
    fid = H5Fopen(h5.c_str(), H5F_ACC_RDWR, fapl.get());
  }
  H5Id file(h5_check_id(fid, root, "H5Fopen"), H5Fclose);
  {
    // A group left by an earlier failed attempt at this frame is replaced.
    const H5Where where = at(group);
    const htri_t exists = H5Lexists(file.get(), group.c_str(), H5P_DEFAULT);
    h5_check(exists < 0 ? -1 : 0, where, "H5Lexists");
    if (exists > 0) h5_check(H5Ldelete(file.get(), group.c_str(), H5P_DEFAULT), where, "H5Ldelete");

    H5Id g = create_group(file.get(), group, where);
    write_scalar_attribute(g.get(), "time", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, frame.time, where);
    const std::int32_t cycle = frame.cycle;
    write_scalar_attribute(g.get(), "cycle", H5T_STD_I32LE, H5T_NATIVE_INT32, cycle, where);

    const auto nd = static_cast<hsize_t>(mesh.n_points());
    const std::vector<double> x = detail::current_coordinates(mesh, frame);
    write_dataset(g.get(), "coordinates", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {nd, 3}, x.data(),
                  at(group + "/coordinates"));
    write_dataset(g.get(), "displacement", H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE, {nd, 3},
                  frame.displacement.data(), at(group + "/displacement"));

    // A cell field: a slice per kind under /frames/NNNNNN/<kind>/ (a kind that is left out of
    // the file without cells has no group).
    std::array<H5Id, kElementKinds.size()> kind_group;
    bool kind_groups_made = false;
    for (const FrameField& f : frame.fields) {
      if (!f.on_cells) {
        write_dataset(g.get(), f.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                      field_dims(mesh.n_points(), f.n_components), f.values.data(),
                      at(group + "/" + f.name));
        continue;
      }
      const auto nc = static_cast<std::size_t>(f.n_components);
      for (ElementKind k : kElementKinds) {
        if (!element_output(k).always_in_file && mesh.n_of(k) == 0) continue;
        const std::string kind = element_kind_name(k);
        H5Id& kg = kind_group[static_cast<std::size_t>(k)];
        if (!kind_groups_made) kg = create_group(g.get(), kind, at(group + "/" + kind));
        write_dataset(kg.get(), f.name, H5T_IEEE_F64LE, H5T_NATIVE_DOUBLE,
                      field_dims(mesh.n_of(k), f.n_components),
                      f.values.data() + mesh.first_cell(k) * nc,
                      at(group + "/" + kind + "/" + f.name));
      }
      kind_groups_made = true;
    }
  }
  const auto n_frames = static_cast<std::int32_t>(frames.size() + 1);
  write_scalar_attribute(file.get(), "n_frames", H5T_STD_I32LE, H5T_NATIVE_INT32, n_frames, root);
  h5_check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), root, "H5Fflush");
  h5_check(file.close(), root, "H5Fclose");
}

void XdmfResultWriter::Impl::append_uniform_grid(std::ostringstream& x, const FrameRecord& fr,
                                                 ElementKind k) const {
  const std::size_t n_points = mesh.n_points();
  const std::size_t n_cells = mesh.n_of(k);
  const std::string kind = element_kind_name(k);
  const ElementOutput out = element_output(k);
  const std::string h5name = kH5Name;
  auto data_item = [&](const std::string& dims, const char* number_type, int precision,
                       const std::string& path) {
    x << "            <DataItem Dimensions=\"" << dims << "\" NumberType=\"" << number_type
      << "\" Precision=\"" << precision << "\" Format=\"HDF\">" << detail::xml_escape(h5name) << ":"
      << detail::xml_escape(path) << "</DataItem>\n";
  };
  auto attribute = [&](const std::string& name, int n_components, bool on_cells) {
    x << "          <Attribute Name=\"" << detail::xml_escape(name) << "\" AttributeType=\""
      << attribute_type(n_components) << "\" Center=\"" << (on_cells ? "Cell" : "Node") << "\">\n";
  };

  x << "        <Grid Name=\"" << out.grid << "\" GridType=\"Uniform\">\n";
  x << "          <Topology " << out.topology << " NumberOfElements=\"" << n_cells << "\">\n";
  data_item(std::to_string(n_cells) + " " + std::to_string(nodes_per_element(k)), "Int", 8,
            "/mesh/" + kind);
  x << "          </Topology>\n";
  x << "          <Geometry GeometryType=\"XYZ\">\n";
  data_item(std::to_string(n_points) + " 3", "Float", 8, fr.group + "/coordinates");
  x << "          </Geometry>\n";

  attribute("part_id", 1, true);
  data_item(std::to_string(n_cells), "Int", 4, std::string("/mesh/") + out.part);
  x << "          </Attribute>\n";
  attribute("displacement", 3, false);
  data_item(std::to_string(n_points) + " 3", "Float", 8, fr.group + "/displacement");
  x << "          </Attribute>\n";
  for (const FieldRecord& f : fr.fields) {
    attribute(f.name, f.n_components, f.on_cells);
    if (f.on_cells) {
      data_item(dims_text(n_cells, f.n_components), "Float", 8,
                fr.group + "/" + kind + "/" + f.name);
    } else {
      data_item(dims_text(n_points, f.n_components), "Float", 8, fr.group + "/" + f.name);
    }
    x << "          </Attribute>\n";
  }
  x << "        </Grid>\n";
}

std::string XdmfResultWriter::Impl::xdmf_text() const {
  std::ostringstream x;
  x << "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n"
    << "<Xdmf xmlns:xi=\"http://www.w3.org/2001/XInclude\" Version=\"3.0\">\n"
    << "  <Domain>\n"
    << "    <Grid Name=\"results\" GridType=\"Collection\" CollectionType=\"Temporal\">\n";
  for (const FrameRecord& fr : frames) {
    x << "      <Grid Name=\"frame_" << fr.group.substr(fr.group.rfind('/') + 1)
      << "\" GridType=\"Collection\" CollectionType=\"Spatial\">\n"
      << "        <Time Value=\"" << detail::format_double(fr.time) << "\"/>\n"
      << "        <Information Name=\"cycle\" Value=\"" << fr.cycle << "\"/>\n";
    for (ElementKind k : kElementKinds) {
      if (mesh.n_of(k) > 0) append_uniform_grid(x, fr, k);
    }
    x << "      </Grid>\n";
  }
  x << "    </Grid>\n"
    << "  </Domain>\n"
    << "</Xdmf>\n";
  return x.str();
}

XdmfResultWriter::XdmfResultWriter(std::filesystem::path out_dir, ResultMesh mesh)
    : impl_(std::make_unique<Impl>()) {
  validate_mesh(mesh);
  impl_->dir = std::move(out_dir);
  impl_->h5 = impl_->dir / kH5Name;
  impl_->xdmf = impl_->dir / kXdmfName;
  impl_->mesh = std::move(mesh);
  std::error_code ec;
  std::filesystem::create_directories(impl_->dir, ec);
  if (ec) {
    throw std::runtime_error("cannot create directory '" + impl_->dir.string() +
                             "': " + ec.message());
  }
  // The empty series goes first so that a results.xdmf left from an earlier run never points at
  // frames of the results.h5 about to be truncated.
  detail::atomic_write_text(impl_->xdmf, impl_->xdmf_text());
  impl_->create_h5();
}

XdmfResultWriter::~XdmfResultWriter() = default;
XdmfResultWriter::XdmfResultWriter(XdmfResultWriter&&) noexcept = default;
XdmfResultWriter& XdmfResultWriter::operator=(XdmfResultWriter&&) noexcept = default;

void XdmfResultWriter::write_frame(const Frame& frame) {
  if (!impl_) throw std::logic_error("XdmfResultWriter: write_frame on a moved-from writer");
  if (impl_->closed) {
    throw std::logic_error("XdmfResultWriter: write_frame after close() for '" +
                           impl_->h5.string() + "'");
  }
  validate_frame(impl_->mesh, frame);
  Impl::FrameRecord record{frame.time,
                           frame.cycle,
                           "/frames/" + detail::zero_padded(impl_->frames.size(), kH5FrameDigits),
                           {}};
  for (const FrameField& f : frame.fields) {
    record.fields.push_back({f.name, f.on_cells, f.n_components});
  }
  impl_->write_frame_h5(frame, record.group);  // flushed and closed on return
  impl_->frames.push_back(std::move(record));
  try {
    detail::atomic_write_text(impl_->xdmf, impl_->xdmf_text());
  } catch (...) {
    impl_->frames.pop_back();  // the next call rewrites this frame's group
    throw;
  }
}

void XdmfResultWriter::close() {
  if (!impl_) return;
  // Every write_frame already leaves both files closed and complete; close() only ends the series.
  impl_->closed = true;
}

XdmfResultWriter::XdmfResultWriter(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}

std::vector<WrittenFrame> XdmfResultWriter::written_frames() const {
  std::vector<WrittenFrame> out;
  if (!impl_) return out;
  for (const auto& fr : impl_->frames) {
    WrittenFrame w{fr.time, fr.cycle, {}};
    for (const auto& f : fr.fields) w.fields.push_back({f.name, f.on_cells, f.n_components});
    out.push_back(std::move(w));
  }
  return out;
}

XdmfResultWriter XdmfResultWriter::reopen(std::filesystem::path out_dir, ResultMesh mesh,
                                          const std::vector<WrittenFrame>& frames) {
  validate_mesh(mesh);
  auto impl = std::make_unique<Impl>();
  impl->dir = std::move(out_dir);
  impl->h5 = impl->dir / kH5Name;
  impl->xdmf = impl->dir / kXdmfName;
  impl->mesh = std::move(mesh);
  for (std::size_t k = 0; k < frames.size(); ++k) {
    Impl::FrameRecord record{
        frames[k].time, frames[k].cycle, "/frames/" + detail::zero_padded(k, kH5FrameDigits), {}};
    for (const auto& f : frames[k].fields)
      record.fields.push_back({f.name, f.on_cells, f.n_components});
    impl->frames.push_back(std::move(record));
  }
  {
    SilenceH5Errors silence;
    const H5Where root = impl->at("/");
    if (!std::filesystem::is_regular_file(impl->h5))
      throw std::runtime_error("'" + impl->h5.string() + "' does not exist");
    H5Id fapl = make_fapl(impl->h5);
    H5Id file(h5_check_id(H5Fopen(impl->h5.c_str(), H5F_ACC_RDWR, fapl.get()), root, "H5Fopen"),
              H5Fclose);
    {  // the same mesh: its points and cells
      const H5Where where = impl->at("/mesh/points");
      H5Id d(h5_check_id(H5Dopen2(file.get(), "/mesh/points", H5P_DEFAULT), where, "H5Dopen2"),
             H5Dclose);
      H5Id space(h5_check_id(H5Dget_space(d.get()), where, "H5Dget_space"), H5Sclose);
      hsize_t dims[2] = {0, 0};
      H5Sget_simple_extent_dims(space.get(), dims, nullptr);
      if (dims[0] != impl->mesh.n_points())
        throw std::runtime_error("'" + impl->h5.string() + "' holds a mesh of " +
                                 std::to_string(dims[0]) + " points, this run's has " +
                                 std::to_string(impl->mesh.n_points()));
    }
    // The kept frames must be there; the groups of later ones go.
    for (std::size_t k = 0;; ++k) {
      const std::string group = "/frames/" + detail::zero_padded(k, kH5FrameDigits);
      const htri_t exists = H5Lexists(file.get(), group.c_str(), H5P_DEFAULT);
      h5_check(exists < 0 ? -1 : 0, impl->at(group), "H5Lexists");
      if (k < frames.size()) {
        if (exists <= 0)
          throw std::runtime_error("'" + impl->h5.string() + "' lacks frame " + group +
                                   " of the run it continues");
        continue;
      }
      if (exists <= 0) break;
      h5_check(H5Ldelete(file.get(), group.c_str(), H5P_DEFAULT), impl->at(group), "H5Ldelete");
    }
    const auto n_frames = static_cast<std::int32_t>(frames.size());
    write_scalar_attribute(file.get(), "n_frames", H5T_STD_I32LE, H5T_NATIVE_INT32, n_frames, root);
    h5_check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), root, "H5Fflush");
    h5_check(file.close(), root, "H5Fclose");
  }
  detail::atomic_write_text(impl->xdmf, impl->xdmf_text());
  return XdmfResultWriter(std::move(impl));
}

std::size_t XdmfResultWriter::frames_written() const { return impl_ ? impl_->frames.size() : 0; }

}  // namespace ncfsim::fem::io
