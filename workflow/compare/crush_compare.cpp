#include "workflow/compare/crush_compare.hpp"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "fem/errors.hpp"
#include "impact/cfc_filter.hpp"
#include "workflow/render/render.hpp"
#include "workflow/run/engine_run.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace fs = std::filesystem;

namespace {

std::vector<double> column_or_fail(const CsvTable& t, const fs::path& file,
                                   const std::string& name) {
  try {
    return t.column(name);
  } catch (const std::out_of_range&) {
    throw InputError(file.string(), name, "no such column (a crush curve needs it)");
  }
}

// The force filtered at a CFC class where the curve has uniform times fine enough for it (SAE
// J211: sampled at 10 x the class at least), else raw.
std::vector<double> filtered_force(const CrushCurve& c, double cfc) {
  if (cfc <= 0 || c.time.size() != c.force.size() || c.time.size() < 2) return c.force;
  const double dt = (c.time.back() - c.time.front()) / static_cast<double>(c.time.size() - 1);
  return dt > 0 && 1.0 / dt >= 10 * cfc ? impact::cfc_filter(c.force, dt, cfc) : c.force;
}

bool has_column(const CsvTable& t, const std::string& name) {
  return std::find(t.columns.begin(), t.columns.end(), name) != t.columns.end();
}

// Trapezoidal work of f over s from its start to `to` (interpolated at the end).
double work_to(const std::vector<double>& s, const std::vector<double>& f, double to) {
  double w = 0;
  for (std::size_t i = 1; i < s.size(); ++i) {
    if (s[i - 1] >= to) break;
    double s1 = s[i], f1 = f[i];
    if (s1 > to && s1 > s[i - 1]) {
      const double a = (to - s[i - 1]) / (s1 - s[i - 1]);
      f1 = f[i - 1] + a * (f1 - f[i - 1]), s1 = to;
    }
    w += 0.5 * (f[i - 1] + f1) * (s1 - s[i - 1]);
  }
  return w;
}

}  // namespace

CrushCurve read_crush_curve(const std::string& source) {
  CrushCurve c;
  const auto eq = source.find('=');
  c.path = eq == std::string::npos ? source : source.substr(eq + 1);
  c.label = eq == std::string::npos ? c.path.filename().string() : source.substr(0, eq);
  if (c.label.empty()) c.label = c.path.parent_path().filename().string();
  if (fs::is_directory(c.path)) {
    const fs::path file = c.path / "history.csv";
    if (!fs::is_regular_file(file))
      throw InputError(c.path.string(), "", "no history.csv: not the folder of a crush run");
    const CsvTable t = read_csv(file);
    c.time = column_or_fail(t, file, "time");
    c.stroke = column_or_fail(t, file, "punch_displacement_m");
    c.force = column_or_fail(t, file, "punch_force_N");
  } else if (fs::is_regular_file(c.path)) {
    const CsvTable t = read_csv(c.path);
    c.stroke = column_or_fail(t, c.path, "stroke_m");
    c.force = column_or_fail(t, c.path, "force_N");
    if (has_column(t, "time_s")) c.time = t.column("time_s");
  } else {
    throw InputError(c.path.string(), "", "neither a crush run's folder nor a CSV file");
  }
  if (c.stroke.size() < 3)
    throw InputError(c.path.string(), "", "fewer than 3 points: not a crush curve");
  return c;
}

FirstLoading first_loading(const CrushCurve& c) {
  const auto& f = c.force;
  const double largest = *std::max_element(f.begin(), f.end());
  FirstLoading l;
  if (!(largest > 0)) return l;
  std::size_t loaded = 0;
  while (loaded + 1 < f.size() && f[loaded] < 0.05 * largest) ++loaded;
  std::size_t onset = loaded;
  while (onset > 0 && f[onset - 1] > 0.01 * largest) --onset;
  if (onset > 0) --onset;
  std::size_t peak = onset;
  for (std::size_t i = onset; i < f.size(); ++i) {
    if (f[i] > f[peak]) peak = i;
    if (f[i] < f[peak] - 0.05 * largest) break;  // a fall, not the ringing of a rising force
  }
  l.contact_stroke = c.stroke[onset], l.peak_stroke = c.stroke[peak], l.peak_force = f[peak];
  return l;
}

