#pragma once
// A quantity a run measures from the solver state and reports: its history.csv columns, its
// values at a history row, its summary.json entries and its log lines. The time loop
// (workflow/run) calls the measures of a case through this interface, in order; each module
// implements its own (drape/probes: ply shear angle, ASTM D1388 bending length, picture-frame
// force, bias-extension Eq. 2; workflow/run/run_measures: energies, tools, reactions, probes,
// contact resultants). A measure reads the solver state, never changes it. Header only: the
// libraries that implement a measure link nlohmann_json.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "fem/checkpoint.hpp"
#include "fem/solver.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::fem {

/// A cell field a measure adds to the result frames: values [n_components * (n_hex + n_bar +
/// n_quad)], hexahedra first, then bars, then shells (the results files' cell order); NaN where
/// it does not apply.
struct MeasureCellField {
  std::string name;
  int n_components = 1;
  std::vector<double> values;
};

class RunMeasure {
 public:
  virtual ~RunMeasure() = default;

  /// Log lines once the model is set up (what the measure found), in the run's log.
  virtual std::vector<std::string> setup_lines() const { return {}; }
  /// Warning lines once the model is set up (what the user should know the run changed or
  /// doubts: the log's warnings, warnings.txt and the workflow report).
  virtual std::vector<std::string> setup_warnings() const { return {}; }
  /// Appends its history.csv column names (units in the names). `columns` holds those of the
  /// measures before it: a measure may look one up (its value is then in `row` at add_values).
  /// Called once before the loop; bad input throws InputError.
  virtual void add_columns(std::vector<std::string>& columns) { (void)columns; }
  /// Columns that are only known once the solver has run a cycle (contact resultants): appended
  /// once, at the first history row, after every measure's add_columns; so only the last
  /// measures with columns may use it (values and columns must stay in the same order).
  virtual void add_late_columns(const ExplicitSolver& s, std::vector<std::string>& columns) const {
    (void)s, (void)columns;
  }
  /// Appends its values at a history row: one per column it added (add_columns, then
  /// add_late_columns), in the same order. `row` holds the values of the measures before it.
  virtual void add_values(const ExplicitSolver& s, std::vector<double>& row) const {
    (void)s, (void)row;
  }
  /// Whether it adds columns computed from the whole history once the run has ended
  /// (add_final_columns): the run then keeps every history row.
  virtual bool needs_final_columns() const { return false; }
  /// Once at the end: columns that need every row (a filter without lag needs the samples after
  /// a row), appended to `columns` and to each row of `rows`; history.csv is then rewritten
  /// (atomically) with them.
  virtual void add_final_columns(std::vector<std::string>& columns,
                                 std::vector<std::vector<double>>& rows) const {
    (void)columns, (void)rows;
  }
  /// After a cycle in which hexahedra were eroded (the erosions are logged before): warning lines
  /// of what the measure saw change (e.g. stitch joints released).
  virtual std::vector<std::string> after_erosion(const ExplicitSolver& s) {
    (void)s;
    return {};
  }
  /// Writes its summary.json entries at the solver's current state (called at every frame and
  /// once at the end). A value that could not be measured is null.
  virtual void add_summary(const ExplicitSolver& s, nlohmann::json& summary) const {
    (void)s, (void)summary;
  }
  /// At every result frame: cell fields of its own. Several measures may fill one field (one
  /// fabric each): a measure adds the field if it is not there yet and fills its own cells.
  virtual void add_frame_fields(const ExplicitSolver& s,
                                std::vector<MeasureCellField>& fields) const {
    (void)s, (void)fields;
  }
  /// Once at the end of the run: files of its own in the output folder (written atomically),
  /// e.g. a drape's ring_shear.csv. Returns the file names it wrote.
  virtual std::vector<std::string> write_files(const ExplicitSolver& s,
                                               const std::filesystem::path& dir) const {
    (void)s, (void)dir;
    return {};
  }
  /// What the measure carries from one row to the next (most carry nothing), into a checkpoint
  /// and back into the same measure of a rebuilt run (fem/checkpoint.hpp).
  virtual void save_state(CheckpointWriter& w) const { (void)w; }
  virtual void load_state(CheckpointReader& r) { (void)r; }
};

/// Mean displacement of a set of nodes at the solver's current state (m).
inline V3 mean_displacement(const ExplicitSolver& s, const std::vector<std::int32_t>& nodes) {
  auto X = s.x.view();
  auto X0 = s.x0.view();
  V3 sum;
  for (auto i : nodes) {
    const auto k = 3 * static_cast<std::size_t>(i);
    sum += V3{X[k] - X0[k], X[k + 1] - X0[k + 1], X[k + 2] - X0[k + 2]};
  }
  return (1.0 / static_cast<double>(nodes.size())) * sum;
}

/// A JSON number, or null when not finite (a value that could not be measured).
inline nlohmann::json json_number(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}

}  // namespace ncfsim::fem
