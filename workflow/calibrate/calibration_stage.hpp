#pragma once
// Stage "calibration": one of the calibrations of `ncfsim calibrate` run from a case file, so that
// a workflow chains a fabric's virtual tests to the laws calibrated from them and those laws to
// the drapes that use them (issue #43; docs/case-file.md, "Calibration"). It writes laws.toml,
// whole [[material]] / [[membrane_law]] / [[bar_law]] tables that a downstream case takes in
// `case.laws` (a workflow's `inputs = { "case.laws" = "<this stage>" }`), and summary.json with
// what came from which test and, where there is one, the target it was calibrated to.
//
//   [calibration]
//   method = "macro"            # macro | tow_bending | stitch
//   positive = "frame_pos"      # macro: the picture-frame run folders (a workflow hands them over)
//   negative = "frame_neg"
#include <filesystem>
#include <string>

#include "workflow/calibrate/calibrate_macro.hpp"
#include "workflow/calibrate/calibrate_stitch.hpp"
#include "workflow/calibrate/calibrate_tow_bending.hpp"
#include "workflow/stages/stage_registry.hpp"

namespace ncfsim::workflow {

/// The laws file a calibration stage writes into its folder (its hand-off).
inline constexpr const char* kLawsFile = "laws.toml";

struct CalibrationCase {
  std::filesystem::path file;
  std::string name, description;
  std::string method;  // macro | tow_bending | stitch
  MacroCalibrationOptions macro;
  TowBendingCalibration bending;
  StitchCalibrationOptions stitch;
  /// The virtual tests (run folders or case files) each law came from, for the summary.
  std::vector<std::pair<std::string, std::filesystem::path>> sources;
};

/// Reads a calibration case (`[case] kind = "calibration"`). Paths are relative to the case file;
/// a run folder may be given by a file in it (a workflow's input hands a stage's results.h5),
/// and must hold a run's summary.json where `runs_must_exist` (a run; `ncfsim check` reads the
/// keys only). Throws InputError naming the file and the key.
CalibrationCase load_calibration_case(const std::filesystem::path& file,
                                      const std::vector<std::string>& overrides,
                                      bool runs_must_exist = false);

int run_calibration_stage(const StageCall& call);
int check_calibration_stage(const StageCall& call);

}  // namespace ncfsim::workflow
