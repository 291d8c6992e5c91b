#include "workflow/calibrate/calibrate_macro.hpp"

#include <fmt/format.h>
#include <toml++/toml.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "drape/fabric.hpp"
#include "drape/stitch_calibration.hpp"
#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"
#include "workflow/output/output_files.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

ResampledCurve resample_frame_curve(const std::vector<double>& angle_deg,
                                    const std::vector<double>& force, double step_deg,
                                    double max_deg) {
  if (!(step_deg > 0 && step_deg <= 45))
    throw std::invalid_argument(fmt::format("the step {} deg is outside (0, 45]", step_deg));
  if (angle_deg.size() != force.size())
    throw std::invalid_argument("as many forces as angles are needed");
  std::vector<std::pair<double, double>> rows;
  for (std::size_t i = 0; i < angle_deg.size(); ++i)
    if (std::isfinite(angle_deg[i]) && std::isfinite(force[i]))
      rows.emplace_back(angle_deg[i], force[i]);
  if (rows.size() < 2) throw std::invalid_argument("fewer than two rows with an angle and a force");
  std::sort(rows.begin(), rows.end());
  const double top = rows.back().first;
  const double last = max_deg > 0 ? std::min(max_deg, top) : top;
  const int n = static_cast<int>(std::floor(last / step_deg + 1e-9));
  if (n < 1)
    throw std::invalid_argument(
        fmt::format("the data reach {:.3g} deg, less than one step of {} deg", top, step_deg));
  const double h = 0.5 * step_deg;
  ResampledCurve out;
  out.curve.angle_deg.push_back(0.0);
  out.curve.force.push_back(0.0);
  out.fitted.push_back(0.0);
  double running = 0;
  std::vector<std::pair<double, double>> drops;  // (angle, relative drop) clipped
  for (int k = 1; k <= n; ++k) {
    const double a = k * step_deg;
    // Least-squares line f = c0 + c1 (g - a) over the rows within a +- h.
    double s0 = 0, s1 = 0, s2 = 0, t0 = 0, t1 = 0;
    for (const auto& [g, f] : rows) {
      if (std::abs(g - a) > h) continue;
      const double d = g - a;
      s0 += 1, s1 += d, s2 += d * d, t0 += f, t1 += f * d;
    }
    const double det = s0 * s2 - s1 * s1;
    double value;
    if (s0 >= 2 && det > 1e-12 * std::max(1.0, s0 * s2)) {
      value = (t0 * s2 - t1 * s1) / det;
    } else {  // too few rows in the window: linear interpolation between the neighbours
      const auto it = std::lower_bound(rows.begin(), rows.end(), std::make_pair(a, -1e300));
      if (it == rows.end())
        value = rows.back().second;
      else if (it == rows.begin())
        value = it->second;
      else {
        const auto& [g0, f0] = *(it - 1);
        const auto& [g1, f1] = *it;
        value = g1 > g0 ? f0 + (f1 - f0) * (a - g0) / (g1 - g0) : f1;
      }
    }
    out.fitted.push_back(value);
    if (value < running) {
      ++out.n_clipped;
      drops.emplace_back(a, (running - value) / running);
      value = running;
    }
    running = value;
    out.curve.angle_deg.push_back(a);
    out.curve.force.push_back(value);
  }
  // A drop counts where the force had reached 1 % of the curve's largest (below: the noise of
  // a force that has not started, e.g. the unstitched frame before its tows touch).
  for (const auto& [a, drop] : drops)
    if (curve_force(out.curve, a) >= 0.01 * running) {
      if (out.clipped_from_deg < 0) out.clipped_from_deg = a;
      out.largest_drop = std::max(out.largest_drop, drop);
    }
  return out;
}

double curve_force(const FrameCurve& c, double a) {
  const auto& x = c.angle_deg;
  const auto& y = c.force;
  if (x.empty()) return 0;
  if (x.size() == 1) return y[0];
  std::size_t i = 1;
  while (i + 1 < x.size() && x[i] < a) ++i;
  return y[i - 1] + (y[i] - y[i - 1]) * (a - x[i - 1]) / (x[i] - x[i - 1]);
}

