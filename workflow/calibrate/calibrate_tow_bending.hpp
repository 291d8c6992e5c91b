#pragma once
// `ncfsim calibrate tow-bending`: the tow fibre modulus E11f that gives a target ASTM D1388 bending
// length in the virtual cantilever test (the paper's procedure: a beam-theory estimate, then runs
// of the test until the simulated bending length matches).
#include <filesystem>
#include <string>
#include <vector>

#include "workflow/run/engine_run.hpp"

namespace ncfsim::workflow {

struct TowBendingCalibration {
  std::filesystem::path case_file;
  std::vector<std::string> overrides;
  double target_bending_length = 0;  // m
  double tolerance = 0.01;           // relative
  int max_runs = 6;
  std::filesystem::path out_dir = "tow_bending_calibration";
};

struct TowBendingResult {
  double E11f = 0;             // Pa
  double bending_length = 0;   // m, simulated with E11f
  int runs = 0;
  bool converged = false;
  std::size_t material_index = 0;  // the bent part's [[material]] in the case
};

/// Needs a case with an [[output.bending_length]] probe on a part of type tow_biphase. Runs go to
/// out_dir/run_<k>; out_dir/calibration.json lists every run. Throws InputError for a case that
/// cannot be calibrated.
TowBendingResult calibrate_tow_bending(const TowBendingCalibration& c);

}  // namespace ncfsim::workflow
