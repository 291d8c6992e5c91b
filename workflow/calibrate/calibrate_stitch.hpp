#pragma once
// `ncfsim calibrate stitch`: a stitch law from bias-extension force data (drape/stitch_calibration).
#include <filesystem>
#include <string>

#include "drape/stitch_calibration.hpp"

namespace ncfsim::workflow {

struct StitchCalibrationOptions {
  std::filesystem::path data;          // CSV with a header row
  std::string extension_column = "extension_m";
  std::string force_column = "force_N";
  double extension_scale = 1.0;        // to m (1e-3 for mm columns)
  double force_scale = 1.0;            // to N
  drape::ShearSign sign = drape::ShearSign::Positive;
  drape::BiasExtensionCoupon coupon;
  double max_shear_deg = 30;
  int points = 12;
  std::filesystem::path out_dir = "stitch_calibration";
  std::string law_name = "stitch";
};

/// Writes stitch_law.csv (strain, force_N), stitch_law.toml (a [[bar_law]] table) and the figures
/// stitch_law.png and stitch_fit.png (data against the forward model of the law) into out_dir.
/// Throws InputError for bad data (file, column, values).
void calibrate_stitch(const StitchCalibrationOptions& o);

}  // namespace ncfsim::workflow
