#pragma once
// history.csv of a run: the measures' columns, one row per call, the header written with the
// first row (contact resultants are named once the contacts have run a cycle). Keeps the rows
// when summary samples or means need them.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "workflow/output/output_files.hpp"
#include "workflow/run/run_measures.hpp"

namespace ncfsim::workflow {

class RunHistory {
 public:
  /// Asks every measure for its columns (bad input throws InputError). `keep_rows`: keep every
  /// row in memory for the summary samples and means.
  RunHistory(std::filesystem::path file, MeasureList& measures, bool keep_rows);
  /// Appends a row at the solver's current state.
  void write_row(const fem::ExplicitSolver& s);
  /// At the end of the run: the measures' final columns (RunMeasure::add_final_columns); when
  /// there are any, history.csv is rewritten atomically with them.
  void finish();

  const std::vector<std::string>& columns() const { return columns_; }
  /// Index of a column, -1 when absent.
  int index(const std::string& name) const;
  const std::vector<std::vector<double>>& rows() const { return rows_; }

  /// Columns, whether the header is written, the file's length and the kept rows, into a
  /// checkpoint; load_state cuts history.csv back to that length (rows written after the
  /// checkpoint go) and appends from there.
  void save_state(fem::CheckpointWriter& w) const;
  void load_state(fem::CheckpointReader& r);

 private:
  std::filesystem::path file_;
  MeasureList& measures_;
  bool keep_rows_;
  std::vector<std::string> columns_;
  std::unique_ptr<HistoryWriter> writer_;
  std::vector<std::vector<double>> rows_;
};

}  // namespace ncfsim::workflow
