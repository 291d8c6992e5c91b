// checkpoint.h5: a CheckpointTree as HDF5 (fem/io/hdf5_checkpoint.hpp). Scalars are attributes
// (double, int64, fixed-length string), arrays 1-D datasets (double, int64, int32, uint8).
#include "fem/io/hdf5_checkpoint.hpp"

#include <hdf5.h>

#include <memory>
#include <system_error>
#include <utility>

#include "fem/io/io_detail.hpp"

namespace ncfsim::fem::io {

namespace {

using Node = CheckpointTree::Node;

/// HDF5's automatic error printing off for its lifetime (failures become exceptions).
class Silence {
 public:
  Silence() {
    H5Eget_auto2(H5E_DEFAULT, &func_, &data_);
    H5Eset_auto2(H5E_DEFAULT, nullptr, nullptr);
  }
  ~Silence() { H5Eset_auto2(H5E_DEFAULT, func_, data_); }
  Silence(const Silence&) = delete;
  Silence& operator=(const Silence&) = delete;

 private:
  H5E_auto2_t func_ = nullptr;
  void* data_ = nullptr;
};

/// One HDF5 identifier, closed with its H5?close.
class Id {
 public:
  using Closer = herr_t (*)(hid_t);
  Id(hid_t id, Closer c) : id_(id), close_(c) {}
  ~Id() {
    if (id_ >= 0) close_(id_);
  }
  Id(const Id&) = delete;
  Id& operator=(const Id&) = delete;
  hid_t get() const { return id_; }
  herr_t close() {
    const herr_t s = id_ >= 0 ? close_(id_) : 0;
    id_ = H5I_INVALID_HID;
    return s;
  }

