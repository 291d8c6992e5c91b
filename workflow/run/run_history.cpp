#include "workflow/run/run_history.hpp"

#include <fmt/format.h>

#include <limits>

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

}  // namespace ncfsim::workflow
