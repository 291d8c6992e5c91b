#pragma once
// Replacing a file so that a reader sees either the old or the new one, never half of it: for
// every text file a run, a stage or an export writes (xdmf/pvd, summary.json, CSV, decks).
#include <filesystem>
#include <string_view>

namespace ncfsim::fem::io {

/// Writes `path`.tmp, fsyncs it, renames it over `path`, fsyncs the directory (best effort).
/// Throws std::runtime_error naming the file on failure (the temporary file is removed).
void atomic_write_text(const std::filesystem::path& path, std::string_view content);

}  // namespace ncfsim::fem::io