FrameCurve average_curves(const FrameCurve& a, const FrameCurve& b) {
  FrameCurve m;
  const double end = std::min(a.angle_deg.back(), b.angle_deg.back());
  double running = 0;
  for (std::size_t i = 0; i < a.angle_deg.size() && a.angle_deg[i] <= end + 1e-9; ++i) {
    running = std::max(running, 0.5 * (a.force[i] + curve_force(b, a.angle_deg[i])));
    m.angle_deg.push_back(a.angle_deg[i]);
    m.force.push_back(running);
  }
  return m;
}

double bias_extension_force_from_curve(const FrameCurve& c, double H, double W, double D) {
  const drape::BiasExtensionCoupon coupon{H, W};
  const double g = drape::central_shear_angle(coupon, D);
  const double dD = 1e-6 * (H - W);
  const double dg =
      (drape::central_shear_angle(coupon, D + dD) - drape::central_shear_angle(coupon, D - dD)) /
      (2 * dD);
  const double deg = 180 / M_PI;
  const double area_a = W * (H - 1.5 * W), area_b = W * W;
  return dg * (area_a * curve_force(c, g * deg) * std::cos(g) +
               0.5 * area_b * curve_force(c, 0.5 * g * deg) * std::cos(0.5 * g));
}

double pillar_shear_force(const std::vector<double>& strain, const std::vector<double>& force,
                          double gauge, double angle_deg) {
  const double g = angle_deg * M_PI / 180, e = std::sqrt(2.0) * std::cos(M_PI / 4 - g / 2) - 1;
  if (e <= 0 || strain.size() < 2) return 0.0;
  std::size_t k = 1;
  while (k + 1 < strain.size() && e > strain[k]) ++k;
  const double tension =
      force[k - 1] + (force[k] - force[k - 1]) * (e - strain[k - 1]) / (strain[k] - strain[k - 1]);
  const double de_dg = std::sqrt(2.0) / 2 * std::sin(M_PI / 4 - g / 2);
  return tension * de_dg / gauge / std::cos(g);
}

