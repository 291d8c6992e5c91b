#pragma once
// A case for the explicit engine, read from TOML: mesh (structured blocks and bar lines),
// materials, bar laws, parts, constraints, loads, rigid tools, time controls, output, figures. The
// keys are documented in docs/case-file.md; every value is range-checked before any run, once, by
// the module that owns its section (fem/case, drape/case; docs/architecture.md).
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include "drape/probe_specs.hpp"
#include "fem/memory_estimate.hpp"
#include "fem/model.hpp"
#include "impact/case/crush_case.hpp"

namespace ncfsim::fem {
class CaseTypeRegistry;  // fem/case/case_context.hpp
}

namespace ncfsim::workflow {

using drape::BendingLengthProbe;
using drape::FabricSummary;
using drape::ShearProbe;

/// Mean displacement of a set of nodes, written to history.csv as <name>_displacement_{x,y,z}_m.
struct DisplacementProbe {
  std::string name;
  std::vector<std::int32_t> nodes;
};

/// One hexahedron's stress and strain in its material axes (2nd Piola-Kirchhoff, Green-Lagrange,
/// what the material law sees), written to history.csv as <name>_stress_<ij>_Pa and
/// <name>_strain_<ij> (ij = 11 22 33 12 23 13, engineering shear strain).
struct ElementProbe {
  std::string name;
  std::int64_t element = 0;  // user id
};

/// A named constraint set whose reaction goes to history.csv as <name>_reaction_{x,y,z}_N.
struct ReactionProbe {
  std::string name;
  std::vector<std::int32_t> nodes;
};

/// Values of history columns at given values of another column, into summary.json as
/// <label>_at_<x in display units><unit> (e.g. force_N_at_10mm). `analytic` adds the bias-extension
/// shear angle of Eq. 2 (analytic_shear_angle_deg_at_...).
struct SummarySamples {
  std::string x;                 // history column, e.g. clamp_displacement_x_m
  double x_display_scale = 1e3;  // 1e3: the keys name mm
  std::string x_unit = "mm";
  std::vector<double> at;                                    // in display units
  std::vector<std::pair<std::string, std::string>> columns;  // label -> history column
  bool bias_extension_analytic = false;
  double coupon_length = 0, coupon_width = 0;  // m (free length H, width W)
};

/// Mean of a history column over a time window, times a scale, into summary.json as <name>
/// (e.g. the friction coefficient F/P of a sled over its steady sliding).
struct SummaryMean {
  std::string name, column;
  double from_time = 0, to_time = 0, scale = 1;
  std::string
      per_column;  // if set: scale * increment of column / increment of per_column over the window
};

/// `[[output.target]]`: a number of the run's summary.json against what it should be (a paper's
/// formula written by a measure, a datum of the case): summary.json `targets` and `targets_met`,
/// a warning for one missed, the workflow report's table of virtual tests against their targets.
struct SummaryTarget {
  std::string quantity;             // a summary.json number of this run
  double target = std::nan("");     // the target value, or ...
  std::string target_quantity;      // ... another summary.json number of the run (e.g. Eq. 2's)
  double tolerance = std::nan("");  // absolute, in the quantity's unit (NaN: none)
  double relative_tolerance = std::nan("");  // of the target (NaN: none); neither: shown only
  std::string source;                        // where the target comes from, for the report
};

struct OutputSettings {
  bool xdmf = true;     // results.h5 + results.xdmf
  bool vtu = false;     // frames/*.vtu + results.pvd
  bool figures = true;  // render figures at the end of the run
  bool report = false;  // write report.html at the end of the run
  // checkpoint.h5 (issue #22): every checkpoint_interval wall minutes (0: only at a stop), and
  // every checkpoint_every_cycles cycles (0: off; for tests: a checkpoint at a known cycle).
  double checkpoint_interval_min = 10.0;
  std::int64_t checkpoint_every_cycles = 0;
  /// What of this the memory estimate counts (fem/memory_estimate.hpp): frames, the VTU copies,
  /// the figures drawn in the run's process, and a checkpoint (a run may always write one).
  fem::OutputMemory memory() const { return {xdmf || vtu, vtu, figures, true}; }
};

/// A curve plot from history.csv: y columns against an x column.
/// A curve from another CSV (test data, a macro shell result), drawn dashed beside the run's.
struct ImportedSeries {
  std::string label;
  std::filesystem::path file;  // absolute, resolved against the case file's folder
  std::string x, y;            // column names
  double x_scale = 1.0, y_scale = 1.0;
};

/// A horizontal reference line (an analytic value), drawn dashed.
struct ReferenceLine {
  std::string label;
  double y = 0;  // in plotted units (after y_scale)
};

struct PlotSpec {
  std::string name;  // file figures/<name>.png
  std::string title;
  std::string x;               // column name
  std::vector<std::string> y;  // column names
  double x_scale = 1.0, y_scale = 1.0;
  std::string x_label, y_label;
  std::vector<ImportedSeries> imports;
  std::vector<ReferenceLine> references;
  std::string source = "history.csv";  // the run's CSV file the columns come from
};

/// A picture of the last frame coloured by a field.
struct PictureSpec {
  std::string name;
  std::string field;   // a frame field (docs/output.md) or displacement_magnitude; "none"
  int component = -1;  // -1: magnitude of a vector/tensor field
  std::string camera;  // iso | top | front
  std::string title;
  std::string follow_part;  // the camera fits this part's current bounds ("" = whole model)
  double deformation_scale = 1.0;
};

struct EngineCase {
  std::filesystem::path file;
  std::string name;
  std::string kind;  // "engine"
  std::string description;
  std::string resolution;  // coarse | default | fine
  std::vector<std::string> laws_replaced;  // case.laws: "[[material]] 'dry_tow' from <file>"
  fem::Model model;
  std::vector<DisplacementProbe> probes;
  std::vector<ReactionProbe> reactions;
  std::vector<ElementProbe> element_probes;
  OutputSettings output;
  std::vector<PlotSpec> plots;
  std::vector<PictureSpec> pictures;
  std::vector<FabricSummary> fabric_summaries;
  std::vector<ShearProbe> shear_probes;
  std::vector<drape::RingShearProbe> ring_probes;
  std::vector<SummarySamples> samples;
  std::vector<BendingLengthProbe> bending;
  std::vector<SummaryMean> means;
  std::vector<SummaryTarget> targets;
  std::vector<double> frame_fabric_length;  // per picture frame: side of the fabric for normalising
  impact::CrushSpec crush;                  // [crush]: the punch's measures (kind crush)
};

/// The material types an engine case knows: fem's, then drape's (tow_biphase), then impact's
/// (tow_damage).
fem::CaseTypeRegistry engine_case_types();

/// Reads and checks a case (throws InputError naming file and key). `overrides` are --set items.
EngineCase load_engine_case(const std::filesystem::path& file,
                            const std::vector<std::string>& overrides);

}  // namespace ncfsim::workflow
