#pragma once
// The stage kinds' names (`[case] kind`, summary.json `stage`), spelled once. What each kind does
// is its record in the registry (workflow/stages/stage_registry.cpp); the case readers and the
// hand-off checks below the workflow (a transfer reads an engine run's results, a crush a
// transfer's) name the kinds through these.
namespace ncfsim::fem::stage_kind {

inline constexpr const char* kEngine = "engine";
inline constexpr const char* kCrush = "crush";
inline constexpr const char* kKinematicDrape = "kinematic_drape";
inline constexpr const char* kTransfer = "transfer";
inline constexpr const char* kCalibration = "calibration";
inline constexpr const char* kWorkflow = "workflow";

}  // namespace ncfsim::fem::stage_kind
