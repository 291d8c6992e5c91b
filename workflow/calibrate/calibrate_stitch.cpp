#include "workflow/calibrate/calibrate_stitch.hpp"

#include <cmath>
#include <sstream>

#include <fmt/format.h>

#include "fem/errors.hpp"
#include "render.hpp"
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

void calibrate_stitch(const StitchCalibrationOptions& o) {
  const std::string file = o.data.string();
  if (!std::filesystem::exists(o.data)) throw InputError(file, "", "no such data file");
  CsvTable t;
  try {
    t = read_csv(o.data);
  } catch (const std::exception& e) {
    throw InputError(file, "", e.what());
  }
  std::vector<double> D, F;
  try {
    D = t.column(o.extension_column);
    F = t.column(o.force_column);
  } catch (const std::out_of_range& e) {
    std::string cols;
    for (const auto& c : t.columns) cols += (cols.empty() ? "" : ", ") + c;
    throw InputError(file, "", std::string(e.what()) + "; the file has: " + cols);
  }
  for (double& v : D) v *= o.extension_scale;
  for (double& v : F) v *= o.force_scale;
  drape::StitchLaw law;
  try {
    law = drape::calibrate_stitch_law(o.coupon, o.sign, D, F, o.max_shear_deg, o.points);
  } catch (const std::invalid_argument& e) {
    throw InputError(file, o.extension_column, e.what());
  }
  std::filesystem::create_directories(o.out_dir / "figures");
  std::string csv = "strain,force_N\n", toml;
  for (std::size_t k = 0; k < law.strain.size(); ++k) csv += fmt::format("{:.9g},{:.9g}\n", law.strain[k], law.force[k]);
  write_file_atomically(o.out_dir / "stitch_law.csv", csv);
  const char* seg = o.sign == drape::ShearSign::Positive ? "I (pillar)" : "Lambda (underlap)";
  toml = fmt::format("# {} stitch law calibrated by `ncfsim calibrate stitch` from {}\n# (coupon {} x {} m, stitch length {} m, gauge {} m, up to {} deg shear)\n[[bar_law]]\nname = \"{}\"\ntype = \"tabulated\"\ntension_only = true\nlinear_density = 1.0e-5   # kg/m, set to the stitch yarn's\nstrain = [",
                     seg, file, o.coupon.length, o.coupon.width, o.coupon.stitch_length, o.coupon.gauge, o.max_shear_deg, o.law_name);
  for (std::size_t k = 0; k < law.strain.size(); ++k) toml += fmt::format("{}{:.6g}", k ? ", " : "", law.strain[k]);
  toml += "]\nforce = [";
  for (std::size_t k = 0; k < law.force.size(); ++k) toml += fmt::format("{}{:.6g}", k ? ", " : "", law.force[k]);
  toml += "]   # N per stitch segment\n";
  write_file_atomically(o.out_dir / "stitch_law.toml", toml);

  std::string why;
  if (render::offscreen_rendering_available(&why)) {
    render::CurvePlot p;
    p.title = fmt::format("{} stitch law", seg);
    p.x_label = "stitch strain [-]";
    p.y_label = "force per stitch segment [N]";
    p.series.push_back({"calibrated law", law.strain, law.force});
    render::plot_curves_png(p, o.out_dir / "figures" / "stitch_law.png");
    render::CurvePlot fit;
    fit.title = "Bias extension: data and the calibrated law";
    fit.x_label = "extension [mm]";
    fit.y_label = "force [N]";
    std::vector<double> Dmm, Dk;
    for (double d : D) Dmm.push_back(1e3 * d);
    render::CurveSeries data{"data", Dmm, F};
    data.markers_only = true;
    fit.series.push_back(data);
    fit.series.push_back({"model with the law", Dmm, drape::coupon_force(o.coupon, o.sign, law, D)});
    render::plot_curves_png(fit, o.out_dir / "figures" / "stitch_fit.png");
  }
}

}  // namespace ncfsim::workflow