namespace {

struct MesoRun {
  std::string summary_case;  // summary.json "case" (and the ncfsim version that ran it)
  std::filesystem::path history;
  CsvTable table;
};

MesoRun read_run(const std::filesystem::path& dir, const std::string& option) {
  const std::string d = dir.string();
  if (!std::filesystem::is_directory(dir))
    throw InputError(d, option, "not a folder (give the output folder of a meso run)");
  const auto summary = dir / "summary.json";
  if (!std::filesystem::is_regular_file(summary))
    throw InputError(summary.string(), option, "no summary.json: not a run folder");
  nlohmann::json js;
  try {
    js = read_json_file(summary);
  } catch (const std::exception& e) {
    throw InputError(summary.string(), option, e.what());
  }
  const std::string status = js.is_object() ? js.value("status", "") : "";
  if (status != "completed")
    throw InputError(summary.string(), "status",
                     "the run did not complete (status '" + status + "')", status, "completed");
  MesoRun r;
  r.summary_case = js.value("case", "") + ", ncfsim " + js.value("ncfsim_version", "?");
  r.history = dir / "history.csv";
  if (!std::filesystem::is_regular_file(r.history))
    throw InputError(r.history.string(), option, "no history.csv in the run folder");
  try {
    r.table = read_csv(r.history);
  } catch (const std::exception& e) {
    throw InputError(r.history.string(), option, e.what());
  }
  return r;
}

std::vector<double> column(const MesoRun& r, const std::string& name) {
  try {
    return r.table.column(name);
  } catch (const std::out_of_range&) {
    std::string cols;
    for (const auto& c : r.table.columns)
      if (c.find("frame") != std::string::npos || c.find("grip") != std::string::npos ||
          c.find("pull") != std::string::npos || c.find("shear") != std::string::npos)
        cols += (cols.empty() ? "" : ", ") + c;
    throw InputError(r.history.string(), name,
                     "no such column" + (cols.empty() ? std::string() : "; related: " + cols));
  }
}

struct FrameSource {
  std::string text;  // for the file's comments
  ResampledCurve curve;
};

FrameSource frame_curve(const std::filesystem::path& dir, const std::string& option,
                        const MacroCalibrationOptions& o) {
  const MesoRun r = read_run(dir, option);
  const auto g = column(r, o.frame + "_shear_angle_deg");
  const auto f = column(r, o.frame + "_normalised_shear_force_N_per_m");
  FrameSource s;
  try {
    s.curve = resample_frame_curve(g, f, o.step_deg, o.max_angle_deg);
  } catch (const std::invalid_argument& e) {
    throw InputError(r.history.string(), o.frame + "_shear_angle_deg", e.what());
  }
  double top = 0;
  for (double v : g)
    if (std::isfinite(v)) top = std::max(top, v);
  s.text = fmt::format("{} (case {}, {} rows, frame to {:.1f} deg)",
                       std::filesystem::absolute(r.history).lexically_normal().string(),
                       r.summary_case, r.table.rows.size(), top);
  return s;
}

// The positive meso frame's 'I' pillar law and stitch gauge, from the case.toml of its run.
struct PillarSource {
  std::string law_name;
  std::vector<double> strain, force;
  double linear_density = 0, gauge = 0;
  bool tension_only = true;
};

// The positive run's case as it ran: its case file with its includes, base and --set resolved
// (summary.json's case_file and overrides), where that file is still there; else the copy in the
// run folder as it is.
toml::table run_case(const std::filesystem::path& dir, std::string& f) {
  f = (dir / "case.toml").string();
  try {
    const nlohmann::json s = read_json_file(dir / "summary.json");
    const std::filesystem::path original = s.value("case_file", std::string());
    if (!original.empty() && std::filesystem::is_regular_file(original)) {
      f = original.string();
      return fem::CaseDocument::load(original, s.value("overrides", std::vector<std::string>{}))
          .root();
    }
  } catch (const std::exception&) {
    f = (dir / "case.toml").string();  // no summary, or a case that no longer reads: the copy
  }
  try {
    return toml::parse_file(f);
  } catch (const toml::parse_error& e) {
    throw InputError(f, "",
                     std::string("--stitch-bars reads the positive run's case: ") +
                         std::string(e.description()));
  }
}

PillarSource pillar_source(const std::filesystem::path& dir) {
  std::string f;
  const toml::table root = run_case(dir, f);
  const toml::array* fabrics = root["mesh"]["fabric"].as_array();
  if (!fabrics || fabrics->empty() || !fabrics->get(0)->is_table())
    throw InputError(f, "mesh.fabric", "--stitch-bars needs the meso frame's [[mesh.fabric]]");
  const toml::table& entry = *fabrics->get(0)->as_table();
  // A blanket that names its fabric (fabric = "NAME") takes the fabric's keys from [fabric.NAME].
  const toml::table* own = root["fabric"][entry["fabric"].value_or(std::string())].as_table();
  auto key = [&](const char* k) {
    return entry.contains(k) || !own ? toml::node_view<const toml::node>(entry[k])
                                     : toml::node_view<const toml::node>((*own)[k]);
  };
  PillarSource p;
  p.law_name = key("stitch_law_I").value_or(std::string());
  if (p.law_name.empty())
    throw InputError(f, "mesh.fabric[0].stitch_law_I", "--stitch-bars needs the pillar law");
  drape::FabricSpec spec;
  spec.tow_width = key("tow_width").value_or(spec.tow_width);
  spec.tow_gap = key("tow_gap").value_or(spec.tow_gap);
  spec.stitch_gauge = key("stitch_gauge").value_or(0.0);
  p.gauge = spec.gauge();
  if (const toml::array* laws = root["bar_law"].as_array())
    for (const auto& n : *laws) {
      const toml::table* law = n.as_table();
      if (!law || (*law)["name"].value_or(std::string()) != p.law_name) continue;
      if (const auto* a = (*law)["strain"].as_array())
        for (const auto& v : *a) p.strain.push_back(v.value_or(NAN));
      if (const auto* a = (*law)["force"].as_array())
        for (const auto& v : *a) p.force.push_back(v.value_or(NAN));
      p.linear_density = (*law)["linear_density"].value_or(0.0);
      p.tension_only = (*law)["tension_only"].value_or(true);
    }
  if (p.strain.size() < 2 || p.strain.size() != p.force.size())
    throw InputError(f, "bar_law",
                     "--stitch-bars: no tabulated [[bar_law]] '" + p.law_name +
                         "' (strain, force) in the positive run's case");
  return p;
}

std::string clip_note(const std::string& what, const ResampledCurve& c) {
  if (c.clipped_from_deg < 0)
    return c.n_clipped ? fmt::format(
                             "{}: {} point(s) held at the running maximum below 1 % of the "
                             "largest force (noise before the force starts)",
                             what, c.n_clipped)
                       : std::string();
  return fmt::format(
      "{}: the meso force falls from {:.1f} deg (by up to {:.0f} % of its running maximum); "
      "the macro curve is held at the running maximum from there",
      what, c.clipped_from_deg, 100 * c.largest_drop);
}

std::string numbers(const std::vector<double>& v, const char* fmt_spec) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i) s += ", ";
    s += fmt::format(fmt::runtime(fmt_spec), v[i]);
  }
  return s;
}

