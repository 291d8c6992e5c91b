#pragma once
// Strict, typed reading of a TOML case file: every key read is recorded, so that after a case is
// built any key nobody read is reported as unknown (with the closest known key as a hint). Every
// error is an InputError naming the file, the full key path, the value and the allowed range.
// Used by every module's case reader (fem/case, drape/case, workflow/case).
#include <toml++/toml.h>

#include <array>
#include <filesystem>
#include <limits>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "fem/errors.hpp"

namespace ncfsim::fem {

// Range (the allowed interval of a number) is ncfsim::Range, in fem/errors.hpp with InputError.

/// The parsed document: root table, file name and the set of keys read so far.
class CaseDocument {
 public:
  /// Parses the file; applies `overrides` ("a.b.c=value", value in TOML syntax or a bare string).
  /// A case with `[case] base = "other.toml"` is that case with the changes of its `case.set`
  /// list applied first (as --set), then its own [case] keys (name, description).
  static CaseDocument load(const std::filesystem::path& file, const std::vector<std::string>& overrides);
  static CaseDocument load_resolved(const std::filesystem::path& file,
                                    const std::vector<std::string>& overrides, int depth);
  const std::filesystem::path& file() const { return file_; }
  const toml::table& root() const { return root_; }
  /// `[case] laws = "laws.toml"` (or a list of files, relative to the case; [] for none): whole
  /// [[material]], [[bar_law]] and [[membrane_law]] tables, such as a calibration stage hands on
  /// (docs/case-file.md, "Calibrated laws"), that replace the case's tables of the same names,
  /// in the order given. A table of a name the case lacks, a table without a name or another
  /// section in the file is bad input naming the laws file and the key. Engine cases call it
  /// after loading (a workflow hashes its stages' cases without it: their laws files are their
  /// upstream stages' results).
  void apply_laws_files();
  /// What apply_laws_files replaced: "[[material]] 'dry_tow' from <file>", in order.
  const std::vector<std::string>& laws_replaced() const { return laws_replaced_; }
  void mark_read(const std::string& path) { read_.insert(path); }
  /// Throws InputError for the first key in the file that was never read.
  void check_unknown_keys() const;

 private:
  std::filesystem::path file_;
  toml::table root_;
  std::set<std::string> read_;
  std::vector<std::string> laws_replaced_;
};

/// A view of one table of the document at `path` ("" = root, "mesh.block[2]").
class TableReader {
 public:
  TableReader(CaseDocument& doc, const toml::table& table, std::string path);

  const std::string& path() const { return path_; }
  const std::filesystem::path& file() const { return doc_->file(); }
  /// The key's path in the document: in this table, or in the defaults' where only they hold it.
  std::string key_path(std::string_view key) const;
  bool has(std::string_view key) const {
    return table_.contains(key) || (defaults_ && defaults_->has(key));
  }
  /// This table over `defaults`: a key this table lacks is read from (and reported in) the
  /// defaults' table, e.g. a [[mesh.fabric]] entry over the [fabric.NAME] it names.
  TableReader with_defaults(const TableReader& defaults) const;
  /// Whether this table itself (not its defaults) holds `key`.
  bool holds(std::string_view key) const { return table_.contains(key); }
  [[noreturn]] void fail(std::string_view key, const std::string& message) const;

  double number(std::string_view key, Range range) const;
  double number(std::string_view key, double fallback, Range range) const;
  std::int64_t integer(std::string_view key, std::int64_t lo, std::int64_t hi) const;
  std::int64_t integer(std::string_view key, std::int64_t fallback, std::int64_t lo, std::int64_t hi) const;
  bool boolean(std::string_view key, bool fallback) const;
  std::string string(std::string_view key) const;
  std::string string(std::string_view key, const std::string& fallback) const;
  /// One of `choices`.
  std::string choice(std::string_view key, const std::vector<std::string>& choices,
                     const std::string& fallback) const;
  std::array<double, 3> vec3(std::string_view key, Range component_range = {}) const;
  std::array<double, 3> vec3_or(std::string_view key, std::array<double, 3> fallback,
                                Range component_range = {}) const;
  std::vector<double> numbers(std::string_view key, Range range, std::size_t min_size = 1) const;
  std::vector<std::string> strings(std::string_view key) const;
  std::optional<TableReader> table(std::string_view key) const;
  TableReader required_table(std::string_view key) const;
  /// Array of tables ([[key]]); empty when absent.
  std::vector<TableReader> tables(std::string_view key) const;
  /// The keys of this table, in the file's order (for tables of free names, e.g. columns).
  std::vector<std::string> keys() const;

  /// A sub-reader over this table that treats `key` as read even if it is not looked at.
  void mark(std::string_view key) const { doc_->mark_read(key_path(key)); }

 private:
  const toml::node& require(std::string_view key) const;
  double as_number(std::string_view key, const toml::node& node) const;

  CaseDocument* doc_;
  const toml::table& table_;
  std::string path_;
  std::shared_ptr<const TableReader> defaults_;
};

}  // namespace ncfsim::fem
