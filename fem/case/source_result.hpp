#pragma once
// A stage's source (a drape's results.h5 for a transfer, a transfer's for a crush) is checked
// against the record of the run that made it: summary.json beside the file, its `stage` and
// `status` (issue #45), not guessed from the fields the file happens to hold.
#include <filesystem>
#include <initializer_list>
#include <string>
#include <string_view>

#include "fem/case/toml_reader.hpp"

namespace ncfsim::fem {

/// What summary.json beside a result says of the run that wrote it.
struct ResultRecord {
  bool found = false;  // no summary.json: a result made elsewhere (nothing to check against)
  std::string stage;   // engine (a drape or another virtual test), transfer, crush, ...
  std::string status;  // completed, interrupted, ...
};
ResultRecord result_record(const std::filesystem::path& result_file);

/// Fails `key` of t (InputError naming the file and key) unless the result was written by a
/// completed run of one of `stages` (e.g. {"engine"} for a transfer's drape; {"transfer"} for a
/// crush's model). `needs` says what the reader needs ("a transfer needs a drape result").
/// A result without a record beside it passes (made elsewhere: its fields are checked later).
void require_result_of(const TableReader& t, std::string_view key,
                       const std::filesystem::path& result_file,
                       std::initializer_list<std::string_view> stages, const std::string& needs);

}  // namespace ncfsim::fem
