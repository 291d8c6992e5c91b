#include "workflow/run/run_history.hpp"

#include <fmt/format.h>

#include <filesystem>
#include <limits>
#include <sstream>

#include "fem/checkpoint.hpp"
#include "fem/errors.hpp"

namespace ncfsim::workflow {

RunHistory::RunHistory(std::filesystem::path file, MeasureList& measures, bool keep_rows)
    : file_(std::move(file)), measures_(measures), keep_rows_(keep_rows) {
  for (auto& m : measures_) {
    m->add_columns(columns_);
    keep_rows_ = keep_rows_ || m->needs_final_columns();
  }
}

void RunHistory::finish() {
  if (!writer_ || !keep_rows_) return;
  const std::size_t before = columns_.size();
  for (const auto& m : measures_)
    if (m->needs_final_columns()) m->add_final_columns(columns_, rows_);
  if (columns_.size() == before) return;
  std::string text;
  for (std::size_t i = 0; i < columns_.size(); ++i) text += (i ? "," : "") + columns_[i];
  text += '\n';
  for (auto& row : rows_) {
    row.resize(columns_.size(), std::numeric_limits<double>::quiet_NaN());
    for (std::size_t i = 0; i < row.size(); ++i) {
      if (i) text += ',';
      text += fmt::format("{:.9g}", row[i]);
    }
    text += '\n';
  }
  writer_.reset();
  write_file_atomically(file_, text);
}

int RunHistory::index(const std::string& name) const {
  for (std::size_t c = 0; c < columns_.size(); ++c)
    if (columns_[c] == name) return static_cast<int>(c);
  return -1;
}

void RunHistory::write_row(const fem::ExplicitSolver& s) {
  if (!writer_) {
    for (const auto& m : measures_) m->add_late_columns(s, columns_);
    writer_ = std::make_unique<HistoryWriter>(file_, columns_);
  }
  std::vector<double> row;
  row.reserve(columns_.size());
  for (const auto& m : measures_) m->add_values(s, row);
  row.resize(columns_.size(),
             std::numeric_limits<double>::quiet_NaN());  // a resultant that came later
  writer_->write_row(row);
  if (keep_rows_) rows_.push_back(std::move(row));
}

void RunHistory::save_state(fem::CheckpointWriter& w) const {
  std::string cols;
  for (std::size_t i = 0; i < columns_.size(); ++i) cols += (i ? "\n" : "") + columns_[i];
  w.write_string("history_columns", cols);
  w.write_int("history_header", writer_ ? 1 : 0);
  std::error_code ec;
  const auto bytes = writer_ ? std::filesystem::file_size(file_, ec) : 0;
  w.write_int("history_bytes", ec ? -1 : static_cast<std::int64_t>(bytes));
  w.write_int("history_kept_rows", keep_rows_ ? static_cast<std::int64_t>(rows_.size()) : -1);
  std::vector<double> flat;
  if (keep_rows_)
    for (const auto& row : rows_) flat.insert(flat.end(), row.begin(), row.end());
  fem::save_array(w, "history_rows", flat);
}

void RunHistory::load_state(fem::CheckpointReader& r) {
  const std::string cols = r.read_string("history_columns");
  columns_.clear();
  std::stringstream ss(cols);
  for (std::string c; std::getline(ss, c, '\n');) columns_.push_back(c);
  const bool header = r.read_int("history_header") != 0;
  const std::int64_t bytes = r.read_int("history_bytes");
  const std::int64_t n_rows = r.read_int("history_kept_rows");
  std::vector<double> flat;
  r.read_array("history_rows", flat);
  rows_.clear();
  if (keep_rows_ && n_rows >= 0) {
    if (flat.size() != static_cast<std::size_t>(n_rows) * columns_.size())
      r.mismatch("history_rows", "does not hold whole rows of the history's columns");
    for (std::size_t k = 0; k < static_cast<std::size_t>(n_rows); ++k)
      rows_.emplace_back(flat.begin() + static_cast<std::ptrdiff_t>(k * columns_.size()),
                         flat.begin() + static_cast<std::ptrdiff_t>((k + 1) * columns_.size()));
  } else if (keep_rows_) {
    r.mismatch("history_rows", "the checkpoint kept no rows, this run needs them");
  }
  writer_.reset();
  std::error_code ec;
  if (!header) {  // no row yet: the first row writes the header
    std::filesystem::remove(file_, ec);
    return;
  }
  if (keep_rows_) {
    // Written again from the kept rows: a stopped run's finish() may have rewritten the file
    // with its final columns (the same text as HistoryWriter's).
    std::string text;
    for (std::size_t i = 0; i < columns_.size(); ++i) text += (i ? "," : "") + columns_[i];
    text += '\n';
    for (const auto& row : rows_) {
      for (std::size_t i = 0; i < row.size(); ++i) {
        if (i) text += ',';
        text += fmt::format("{:.9g}", row[i]);
      }
      text += '\n';
    }
    write_file_atomically(file_, text);
    writer_ = std::make_unique<HistoryWriter>(file_, columns_, true);
    return;
  }
  const auto size = std::filesystem::file_size(file_, ec);
  if (ec || bytes < 0 || size < static_cast<std::uintmax_t>(bytes))
    throw InputError(file_.string(), "--resume",
                     "is shorter than at the checkpoint (" + std::to_string(bytes) +
                         " bytes): it was changed or cut since; run without --resume");
  std::filesystem::resize_file(file_, static_cast<std::uintmax_t>(bytes));
  writer_ = std::make_unique<HistoryWriter>(file_, columns_, true);
}

}  // namespace ncfsim::workflow