CrushMeasures measure_crush(const CrushCurve& c, double cfc, double common_stroke,
                            double slope_window) {
  CrushMeasures m;
  const std::vector<double> f = filtered_force(c, cfc);
  std::size_t peak = 0;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (f[i] > f[peak]) peak = i;
  m.peak_force = f[peak], m.peak_stroke = c.stroke[peak];
  const FirstLoading l = first_loading(c);
  m.first = l;
  m.contact_stroke = l.contact_stroke;
  m.slope_window = slope_window > 0 ? slope_window : l.peak_stroke - l.contact_stroke;
  // The least-squares line of the raw force over the window's samples: at a crush's speed the
  // CFC filter resolves no less than about a millimetre of stroke, the first loading is shorter.
  double n = 0, sx = 0, sy = 0, sxx = 0, sxy = 0;
  bool covered = false;
  for (std::size_t i = 0; i < c.force.size(); ++i) {
    const double x = c.stroke[i] - m.contact_stroke;
    if (x < -1e-3 * m.slope_window) continue;
    if (x > m.slope_window * (1 + 1e-3)) {
      covered = true;
      break;
    }
    covered = x >= m.slope_window * (1 - 1e-3);
    n += 1, sx += x, sy += c.force[i], sxx += x * x, sxy += x * c.force[i];
  }
  const double det = n * sxx - sx * sx;
  m.elastic_slope = n >= 3 && det > 0 && covered ? (n * sxy - sx * sy) / det : std::nan("");
  m.common_stroke = common_stroke;
  m.energy = work_to(c.stroke, c.force, common_stroke);
  return m;
}

