#pragma once
// `ncfsim compare-crush`: punch force against stroke of several crushes side by side, ncfsim's
// crush runs (their history.csv) and curves from other solvers (a CSV with stroke_m and force_N,
// e.g. an OpenRadioss run of the exported deck: scripts/radioss-check). Per source, from the
// force filtered at a CFC class: the elastic slope (the secant of the first loading between 10 %
// and 50 % of the peak), the peak and its stroke, and the energy absorbed to the stroke all sources
// reach (the raw force's work); the differences from the first source; one plot. docs/cli.md,
// docs/export.md.
#include <filesystem>
#include <string>
#include <vector>

#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

struct CrushCurve {
  std::string label;
  std::filesystem::path path;
  std::vector<double> time, stroke, force;  // s (empty: none), m, N
};

struct CrushMeasures {
  double elastic_slope = 0;  // N/m
  double peak_force = 0;     // N, filtered
  double peak_stroke = 0;    // m
  double energy = 0;         // J, to the common stroke
  double common_stroke = 0;  // m
};

/// A crush run folder (history.csv: time, punch_displacement_m, punch_force_N) or a CSV with
/// stroke_m and force_N (time_s optional); LABEL=PATH names it. InputError naming the file and
/// the missing column.
CrushCurve read_crush_curve(const std::string& source);

/// The measures of a curve, its force filtered at `cfc` (SAE J211; 0: raw, or a curve without
/// times), the energy to `common_stroke`.
CrushMeasures measure_crush(const CrushCurve& c, double cfc, double common_stroke);

struct CrushCompareOptions {
  std::vector<std::string> sources;
  std::filesystem::path out_dir = "crush_comparison";
  double cfc = 600;
  bool overwrite = false;
  Verbosity verbosity = Verbosity::Normal;
};

/// Writes crush_comparison.csv, comparison.md, summary.json and figures/crush_compared.png into
/// out_dir; returns the exit code (0).
int compare_crushes(const CrushCompareOptions& opt);

}  // namespace ncfsim::workflow
