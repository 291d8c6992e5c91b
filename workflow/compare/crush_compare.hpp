#pragma once
// `ncfsim compare-crush`: punch force against stroke of several crushes side by side, ncfsim's
// crush runs (their history.csv) and curves from other solvers (a CSV with stroke_m and force_N,
// e.g. an OpenRadioss run of the exported deck: scripts/radioss-check). Per source, from the
// force filtered at a CFC class: the elastic slope (the least-squares line of the raw force over
// one window of stroke after each curve's own contact, by default the shortest first loading of
// all: a share of the peak would move with where the curve ends and span failures), the peak and
// its stroke, and the energy absorbed to the stroke all sources
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

/// A curve's first loading: where the raw force last leaves zero (1 % of its largest) before it
/// first passes 5 %, and its first peak (the largest force before it falls below it by 5 % of
/// the largest).
struct FirstLoading {
  double contact_stroke = 0, peak_stroke = 0;  // m
  double peak_force = 0;                       // N, raw
};
struct CrushMeasures {
  double contact_stroke = 0;  // m, where the force last leaves zero before the first loading
  double slope_window = 0;    // m, of stroke after the contact
  double elastic_slope = 0;   // N/m, NaN where the curve has too little of the window
  FirstLoading first;         // the first loading, raw
  double peak_force = 0;     // N, filtered
  double peak_stroke = 0;    // m
  double energy = 0;         // J, to the common stroke
  double common_stroke = 0;  // m
};

/// A crush run folder (history.csv: time, punch_displacement_m, punch_force_N) or a CSV with
/// stroke_m and force_N (time_s optional); LABEL=PATH names it. InputError naming the file and
/// the missing column.
CrushCurve read_crush_curve(const std::string& source);

FirstLoading first_loading(const CrushCurve& c);

/// The measures of a curve, its force filtered at `cfc` (SAE J211; 0: raw, or a curve without
/// times), the elastic slope over `slope_window` of stroke after its contact (0: its own first
/// loading), the energy to `common_stroke`.
CrushMeasures measure_crush(const CrushCurve& c, double cfc, double common_stroke,
                            double slope_window);

struct CrushCompareOptions {
  std::vector<std::string> sources;
  std::filesystem::path out_dir = "crush_comparison";
  double cfc = 600;
  double slope_window = 0;  // m; 0: the shortest first loading of the sources
  bool overwrite = false;
  Verbosity verbosity = Verbosity::Normal;
};

/// Writes crush_comparison.csv, comparison.md, summary.json and figures/crush_compared.png into
/// out_dir; returns the exit code (0).
int compare_crushes(const CrushCompareOptions& opt);

}  // namespace ncfsim::workflow