// The meso bias-extension run against the curve's ideal-trellis force (a check, not a fit).
std::vector<BiasCheckRow> bias_check(const std::filesystem::path& dir, const std::string& option,
                                     const FrameCurve& curve, const MacroCalibrationOptions& o,
                                     std::string& source) {
  const MesoRun r = read_run(dir, option);
  // The pull axis: the grip column that moved the most.
  std::string axis;
  double moved = 0;
  for (const char* a : {"x", "y", "z"}) {
    const std::string c = std::string("grip_displacement_") + a + "_m";
    if (std::find(r.table.columns.begin(), r.table.columns.end(), c) == r.table.columns.end())
      continue;
    const auto v = r.table.column(c);
    if (!v.empty() && std::abs(v.back()) > moved) moved = std::abs(v.back()), axis = a;
  }
  if (axis.empty())
    throw InputError(
        r.history.string(), "grip_displacement_x_m",
        "no grip_displacement_{x,y,z}_m column (the bias-extension cases' grip probe)");
  const auto D = r.table.column("grip_displacement_" + axis + "_m");
  const auto F = column(r, "pull_reaction_" + axis + "_N");
  std::vector<double> S;
  if (std::find(r.table.columns.begin(), r.table.columns.end(), "centre_shear_angle_deg") !=
      r.table.columns.end())
    S = r.table.column("centre_shear_angle_deg");
  source = fmt::format("{} (case {}, pulled along {})",
                       std::filesystem::absolute(r.history).lexically_normal().string(),
                       r.summary_case, axis);
  std::vector<BiasCheckRow> rows;
  for (double mm : {5.0, 10.0, 20.0, 30.0, 40.0}) {
    const double d = 1e-3 * mm;
    // The first row past d, interpolated with the one before.
    std::size_t i = 1;
    while (i < D.size() && std::abs(D[i]) < d) ++i;
    if (i >= D.size()) break;
    const double d0 = std::abs(D[i - 1]), d1 = std::abs(D[i]);
    const double w = d1 > d0 ? (d - d0) / (d1 - d0) : 1.0;
    BiasCheckRow row;
    row.extension_mm = mm;
    row.meso_force_N = std::abs(F[i - 1] + w * (F[i] - F[i - 1]));
    row.meso_shear_deg =
        S.empty() ? std::numeric_limits<double>::quiet_NaN() : S[i - 1] + w * (S[i] - S[i - 1]);
    row.curve_force_N = bias_extension_force_from_curve(curve, o.coupon_length, o.coupon_width, d);
    row.eq2_shear_deg =
        180 / M_PI * drape::central_shear_angle({o.coupon_length, o.coupon_width}, d);
    rows.push_back(row);
  }
  return rows;
}