 private:
  hid_t id_;
  Closer close_;
};

struct Where {
  const std::filesystem::path& file;
  std::string object;
  [[noreturn]] void fail(const std::string& what) const {
    H5Eclear2(H5E_DEFAULT);
    throw std::runtime_error("checkpoint file '" + file.string() + "', object '" + object +
                             "': " + what);
  }
  hid_t check(hid_t id, const char* call) const {
    if (id < 0) fail(std::string(call) + " failed");
    return id;
  }
  void check(herr_t s, const char* call, int) const {
    if (s < 0) fail(std::string(call) + " failed");
  }
};

std::string child(const std::string& parent, const std::string& name) {
  return parent == "/" ? "/" + name : parent + "/" + name;
}

// --- writing -------------------------------------------------------------------------------------

void write_attribute(hid_t loc, const std::string& name, const CheckpointTree::Value& v,
                     const Where& w) {
  Id space(w.check(H5Screate(H5S_SCALAR), "H5Screate"), H5Sclose);
  hid_t type = H5T_NATIVE_DOUBLE;
  const void* data = nullptr;
  std::string text;
  std::unique_ptr<Id> str_type;
  if (const auto* d = std::get_if<double>(&v)) {
    data = d;
  } else if (const auto* i = std::get_if<std::int64_t>(&v)) {
    type = H5T_NATIVE_INT64;
    data = i;
  } else {
    text = std::get<std::string>(v);
    str_type = std::make_unique<Id>(w.check(H5Tcopy(H5T_C_S1), "H5Tcopy"), H5Tclose);
    w.check(H5Tset_size(str_type->get(), text.size() + 1), "H5Tset_size", 0);
    w.check(H5Tset_strpad(str_type->get(), H5T_STR_NULLTERM), "H5Tset_strpad", 0);
    type = str_type->get();
    data = text.c_str();
  }
  Id attr(w.check(H5Acreate2(loc, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT),
                  "H5Acreate2"),
          H5Aclose);
  w.check(H5Awrite(attr.get(), type, data), "H5Awrite", 0);
}

template <class T>
void write_dataset(hid_t loc, const std::string& name, hid_t type, const std::vector<T>& v,
                   const Where& w) {
  const hsize_t n = v.size();
  Id space(w.check(H5Screate_simple(1, &n, nullptr), "H5Screate_simple"), H5Sclose);
  Id dset(w.check(H5Dcreate2(loc, name.c_str(), type, space.get(), H5P_DEFAULT, H5P_DEFAULT,
                             H5P_DEFAULT),
                  "H5Dcreate2"),
          H5Dclose);
  if (n > 0)
    w.check(H5Dwrite(dset.get(), type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "H5Dwrite", 0);
  w.check(dset.close(), "H5Dclose", 0);
}

void write_node(hid_t loc, const Node& node, const std::filesystem::path& file,
                const std::string& path) {
  for (const auto& [name, v] : node.values) {
    const Where w{file, child(path, name)};
    if (v.index() <= 2) {
      write_attribute(loc, name, v, w);
    } else if (const auto* d = std::get_if<std::vector<double>>(&v)) {
      write_dataset(loc, name, H5T_NATIVE_DOUBLE, *d, w);
    } else if (const auto* i = std::get_if<std::vector<std::int64_t>>(&v)) {
      write_dataset(loc, name, H5T_NATIVE_INT64, *i, w);
    } else if (const auto* i32 = std::get_if<std::vector<std::int32_t>>(&v)) {
      write_dataset(loc, name, H5T_NATIVE_INT32, *i32, w);
    } else {
      write_dataset(loc, name, H5T_NATIVE_UINT8, std::get<std::vector<std::uint8_t>>(v), w);
    }
  }
  for (const auto& [name, g] : node.groups) {
    const Where w{file, child(path, name)};
    Id grp(
        w.check(H5Gcreate2(loc, name.c_str(), H5P_DEFAULT, H5P_DEFAULT, H5P_DEFAULT), "H5Gcreate2"),
        H5Gclose);
    write_node(grp.get(), g, file, w.object);
  }
}

// --- reading -------------------------------------------------------------------------------------

struct ReadContext {
  const std::filesystem::path* file;
  std::string path;
  Node* node;
  std::string error;
};

CheckpointTree::Value read_attribute_value(hid_t loc, const char* name, const Where& w) {
  Id attr(w.check(H5Aopen(loc, name, H5P_DEFAULT), "H5Aopen"), H5Aclose);
  Id type(w.check(H5Aget_type(attr.get()), "H5Aget_type"), H5Tclose);
  switch (H5Tget_class(type.get())) {
    case H5T_FLOAT: {
      double d = 0;
      w.check(H5Aread(attr.get(), H5T_NATIVE_DOUBLE, &d), "H5Aread", 0);
      return d;
    }
    case H5T_INTEGER: {
      std::int64_t i = 0;
      w.check(H5Aread(attr.get(), H5T_NATIVE_INT64, &i), "H5Aread", 0);
      return i;
    }
    case H5T_STRING: {
      if (H5Tis_variable_str(type.get()) > 0) w.fail("variable-length string attribute");
      const std::size_t size = H5Tget_size(type.get());
      std::string s(size, '\0');
      Id mem(w.check(H5Tcopy(H5T_C_S1), "H5Tcopy"), H5Tclose);
      w.check(H5Tset_size(mem.get(), size), "H5Tset_size", 0);
      w.check(H5Aread(attr.get(), mem.get(), s.data()), "H5Aread", 0);
      s.resize(s.find('\0') == std::string::npos ? size : s.find('\0'));
      return s;
    }
    default:
      w.fail("attribute of a type a checkpoint does not hold");
  }
}

template <class T>
std::vector<T> read_dataset_values(hid_t dset, hid_t mem_type, const Where& w) {
  Id space(w.check(H5Dget_space(dset), "H5Dget_space"), H5Sclose);
  if (H5Sget_simple_extent_ndims(space.get()) != 1) w.fail("not a 1-D dataset");
  hsize_t n = 0;
  H5Sget_simple_extent_dims(space.get(), &n, nullptr);
  std::vector<T> v(static_cast<std::size_t>(n));
  if (n > 0)
    w.check(H5Dread(dset, mem_type, H5S_ALL, H5S_ALL, H5P_DEFAULT, v.data()), "H5Dread", 0);
  return v;
}

void read_node(hid_t loc, Node& node, const std::filesystem::path& file, const std::string& path);

herr_t visit_link(hid_t loc, const char* name, const H5L_info_t*, void* data) {
  auto* ctx = static_cast<ReadContext*>(data);
  try {
    const Where w{*ctx->file, child(ctx->path, name)};
    H5O_info_t info;
    w.check(H5Oget_info_by_name2(loc, name, &info, H5O_INFO_BASIC, H5P_DEFAULT),
            "H5Oget_info_by_name", 0);
    if (info.type == H5O_TYPE_GROUP) {
      Id g(w.check(H5Gopen2(loc, name, H5P_DEFAULT), "H5Gopen2"), H5Gclose);
      read_node(g.get(), ctx->node->groups[name], *ctx->file, w.object);
    } else if (info.type == H5O_TYPE_DATASET) {
      Id d(w.check(H5Dopen2(loc, name, H5P_DEFAULT), "H5Dopen2"), H5Dclose);
      Id type(w.check(H5Dget_type(d.get()), "H5Dget_type"), H5Tclose);
      const H5T_class_t cls = H5Tget_class(type.get());
      const std::size_t size = H5Tget_size(type.get());
      CheckpointTree::Value& v = ctx->node->values[name];
      if (cls == H5T_FLOAT) {
        v = read_dataset_values<double>(d.get(), H5T_NATIVE_DOUBLE, w);
      } else if (cls == H5T_INTEGER && size == 8) {
        v = read_dataset_values<std::int64_t>(d.get(), H5T_NATIVE_INT64, w);
      } else if (cls == H5T_INTEGER && size == 4) {
        v = read_dataset_values<std::int32_t>(d.get(), H5T_NATIVE_INT32, w);
      } else if (cls == H5T_INTEGER && size == 1) {
        v = read_dataset_values<std::uint8_t>(d.get(), H5T_NATIVE_UINT8, w);
      } else {
        w.fail("dataset of a type a checkpoint does not hold");
      }
    }
  } catch (const std::exception& e) {
    ctx->error = e.what();
    return -1;
  }
  return 0;
}

herr_t visit_attribute(hid_t loc, const char* name, const H5A_info_t*, void* data) {
  auto* ctx = static_cast<ReadContext*>(data);
  try {
    ctx->node->values[name] = read_attribute_value(loc, name, {*ctx->file, child(ctx->path, name)});
  } catch (const std::exception& e) {
    ctx->error = e.what();
    return -1;
  }
  return 0;
}

void read_node(hid_t loc, Node& node, const std::filesystem::path& file, const std::string& path) {
  ReadContext ctx{&file, path, &node, {}};
  hsize_t idx = 0;
  if (H5Aiterate2(loc, H5_INDEX_NAME, H5_ITER_INC, &idx, visit_attribute, &ctx) < 0) {
    if (!ctx.error.empty()) throw std::runtime_error(ctx.error);
    Where{file, path}.fail("H5Aiterate2 failed");
  }
  idx = 0;
  if (H5Literate(loc, H5_INDEX_NAME, H5_ITER_INC, &idx, visit_link, &ctx) < 0) {
    if (!ctx.error.empty()) throw std::runtime_error(ctx.error);
    Where{file, path}.fail("H5Literate failed");
  }
}

}  // namespace

void write_checkpoint_file(const std::filesystem::path& path, const CheckpointTree& tree) {
  Silence silence;
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  try {
    const Where w{tmp, "/"};
    {
      Id fapl(w.check(H5Pcreate(H5P_FILE_ACCESS), "H5Pcreate"), H5Pclose);
#if H5_VERSION_GE(1, 10, 7)
      H5Pset_file_locking(fapl.get(), 0, 1);  // a new file no one else reads before the rename
#endif
      Id file(w.check(H5Fcreate(tmp.c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, fapl.get()), "H5Fcreate"),
              H5Fclose);
      write_node(file.get(), tree.root(), tmp, "/");
      w.check(H5Fflush(file.get(), H5F_SCOPE_GLOBAL), "H5Fflush", 0);
      w.check(file.close(), "H5Fclose", 0);
    }
    detail::fsync_file(tmp);
    detail::rename_replace(tmp, path);
  } catch (...) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    throw;
  }
}

CheckpointTree read_checkpoint_file(const std::filesystem::path& path) {
  Silence silence;
  const Where w{path, "/"};
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw CheckpointMismatch("checkpoint file '" + path.string() + "' does not exist");
  try {
    Id fapl(w.check(H5Pcreate(H5P_FILE_ACCESS), "H5Pcreate"), H5Pclose);
#if H5_VERSION_GE(1, 10, 7)
    H5Pset_file_locking(fapl.get(), 0, 1);
#endif
    const hid_t fid = H5Fopen(path.c_str(), H5F_ACC_RDONLY, fapl.get());
    if (fid < 0) w.fail("not an HDF5 file (damaged or not a checkpoint)");
    Id file(fid, H5Fclose);
    Node root;
    read_node(file.get(), root, path, "/");
    return CheckpointTree(std::move(root));
  } catch (const CheckpointMismatch&) {
    throw;
  } catch (const std::exception& e) {
    throw CheckpointMismatch(e.what());
  }
}

}  // namespace ncfsim::fem::io
