#pragma once
// Runs an engine case to its output folder: log.txt, history.csv, summary.json, results.h5/.xdmf
// (and .vtu/.pvd on request), figures/*.png, report.html on request.
#include <filesystem>
#include <string>
#include <vector>

#include "workflow/case/engine_case.hpp"
#include "workflow/run/run_output.hpp"

namespace ncfsim::workflow {

struct RunOptions {
  std::filesystem::path out_dir;      // empty: results/<case name>
  Verbosity verbosity = Verbosity::Normal;
  double progress_interval_s = 5.0;   // wall seconds between progress lines
  std::vector<std::string> overrides; // --set items, echoed into summary.json
  int ranks = 1;                      // --np: MPI ranks requested
  std::vector<std::string> force_stages;  // --force: workflow stages rerun although unchanged
  bool overwrite = false;  // --overwrite: write into a folder holding files ncfsim did not write
  bool resume = false;      // --resume: continue the interrupted run in out_dir from its checkpoint
  std::string inputs_hash;  // the workflow's hash of the stage's inputs (stored in the checkpoint)
};

/// Exit codes of the command line (docs/cli.md).
enum ExitCode : int { kSuccess = 0, kOtherError = 1, kBadInput = 2, kNumericalFailure = 3 };

/// Runs the case; returns the exit code. Bad input found before the run throws InputError.
int run_engine_case(EngineCase& ec, const RunOptions& options);
/// The same run on an MPI rank other than the root (docs/parallel.md): it integrates its share and
/// takes part in the root's output gathers; the root writes every file. Returns the exit code.
int run_engine_worker(EngineCase& ec, const RunOptions& options);

/// The folder a run (of any stage) writes to: options.out_dir, or results/<case name>.
std::filesystem::path output_folder(const std::string& case_name, const RunOptions& options);
inline std::filesystem::path output_folder(const EngineCase& ec, const RunOptions& options) {
  return output_folder(ec.name, options);
}

}  // namespace ncfsim::workflow
