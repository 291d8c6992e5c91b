#pragma once
// `ncfsim compare`: the shear rings of the paper's Fig. 18 measure (drape/ring_measure.hpp) from
// several sources side by side: meso drape runs, kinematic drape (fishnet) stages, macro drape
// runs (their ring_shear.csv columns shear_deg, kinematic_shear_deg, macro_shear_deg), the stages
// of a workflow folder, and macro results computed elsewhere (.vtu / .csv, ring_import.hpp). Per
// source the four quadrant maxima (drape::quadrant_maxima), per pair the RMS, mean and largest
// difference over the azimuths both sources hit; one plot of all rings. docs/cli.md, docs/output.md
// ("Comparison outputs").
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "drape/ring_measure.hpp"
#include "workflow/compare/ring_import.hpp"
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

struct RingSource {
  std::string label;
  std::string kind;            // meso | macro | kinematic | imported
  std::filesystem::path path;  // the run folder or the imported file
  std::string column;          // ring_shear.csv column, or the imported field
  std::vector<drape::RingSample> ring;
  ImportedRing import;            // imported sources: how the file was read (ring moved to `ring`)
  nlohmann::json summary_maxima;  // a run folder's summary.json quadrant keys (null: none)
};

/// The ring sources of a run folder (a workflow folder: of its stages), one per shear column of
/// its ring_shear.csv. InputError naming the folder when it holds none.
std::vector<RingSource> read_run_folder(const std::filesystem::path& dir, const std::string& label);

struct RingDifference {
  int azimuths = 0;  // compared: the azimuths (within 1e-6 deg) that both hit
  double rms_deg = std::numeric_limits<double>::quiet_NaN();
  double mean_deg = std::numeric_limits<double>::quiet_NaN();     // a - b
  double max_abs_deg = std::numeric_limits<double>::quiet_NaN();  // largest |a - b|
  double max_at_azimuth_deg = std::numeric_limits<double>::quiet_NaN();
};

/// a - b over the azimuths both rings hit: sqrt(mean (a-b)^2), mean (a-b), max |a-b| and where.
RingDifference ring_difference(const std::vector<drape::RingSample>& a,
                               const std::vector<drape::RingSample>& b);

struct CompareOptions {
  std::vector<std::string> sources;  // PATH or LABEL=PATH: run folders, .vtu / .csv files
  std::filesystem::path out_dir = "comparison";
  RingImportOptions import;  // the ring the imported files are read on, field, tolerance
  bool overwrite = false;
  Verbosity verbosity = Verbosity::Normal;
};

/// Reads every source (bad input: InputError, nothing written), then writes the comparison into
/// out_dir (comparison.csv, pairs.csv, comparison.md, rings.csv, imported_<label>.csv,
/// summary.json, figures/ring_shear_compared.png, log.txt). Returns the exit code.
int compare_rings(const CompareOptions& opt);

}  // namespace ncfsim::workflow