// calibrate_macro's options from the command line: bad input names the option.
void check_options(const MacroCalibrationOptions& o) {
  const std::string out = o.output.string();
  if (o.output.empty() || std::filesystem::is_directory(o.output))
    throw InputError(out, "--output", "give a file name for the [[membrane_law]] block");
  if (!(o.step_deg > 0 && o.step_deg <= 10))
    throw InputError::out_of_range("calibrate macro", "--step", o.step_deg,
                                   Range::open_closed(0, 10));
  for (const auto& [key, v] : {std::pair{"--areal-density", o.areal_density},
                               {"--fibre-tension-stiffness", o.fibre_tension_stiffness},
                               {"--bending-stiffness", o.bending_stiffness}})
    if (!(v > 0)) throw InputError::out_of_range("calibrate macro", key, v, Range::positive());
  if (!(o.fibre_compression_ratio >= 0 && o.fibre_compression_ratio <= 1))
    throw InputError::out_of_range("calibrate macro", "--fibre-compression-ratio",
                                   o.fibre_compression_ratio, Range::closed(0, 1));
  if (!(o.coupon_length > 1.5 * o.coupon_width && o.coupon_width > 0))
    throw InputError("calibrate macro", "--coupon-length",
                     "the bias-extension coupon needs H > 1.5 W > 0");
}

// --stitch-bars: the positive curve becomes the tows' share, the frame less its pillars'
// kinematic force, held monotone (the pillars' force grows faster than the frame's below a few
// degrees, where both are noise).
void subtract_pillars(const PillarSource& pillars, MacroCalibration& cal) {
  double top = 0;
  int held = 0;
  for (std::size_t i = 0; i < cal.positive.curve.angle_deg.size(); ++i) {
    double& f = cal.positive.curve.force[i];
    f -= pillar_shear_force(pillars.strain, pillars.force, pillars.gauge,
                            cal.positive.curve.angle_deg[i]);
    if (f < top || f < 0) ++held;
    f = std::max({f, top, 0.0});
    top = f;
  }
  if (held)
    cal.notes.push_back(
        fmt::format("positive, less the pillars: {} point(s) held at the running maximum", held));
}

