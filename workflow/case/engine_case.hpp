#pragma once
// A case for the explicit engine, read from TOML: mesh (structured blocks and bar lines), materials,
// bar laws, parts, constraints, loads, rigid tools, time controls, output, figures.
// The keys are documented in docs/case-file.md; every value is range-checked here, before any run.
#include <filesystem>
#include <string>
#include <vector>

#include "fem/model.hpp"

namespace ncfsim::workflow {

/// Mean displacement of a set of nodes, written to history.csv as <name>_displacement_{x,y,z}_m.
struct DisplacementProbe {
  std::string name;
  std::vector<std::int32_t> nodes;
};

/// A named constraint set whose reaction goes to history.csv as <name>_reaction_{x,y,z}_N.
struct ReactionProbe {
  std::string name;
  std::vector<std::int32_t> nodes;
};

/// In-plane shear angle between the fibres of two plies over the elements whose reference centroid
/// lies in a box (a material region): 90 deg minus the angle between the mean fibre directions.
/// history.csv: <name>_shear_angle_deg.
struct ShearProbe {
  std::string name;
  int part_a = -1, part_b = -1;
  std::array<double, 3> box_min{}, box_max{};
};

/// Values of history columns at given values of another column, into summary.json as
/// <label>_at_<x in display units><unit> (e.g. force_N_at_10mm). `analytic` adds the bias-extension
/// shear angle of Eq. 2 (analytic_shear_angle_deg_at_...).
struct SummarySamples {
  std::string x;                    // history column, e.g. clamp_displacement_x_m
  double x_display_scale = 1e3;     // 1e3: the keys name mm
  std::string x_unit = "mm";
  std::vector<double> at;           // in display units
  std::vector<std::pair<std::string, std::string>> columns;  // label -> history column
  bool bias_extension_analytic = false;
  double coupon_length = 0, coupon_width = 0;  // m (free length H, width W)
};

/// ASTM D1388 cantilever bending of a strip clamped at `root` and overhanging to `tip` under
/// gravity: tip angle theta below the horizontal, bending length c = O (cos(theta/2) / (8 tan
/// theta))^(1/3), flexural rigidity G = w c^3 (w = weight per area), and the beam-theory c of the
/// part's material, (E1 t^3 / 12 / w)^(1/3). history.csv: <name>_tip_angle_deg.
struct BendingLengthProbe {
  std::string name;
  int part = -1;
  std::vector<std::int32_t> root, tip;
};

/// Mean of a history column over a time window, times a scale, into summary.json as <name>
/// (e.g. the friction coefficient F/P of a sled over its steady sliding).
struct SummaryMean {
  std::string name, column;
  double from_time = 0, to_time = 0, scale = 1;
  std::string per_column;  // if set: scale * increment of column / increment of per_column over the window
};

struct OutputSettings {
  bool xdmf = true;           // results.h5 + results.xdmf
  bool vtu = false;           // frames/*.vtu + results.pvd
  bool figures = true;        // render figures at the end of the run
  bool report = false;        // write report.html at the end of the run
};

/// A curve plot from history.csv: y columns against an x column.
/// A curve from another CSV (test data, a macro shell result), drawn dashed beside the run's.
struct ImportedSeries {
  std::string label;
  std::filesystem::path file;       // absolute, resolved against the case file's folder
  std::string x, y;                 // column names
  double x_scale = 1.0, y_scale = 1.0;
};

/// A horizontal reference line (an analytic value), drawn dashed.
struct ReferenceLine {
  std::string label;
  double y = 0;                     // in plotted units (after y_scale)
};

struct PlotSpec {
  std::string name;                 // file figures/<name>.png
  std::string title;
  std::string x;                    // column name
  std::vector<std::string> y;       // column names
  double x_scale = 1.0, y_scale = 1.0;
  std::string x_label, y_label;
  std::vector<ImportedSeries> imports;
  std::vector<ReferenceLine> references;
};

/// A picture of the last frame coloured by a field.
struct PictureSpec {
  std::string name;
  std::string field;        // a frame field (docs/output.md) or displacement_magnitude; "none"
  int component = -1;       // -1: magnitude of a vector/tensor field
  std::string camera;       // iso | top | front
  std::string title;
  std::string follow_part;  // the camera fits this part's current bounds ("" = whole model)
  double deformation_scale = 1.0;
};

/// What a [[mesh.fabric]] generated (echoed in the log and summary.json).
struct FabricSummary {
  std::string name;
  std::size_t tows = 0, dropped_tows = 0, penetrations = 0, connections = 0;
  double tow_thickness = 0;
  // Index of its stitch-to-tow connection in model.contacts (-1: none).
  int connection_contact = -1;
};

struct EngineCase {
  std::filesystem::path file;
  std::string name;
  std::string kind;          // "engine"
  std::string description;
  std::string resolution;    // coarse | default | fine
  fem::Model model;
  std::vector<DisplacementProbe> probes;
  std::vector<ReactionProbe> reactions;
  OutputSettings output;
  std::vector<PlotSpec> plots;
  std::vector<PictureSpec> pictures;
  std::vector<FabricSummary> fabric_summaries;
  std::vector<ShearProbe> shear_probes;
  std::vector<SummarySamples> samples;
  std::vector<BendingLengthProbe> bending;
  std::vector<SummaryMean> means;
  std::vector<double> frame_fabric_length;  // per picture frame: side of the fabric for normalising
};

/// Reads and checks a case (throws InputError naming file and key). `overrides` are --set items.
EngineCase load_engine_case(const std::filesystem::path& file, const std::vector<std::string>& overrides);

}  // namespace ncfsim::workflow