int compare_crushes(const CrushCompareOptions& opt) {
  if (opt.sources.empty()) throw InputError("", "sources", "no crush to compare");
  if (opt.cfc < 0) throw InputError("", "--cfc", "must be >= 0 (0: the raw force)");
  std::vector<CrushCurve> curves;
  for (const auto& s : opt.sources) curves.push_back(read_crush_curve(s));
  double common = 1e300;
  for (const auto& c : curves)
    common = std::min(common, *std::max_element(c.stroke.begin(), c.stroke.end()));

  const OutputFolder folder =
      OutputFolder::claim(opt.out_dir, opt.overwrite, {}, "crush comparison");
  const fs::path& dir = opt.out_dir;
  auto log = make_run_logger(dir, opt.verbosity);
  log->info("ncfsim {} | compare-crush | {} curves -> {} (CFC {:g})", kVersion, curves.size(),
            dir.string(), opt.cfc);
  std::vector<CrushMeasures> m;
  // The window: as asked, else the shortest first loading of all (from contact to the first
  // peak), so that every source's slope is taken before anything fails in any of them.
  double window = opt.slope_window;
  if (!(window > 0)) {
    window = 1e300;
    for (const auto& c : curves) {
      const auto l = first_loading(c);
      if (l.peak_stroke > l.contact_stroke)
        window = std::min(window, l.peak_stroke - l.contact_stroke);
    }
    if (window == 1e300) window = 0;
  }
  for (const auto& c : curves) {
    m.push_back(measure_crush(c, opt.cfc, common, window));
    if (std::isnan(m.back().elastic_slope))
      log->warn(
          "{}: no elastic slope: the curve has fewer than 3 samples over the {:.3f} mm "
          "after its contact at {:.3f} mm, or ends before it (--slope-window)",
          c.label, window * 1e3, m.back().contact_stroke * 1e3);
  }
  const auto diff = [](double a, double b) { return b != 0 ? 100.0 * (a - b) / b : std::nan(""); };
  std::string csv =
      "label,elastic_slope_N_per_mm,peak_force_N,peak_stroke_mm,energy_J,to_stroke_mm,"
      "slope_diff_pct,peak_diff_pct,energy_diff_pct,contact_stroke_mm,first_peak_N,"
      "first_peak_after_contact_mm\n";
  std::string md = fmt::format(
      "# Crush curves compared (force filtered at CFC {:g}; elastic slope: the least-squares "
      "line of the raw force over the first {:.3f} mm after each curve's contact; energy to "
      "{:.3f} mm, the stroke all reach)\n\n| source | contact at (mm) | elastic slope (N/mm) | "
      "first peak, raw (N at mm after contact) | peak (N) | at (mm) | energy (J) | slope, peak, "
      "energy against {} |\n|---|---|---|---|---|---|---|---|\n",
      opt.cfc, window * 1e3, common * 1e3, curves[0].label);
  nlohmann::json js = {{"stage", "compare-crush"},
                       {"ncfsim_version", kVersion},
                       {"status", "completed"},
                       {"cfc_class", opt.cfc},
                       {"slope_window_m", window},
                       {"common_stroke_m", common},
                       {"sources", nlohmann::json::array()}};
  for (std::size_t i = 0; i < curves.size(); ++i) {
    const auto& a = m[i];
    const double ds = diff(a.elastic_slope, m[0].elastic_slope),
                 dp = diff(a.peak_force, m[0].peak_force), de = diff(a.energy, m[0].energy);
    csv += fmt::format(
        "{},{:.6g},{:.6g},{:.6g},{:.6g},{:.6g},{:.4g},{:.4g},{:.4g},{:.6g},{:.6g},{:.6g}\n",
        curves[i].label, a.elastic_slope * 1e-3, a.peak_force, a.peak_stroke * 1e3, a.energy,
        common * 1e3, ds, dp, de, a.contact_stroke * 1e3, a.first.peak_force,
        (a.first.peak_stroke - a.first.contact_stroke) * 1e3);
    md += fmt::format(
        "| {} | {:.3f} | {:.1f} | {:.1f} at {:.3f} | {:.1f} | {:.3f} | {:.4f} | {} |\n",
        curves[i].label, a.contact_stroke * 1e3, a.elastic_slope * 1e-3, a.first.peak_force,
        (a.first.peak_stroke - a.first.contact_stroke) * 1e3, a.peak_force, a.peak_stroke * 1e3,
        a.energy,
        i == 0 ? std::string("-") : fmt::format("{:+.1f} %, {:+.1f} %, {:+.1f} %", ds, dp, de));
    js["sources"].push_back({{"label", curves[i].label},
                             {"path", curves[i].path.string()},
                             {"contact_stroke_m", a.contact_stroke},
                             {"elastic_slope_N_per_m", a.elastic_slope},
                             {"first_peak_force_N", a.first.peak_force},
                             {"first_peak_stroke_m", a.first.peak_stroke},
                             {"peak_force_N", a.peak_force},
                             {"peak_stroke_m", a.peak_stroke},
                             {"energy_J", a.energy}});
    log->info("{}: elastic slope {:.1f} N/mm, peak {:.1f} N at {:.3f} mm, {:.4f} J to {:.3f} mm",
              curves[i].label, a.elastic_slope * 1e-3, a.peak_force, a.peak_stroke * 1e3, a.energy,
              common * 1e3);
  }
  render::CurvePlot plot;
  plot.title = fmt::format("Punch force against stroke (CFC {:g})", opt.cfc);
  plot.x_label = "punch stroke [mm]";
  plot.y_label = "punch force [N]";
  for (const auto& c : curves) {
    render::CurveSeries sr;
    sr.label = c.label;
    const std::vector<double> f = filtered_force(c, opt.cfc);
    for (std::size_t i = 0; i < c.stroke.size(); ++i)
      sr.x.push_back(c.stroke[i] * 1e3), sr.y.push_back(f[i]);
    plot.series.push_back(std::move(sr));
  }
  const fs::path png = dir / "figures" / "crush_compared.png";
  try {
    fs::create_directories(png.parent_path());
    render::plot_curves_png(plot, png);
    js["figure"] = "figures/crush_compared.png";
    md += "\n![crush curves](figures/crush_compared.png)\n";
  } catch (const std::exception& e) {
    js["figure"] = nullptr;
    js["figure_error"] = e.what();
    log->warn("the crush plot was not drawn: {}", e.what());
  }
  write_file_atomically(dir / "crush_comparison.csv", csv);
  write_file_atomically(dir / "comparison.md", md);
  write_file_atomically(dir / "summary.json", js.dump(2) + "\n");
  log->info("wrote crush_comparison.csv, comparison.md, summary.json{}",
            js["figure"].is_null() ? "" : ", figures/crush_compared.png");
  folder.finish();
  return kSuccess;
}

}  // namespace ncfsim::workflow