// The [[membrane_law]] file: where each curve came from, the constants, the block(s).
std::string law_file_text(const MacroCalibrationOptions& o, const MacroCalibration& cal,
                          const FrameSource& pos, const FrameSource& neg, const FrameSource& uns,
                          const PillarSource& pillars) {
  std::string t = fmt::format(
      "# Macro fabric membrane law calibrated by `ncfsim calibrate macro` (ncfsim {}) from the "
      "meso\n"
      "# picture-frame virtual tests: normalised shear force F_sh = frame force x L_frame /\n"
      "# L_fabric^2 / (2 cos theta) (N/m, Harrison) against shear angle, resampled every {} deg\n"
      "# (a least-squares line through the history rows within +-{} deg of each angle), 0 at 0 "
      "deg.\n"
      "#   positive shear (wales along the opening diagonal, stitch stretched):\n#     {}\n"
      "#   negative shear (wales across it): {}\n",
      kVersion, o.step_deg, 0.5 * o.step_deg, pos.text, neg.text);
  if (o.stitch_bars)
    t += fmt::format(
        "# --stitch-bars: the stitch is carried by bars sewn on the shells ([[mesh.shell_stitch]]\n"
        "# with law = \"{}\", below): the positive curve is the tows' share, the positive frame\n"
        "# less its 'I' pillars' kinematic force (Eq. 4-5: the pillar law and gauge {:.4g} m of\n"
        "# the positive run's case.toml).\n",
        pillars.law_name, pillars.gauge);
  if (o.symmetric)
    t += "# --symmetric: one curve, the mean of the two signs (the classic symmetric macro law).\n";
  else
    t += "# Positive -> shear_angle_deg / shear_force, negative -> negative_shear_angle_deg /\n"
         "# negative_shear_force (the law's positive shear closes the angle around material axis\n"
         "# 1, the wale).\n";
  for (const auto& n : cal.notes) t += "# MONOTONE: " + n + ".\n";
  if (cal.notes.empty()) t += "# Monotone as measured: no clipping was needed.\n";
  t += fmt::format(
      "# Not from the frame (calibrate macro options): areal_density, fibre_angles_deg,\n"
      "# fibre_tension_stiffness, fibre_compression_ratio, bending_stiffness.\n"
      "[[membrane_law]]\nname = \"{}\"\ntype = \"fabric\"\nareal_density = {:g}              # "
      "kg/m^2\n"
      "fibre_angles_deg = [{:.1f}, {:.1f}]   # from material axis 1 (the wale)\n"
      "fibre_tension_stiffness = {:g}    # N/m per family\nfibre_compression_ratio = {:g}\n"
      "bending_stiffness = {:g}          # N m\n",
      o.name, o.areal_density, o.fibre_angles_deg[0], o.fibre_angles_deg[1],
      o.fibre_tension_stiffness, o.fibre_compression_ratio, o.bending_stiffness);
  auto curve_lines = [&](const FrameCurve& c, const char* akey, const char* fkey) {
    t += fmt::format("{} = [{}]\n{} = [{}]   # N/m\n", akey, numbers(c.angle_deg, "{:g}"), fkey,
                     numbers(c.force, "{:.4g}"));
  };
  if (o.symmetric) {
    curve_lines(cal.symmetric, "shear_angle_deg", "shear_force");
  } else {
    curve_lines(cal.positive.curve, "shear_angle_deg", "shear_force");
    curve_lines(cal.negative.curve, "negative_shear_angle_deg", "negative_shear_force");
  }
  if (o.stitch_bars)
    t += fmt::format(
        "\n# The 'I' pillar law of the meso frame (its [[bar_law]] '{}'), for the stitch bars:\n"
        "[[bar_law]]\nname = \"{}\"\ntype = \"tabulated\"\ntension_only = {}\n"
        "linear_density = {:g}\nstrain = [{}]\nforce = [{}]   # N\n",
        pillars.law_name, pillars.law_name, pillars.tension_only ? "true" : "false",
        pillars.linear_density, numbers(pillars.strain, "{:g}"), numbers(pillars.force, "{:g}"));
  if (!o.unstitched.empty()) {
    t += fmt::format(
        "\n# The same fabric without its stitch (symmetric), from the unstitched meso frame:\n#   "
        "{}\n"
        "[[membrane_law]]\nname = \"{}_unstitched\"\ntype = \"fabric\"\nareal_density = {:g}\n"
        "fibre_angles_deg = [{:.1f}, {:.1f}]\nfibre_tension_stiffness = {:g}\n"
        "fibre_compression_ratio = {:g}\nbending_stiffness = {:g}\n",
        uns.text, o.name, o.areal_density, o.fibre_angles_deg[0], o.fibre_angles_deg[1],
        o.fibre_tension_stiffness, o.fibre_compression_ratio, o.bending_stiffness);
    curve_lines(cal.unstitched.curve, "shear_angle_deg", "shear_force");
  }
  return t;
}

// Optional check against the meso bias-extension runs: comments in the file `t`, notes and
// rows in `cal`.
void add_bias_checks(const MacroCalibrationOptions& o, MacroCalibration& cal, std::string& t) {
  const double H = o.coupon_length, W = o.coupon_width;
  for (const auto& [dir, sign, rows] :
       {std::tuple{&o.bias_positive, "positive", &cal.bias_positive},
        {&o.bias_negative, "negative", &cal.bias_negative}}) {
    if (dir->empty()) continue;
    const FrameCurve& c = o.symmetric                       ? cal.symmetric
                          : std::string(sign) == "positive" ? cal.positive.curve
                                                            : cal.negative.curve;
    std::string src;
    *rows = bias_check(*dir, std::string("--bias-") + sign, c, o, src);
    t += fmt::format(
        "\n# Check, {} bias extension ({} x {} m coupon): the meso run {}\n"
        "# against the force this curve gives an ideal trellis (pin-jointed, Eq. 2 kinematics):\n"
        "#   extension mm | meso force N | curve force N | meso centre shear deg | Eq. 2 deg\n",
        sign, H, W, src);
    for (const auto& r : *rows) {
      t += fmt::format("#   {:5.0f} | {:8.3g} | {:8.3g} | {:6.1f} | {:6.1f}\n", r.extension_mm,
                       r.meso_force_N, r.curve_force_N, r.meso_shear_deg, r.eq2_shear_deg);
      cal.notes.push_back(fmt::format(
          "bias extension {} at {:.0f} mm: meso {:.3g} N, ideal trellis with the curve {:.3g} N "
          "(centre {:.1f} deg, Eq. 2 {:.1f} deg)",
          sign, r.extension_mm, r.meso_force_N, r.curve_force_N, r.meso_shear_deg,
          r.eq2_shear_deg));
    }
  }
}

