#pragma once
// Internal helpers shared by the results writers. Not part of the public API.
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

#include "fem/io/atomic_file.hpp"
#include "fem/io/result_writers.hpp"

namespace ncfsim::fem::io::detail {

/// Shortest decimal text that reads back to the same double ("0.1", "1e-06", "nan").
std::string format_double(double value);
/// Zero-padded decimal, at least `width` digits.
std::string zero_padded(std::size_t value, int width);
/// Escapes & < > " ' for XML text and attribute values.
std::string xml_escape(std::string_view text);

using io::atomic_write_text;  // fem/io/atomic_file.hpp
/// fsync of an existing file (best effort for the directory). Throws std::runtime_error.
void fsync_file(const std::filesystem::path& path);
/// Renames `from` to `to` (replacing `to`) and fsyncs the directory. Throws std::runtime_error.
void rename_replace(const std::filesystem::path& from, const std::filesystem::path& to);

/// points + displacement, [3*n_points].
std::vector<double> current_coordinates(const ResultMesh& mesh, const Frame& frame);

/// Letters, digits and _ - . + ( ) [ ]: safe as an HDF5 link name, inside XDMF "file:path" text and
/// as a VTK array name (vtkXMLWriter does not escape quotes in names).
bool is_valid_field_name(std::string_view name);
/// Field names the writers reserve for their own datasets, groups and arrays.
bool is_reserved_field_name(std::string_view name);

}  // namespace ncfsim::fem::io::detail
