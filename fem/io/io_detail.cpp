#include "fem/io/io_detail.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <array>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <set>
#include <stdexcept>
#include <system_error>

namespace ncfsim::fem::io {

namespace {

std::string entity_text(const char* what, std::size_t index) {
  return std::string(what) + " " + std::to_string(index);
}

void check_node_ids(const std::vector<std::int64_t>& ids, std::size_t per_element,
                    std::size_t n_points, const char* what) {
  const auto n = static_cast<std::int64_t>(n_points);
  for (std::size_t i = 0; i < ids.size(); ++i) {
    if (ids[i] < 0 || ids[i] >= n) {
      throw std::invalid_argument("ResultMesh: " + entity_text(what, i / per_element) +
                                  " has node id " + std::to_string(ids[i]) + " outside [0, " +
                                  std::to_string(n_points) + ")");
    }
  }
}

void check_part_ids(const std::vector<std::int32_t>& parts, const char* what) {
  for (std::size_t i = 0; i < parts.size(); ++i) {
    if (parts[i] < 0) {
      throw std::invalid_argument("ResultMesh: " + entity_text(what, i) + " has negative part id " +
                                  std::to_string(parts[i]));
    }
  }
}

// An optional per-entity array of the stage hand-off: empty, or one value per entity.
template <class T>
void check_optional(const std::vector<T>& values, std::size_t n, const char* name,
                    const char* what) {
  if (!values.empty() && values.size() != n) {
    throw std::invalid_argument(std::string("ResultMesh: ") + name + " has " +
                                std::to_string(values.size()) + " entries for " +
                                std::to_string(n) + " " + what);
  }
}

// One kind's cells: connectivity and parts, the optional hand-off arrays, material indices within
// their names where those are given.
void check_cells(const ResultMesh& mesh, ElementKind k) {
  const ResultCells& c = mesh.of(k);
  const auto nodes = static_cast<std::size_t>(nodes_per_element(k));
  const ElementOutput out = element_output(k);
  const char* name = element_kind_name(k);
  if (c.conn.size() % nodes != 0) {
    throw std::invalid_argument(std::string("ResultMesh: ") + name + " has " +
                                std::to_string(c.conn.size()) + " node ids, not a multiple of " +
                                std::to_string(nodes));
  }
  const std::size_t n = mesh.n_of(k);
  if (c.part.size() != n) {
    throw std::invalid_argument(std::string("ResultMesh: ") + out.part + " has " +
                                std::to_string(c.part.size()) + " entries for " +
                                std::to_string(n) + " " + element_plural(k));
  }
  check_node_ids(c.conn, nodes, mesh.n_points(), element_noun(k));
  check_part_ids(c.part, element_noun(k));
  check_optional(c.user_id, n, out.user_id, element_plural(k));
  check_optional(c.material, n, out.material, element_plural(k));
  const auto& names = out.bar_law ? mesh.bar_law_names : mesh.material_names;
  const auto n_names = static_cast<std::int64_t>(names.size());
  for (std::size_t i = 0; i < c.material.size(); ++i) {
    const std::int32_t m = c.material[i];
    if (m < -1 || (n_names > 0 && m >= n_names)) {
      throw std::invalid_argument(
          "ResultMesh: " + entity_text(element_noun(k), i) + " has material index " +
          std::to_string(m) + ", allowed -1 (none)" +
          (n_names > 0 ? " or [0, " + std::to_string(n_names) + ") (" +
                             (out.bar_law ? "bar_law_names" : "material_names") + ")"
                       : std::string(" or >= 0")));
    }
  }
}

}  // namespace

void validate_mesh(const ResultMesh& mesh) {
  if (mesh.points.size() % 3 != 0) {
    throw std::invalid_argument("ResultMesh: points has " + std::to_string(mesh.points.size()) +
                                " values, not a multiple of 3");
  }
  for (ElementKind k : kElementKinds) check_cells(mesh, k);
  check_optional(mesh.node_user_id, mesh.n_points(), "node_user_id", "points");
  check_optional(mesh.hex_ply, mesh.n_hex(), "hex_ply", "hexahedra");
  check_optional(mesh.hex_tow, mesh.n_hex(), "hex_tow", "hexahedra");
  check_optional(mesh.quad_thickness, mesh.n_quad(), "quad_thickness", "shells");
  for (std::size_t i = 0; i < mesh.quad_thickness.size(); ++i) {
    const double t = mesh.quad_thickness[i];
    if (!std::isfinite(t) || t <= 0) {
      throw std::invalid_argument("ResultMesh: " + entity_text("shell", i) + " has thickness " +
                                  detail::format_double(t) + " m, not a finite value > 0");
    }
  }
}

void validate_frame(const ResultMesh& mesh, const Frame& frame) {
  const std::size_t n_points = mesh.n_points();
  const std::size_t n_cells = mesh.n_cells();
  if (frame.displacement.size() != 3 * n_points) {
    throw std::invalid_argument("Frame (cycle " + std::to_string(frame.cycle) +
                                "): displacement has " + std::to_string(frame.displacement.size()) +
                                " values, expected " + std::to_string(3 * n_points));
  }
  std::set<std::string, std::less<>> seen;
  for (const FrameField& f : frame.fields) {
    const std::string where =
        "Frame (cycle " + std::to_string(frame.cycle) + "): field '" + f.name + "': ";
    if (!detail::is_valid_field_name(f.name)) {
      throw std::invalid_argument(where +
                                  "name must be non-empty and use only letters, digits and "
                                  "_ - . + ( ) [ ] (it becomes an HDF5 path, an XDMF path and a "
                                  "VTK array name)");
    }
    if (detail::is_reserved_field_name(f.name)) {
      throw std::invalid_argument(where + "name is reserved by the writer");
    }
    if (!seen.insert(f.name).second) {
      throw std::invalid_argument(where + "name appears twice");
    }
    if (f.n_components < 1) {
      throw std::invalid_argument(where + "n_components " + std::to_string(f.n_components) +
                                  " must be >= 1");
    }
    const std::size_t n = f.on_cells ? n_cells : n_points;
    const std::size_t expected = n * static_cast<std::size_t>(f.n_components);
    if (f.values.size() != expected) {
      throw std::invalid_argument(where + "has " + std::to_string(f.values.size()) +
                                  " values, expected " + std::to_string(expected) + " (" +
                                  std::to_string(f.n_components) + " x " + std::to_string(n) +
                                  (f.on_cells ? " cells: " + std::to_string(mesh.n_hex()) +
                                                    " hexahedra, " + std::to_string(mesh.n_bar()) +
                                                    " bars, " + std::to_string(mesh.n_quad()) +
                                                    " shells, in that order)"
                                              : std::string(" nodes)")));
    }
  }
}

namespace detail {

std::string format_double(double value) {
  if (std::isnan(value)) return "NaN";
  if (std::isinf(value)) return value > 0 ? "INF" : "-INF";
  std::array<char, 64> buf{};
  const auto res = std::to_chars(buf.data(), buf.data() + buf.size(), value);
  return std::string(buf.data(), res.ptr);
}

std::string zero_padded(std::size_t value, int width) {
  std::string digits = std::to_string(value);
  if (static_cast<int>(digits.size()) < width) {
    digits.insert(0, static_cast<std::size_t>(width) - digits.size(), '0');
  }
  return digits;
}

std::string xml_escape(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&apos;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

namespace {

[[noreturn]] void throw_errno(const std::string& what, const std::filesystem::path& path) {
  const int err = errno;
  throw std::runtime_error(what + " '" + path.string() + "': " + std::strerror(err));
}

void fsync_directory_of(const std::filesystem::path& path) {
  std::filesystem::path dir = path.parent_path();
  if (dir.empty()) dir = ".";
  const int fd = ::open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) return;  // best effort: durability of the rename only
  (void)::fsync(fd);
  ::close(fd);
}

}  // namespace

void fsync_file(const std::filesystem::path& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw_errno("cannot open for fsync", path);
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    errno = err;
    throw_errno("fsync failed for", path);
  }
  ::close(fd);
}

void rename_replace(const std::filesystem::path& from, const std::filesystem::path& to) {
  if (std::rename(from.c_str(), to.c_str()) != 0) {
    const int err = errno;
    throw std::runtime_error("cannot rename '" + from.string() + "' to '" + to.string() +
                             "': " + std::strerror(err));
  }
  fsync_directory_of(to);
}

std::vector<double> current_coordinates(const ResultMesh& mesh, const Frame& frame) {
  std::vector<double> x(mesh.points.size());
  for (std::size_t i = 0; i < x.size(); ++i) x[i] = mesh.points[i] + frame.displacement[i];
  return x;
}

bool is_valid_field_name(std::string_view name) {
  if (name.empty() || name == "." || name == "..") return false;
  for (char c : name) {
    const bool ok = (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') ||
                    c == '_' || c == '-' || c == '.' || c == '+' || c == '(' || c == ')' ||
                    c == '[' || c == ']';
    if (!ok) return false;
  }
  return true;
}

bool is_reserved_field_name(std::string_view name) {
  return name == "coordinates" || name == "displacement" || name == "part_id" || name == "hex8" ||
         name == "bar2" || name == "quad4";
}

}  // namespace detail
void atomic_write_text(const std::filesystem::path& path, std::string_view content) {
  std::filesystem::path tmp = path;
  tmp += ".tmp";
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) detail::throw_errno("cannot create", tmp);
  const char* p = content.data();
  std::size_t left = content.size();
  while (left > 0) {
    const ssize_t n = ::write(fd, p, left);
    if (n < 0) {
      if (errno == EINTR) continue;
      const int err = errno;
      ::close(fd);
      std::remove(tmp.c_str());
      errno = err;
      detail::throw_errno("cannot write", tmp);
    }
    p += n;
    left -= static_cast<std::size_t>(n);
  }
  if (::fsync(fd) != 0) {
    const int err = errno;
    ::close(fd);
    std::remove(tmp.c_str());
    errno = err;
    detail::throw_errno("fsync failed for", tmp);
  }
  if (::close(fd) != 0) {
    const int err = errno;
    std::remove(tmp.c_str());
    errno = err;
    detail::throw_errno("cannot close", tmp);
  }
  try {
    detail::rename_replace(tmp, path);
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
}

}  // namespace ncfsim::fem::io