// --curves-csv: the meso curves on the macro grid (a reference for the chain).
std::string curves_csv_text(const MacroCalibrationOptions& o, const MacroCalibration& cal,
                            const FrameSource& pos, const FrameSource& neg,
                            const FrameSource& uns) {
  std::string csv = fmt::format(
      "# Meso picture-frame curves on the grid of `ncfsim calibrate macro` (ncfsim {}):\n"
      "# normalised shear force (N/m) fitted every {} deg (*_fitted: the meso curve; *_macro: "
      "the\n"
      "# law's curve, held at the running maximum). Sources:\n#   positive: {}\n#   negative: "
      "{}\n",
      kVersion, o.step_deg, pos.text, neg.text);
  if (!o.unstitched.empty()) csv += "#   unstitched: " + uns.text + "\n";
  csv += "shear_angle_deg,positive_fitted,positive_macro,negative_fitted,negative_macro";
  if (!o.unstitched.empty()) csv += ",unstitched_fitted,unstitched_macro";
  csv += "\n";
  const auto& grid = cal.positive.curve.angle_deg;
  auto at = [](const ResampledCurve& c, std::size_t i, bool fit) {
    const auto& v = fit ? c.fitted : c.curve.force;
    return i < v.size() ? fmt::format("{:.5g}", v[i]) : std::string();
  };
  for (std::size_t i = 0; i < grid.size(); ++i) {
    csv += fmt::format("{:g},{},{},{},{}", grid[i], at(cal.positive, i, true),
                       at(cal.positive, i, false), at(cal.negative, i, true),
                       at(cal.negative, i, false));
    if (!o.unstitched.empty())
      csv += "," + at(cal.unstitched, i, true) + "," + at(cal.unstitched, i, false);
    csv += "\n";
  }
  return csv;
}

}  // namespace

MacroCalibration calibrate_macro(const MacroCalibrationOptions& o) {
  check_options(o);
  MacroCalibration cal;
  const FrameSource pos = frame_curve(o.positive, "positive", o);
  const FrameSource neg = frame_curve(o.negative, "negative", o);
  cal.positive = pos.curve;
  cal.negative = neg.curve;
  FrameSource uns;
  if (!o.unstitched.empty()) {
    uns = frame_curve(o.unstitched, "--unstitched", o);
    cal.unstitched = uns.curve;
  }
  for (const auto& [what, c] : {std::pair{"positive", &cal.positive},
                                {"negative", &cal.negative},
                                {"unstitched", &cal.unstitched}})
    if (const auto n = clip_note(what, *c); !n.empty()) cal.notes.push_back(n);
  PillarSource pillars;
  if (o.stitch_bars) {
    if (o.symmetric)
      throw InputError("", "--stitch-bars", "give either --stitch-bars or --symmetric");
    pillars = pillar_source(o.positive);
    subtract_pillars(pillars, cal);
  }
  if (o.symmetric) cal.symmetric = average_curves(cal.positive.curve, cal.negative.curve);
  std::string t = law_file_text(o, cal, pos, neg, uns, pillars);
  add_bias_checks(o, cal, t);
  if (o.output.has_parent_path()) std::filesystem::create_directories(o.output.parent_path());
  write_file_atomically(o.output, t);
  if (!o.curves_csv.empty()) {
    if (o.curves_csv.has_parent_path())
      std::filesystem::create_directories(o.curves_csv.parent_path());
    write_file_atomically(o.curves_csv, curves_csv_text(o, cal, pos, neg, uns));
  }
  cal.toml = std::move(t);
  return cal;
}

}  // namespace ncfsim::workflow
