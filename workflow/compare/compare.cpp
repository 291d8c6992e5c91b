#include "workflow/compare/compare.hpp"

#include <fmt/format.h>
#include <spdlog/logger.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

#include "fem/case/stage_kinds.hpp"
#include "fem/errors.hpp"
#include "fem/run_measure.hpp"
#include "workflow/render/render.hpp"
#include "workflow/run/engine_run.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace fs = std::filesystem;
using nlohmann::json;

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// ring_shear.csv columns and the kind of drape each comes from, with its summary.json prefix.
struct ShearColumn {
  const char *column, *kind, *summary_prefix;
};
constexpr ShearColumn kColumns[] = {{"shear_deg", "meso", ""},
                                    {"macro_shear_deg", "macro", "macro_"},
                                    {"kinematic_shear_deg", "kinematic", "kinematic_"}};

std::string folder_label(const fs::path& p) {
  const fs::path q = p.has_filename() ? p : p.parent_path();
  const std::string s = q.filename().string();
  return s.empty() || s == "." ? fs::absolute(q).lexically_normal().filename().string() : s;
}

std::string file_safe(const std::string& s) {
  std::string o = s;
  for (auto& c : o)
    if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_' || c == '.')) c = '_';
  return o;
}

std::string csv_safe(const std::string& s) {
  std::string o = s;
  for (auto& c : o)
    if (c == ',' || c == '\n' || c == '"') c = ';';
  return o;
}

std::string md_safe(const std::string& s) {
  std::string o;
  for (char c : s) o += c == '|' ? std::string("\\|") : std::string(1, c);
  return o;
}

// One ring from a ring_shear.csv column.
std::vector<drape::RingSample> ring_column(const CsvTable& t, const std::string& column,
                                           const fs::path& csv) {
  const auto az = t.column("azimuth_deg"), y = t.column(column);
  std::vector<double> hit, x, yy, z;
  try {
    hit = t.column("hit");
    x = t.column("x_m"), yy = t.column("y_m"), z = t.column("z_m");
  } catch (const std::out_of_range&) {
    throw InputError(csv.string(), "",
                     "missing column hit, x_m, y_m or z_m (not a ring_shear.csv of ncfsim)");
  }
  std::vector<drape::RingSample> ring(az.size());
  for (std::size_t i = 0; i < az.size(); ++i) {
    ring[i].azimuth_deg = az[i];
    ring[i].hit = std::isfinite(y[i]) && (column != "shear_deg" || hit[i] > 0.5);
    ring[i].shear_deg = ring[i].hit ? y[i] : 0.0;
    ring[i].point = {x[i], yy[i], z[i]};
  }
  return ring;
}

int hits(const std::vector<drape::RingSample>& r) {
  return static_cast<int>(std::count_if(r.begin(), r.end(), [](const auto& s) { return s.hit; }));
}

// [label=]path -> (label, path): an existing path as given wins over a split at '='.
std::pair<std::string, fs::path> split_source(const std::string& arg) {
  std::error_code ec;
  if (fs::exists(arg, ec)) return {"", arg};
  const auto eq = arg.find('=');
  if (eq != std::string::npos && eq > 0) return {arg.substr(0, eq), arg.substr(eq + 1)};
  return {"", arg};
}

bool same_ring(const std::vector<drape::RingSample>& a, const std::vector<drape::RingSample>& b) {
  if (a.size() != b.size()) return false;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i].hit != b[i].hit || std::abs(a[i].azimuth_deg - b[i].azimuth_deg) > 1e-6 ||
        std::abs(a[i].shear_deg - b[i].shear_deg) > 1e-9)
      return false;
  return true;
}

json number_or_null(double v) { return std::isfinite(v) ? json(v) : json(nullptr); }

std::string cell(double v, const char* spec = "{:.3f}") {
  return std::isfinite(v) ? fmt::format(fmt::runtime(spec), v) : std::string("-");
}

// The quadrant maxima, NaN for a quadrant without a hit.
std::array<double, 4> maxima(const std::vector<drape::RingSample>& ring) {
  const auto q = drape::quadrant_maxima(ring);
  std::array<double, 4> m{};
  for (std::size_t k = 0; k < 4; ++k) m[k] = q.samples[k] > 0 ? q.max_shear_deg[k] : kNaN;
  return m;
}

std::string v3(const fem::V3& v) { return fmt::format("[{:.6g}, {:.6g}, {:.6g}]", v.x, v.y, v.z); }

}  // namespace

std::vector<RingSource> read_run_folder(const fs::path& dir, const std::string& label) {
  const fs::path csv = dir / "ring_shear.csv";
  const json summary = read_json_file(dir / "summary.json");
  std::vector<RingSource> out;
  if (!fs::exists(csv)) {
    // A workflow folder: the ring of each of its stages that measured one.
    if (summary.is_object() && summary.value("stage", "") == fem::stage_kind::kWorkflow &&
        summary.contains("stages") && summary["stages"].is_array()) {
      for (const auto& st : summary["stages"]) {
        if (!st.is_object() || !st.contains("folder") || !st["folder"].is_string()) continue;
        const fs::path sub = dir / st["folder"].get<std::string>();
        if (!fs::exists(sub / "ring_shear.csv")) continue;
        auto part = read_run_folder(sub, label + "/" + st.value("name", folder_label(sub)));
        out.insert(out.end(), part.begin(), part.end());
      }
      if (!out.empty()) return out;
    }
    throw InputError(dir.string(), "",
                     "holds no ring_shear.csv (give the output folder of a meso drape with "
                     "[[output.ring_shear]], of a kinematic_drape or macro drape stage, or of a "
                     "workflow with one of them)");
  }
  CsvTable t;
  try {
    t = read_csv(csv);
  } catch (const std::exception& e) {
    throw InputError(csv.string(), "", e.what());
  }
  if (std::find(t.columns.begin(), t.columns.end(), "azimuth_deg") == t.columns.end())
    throw InputError(csv.string(), "", "no column azimuth_deg (not a ring_shear.csv of ncfsim)");
  int own = 0;
  for (const auto& c : kColumns) {
    if (std::find(t.columns.begin(), t.columns.end(), c.column) == t.columns.end()) continue;
    RingSource s;
    s.kind = c.kind;
    // A shell drape that wrote its ring as shear_deg: its summary names it by the macro_ keys.
    if (s.kind == std::string("meso") && summary.is_object() &&
        !summary.contains("max_shear_deg_q1") && summary.contains("macro_max_shear_deg_q1"))
      s.kind = "macro";
    s.path = dir;
    s.column = c.column;
    s.ring = ring_column(t, c.column, csv);
    // A folder's own ring carries its label; a second ring in the same file (the meso run's
    // kinematic column) gets its kind appended.
    s.label = own++ == 0 ? label : label + " " + c.kind;
    s.summary_maxima = json::object();
    if (summary.is_object())
      for (int k = 1; k <= 4; ++k) {
        const std::string key =
            fmt::format("{}max_shear_deg_q{}", s.kind == "macro" ? "macro_" : c.summary_prefix, k);
        if (summary.contains(key)) s.summary_maxima[key] = summary[key];
      }
    out.push_back(std::move(s));
  }
  if (out.empty())
    throw InputError(csv.string(), "",
                     "no shear column (one of shear_deg, macro_shear_deg, kinematic_shear_deg)");
  return out;
}

RingDifference ring_difference(const std::vector<drape::RingSample>& a,
                               const std::vector<drape::RingSample>& b) {
  std::map<long long, double> bv;  // azimuth in micro-degrees -> value
  for (const auto& s : b)
    if (s.hit) bv[std::llround(s.azimuth_deg * 1e6)] = s.shear_deg;
  RingDifference d;
  double sq = 0, sum = 0, worst = -1;
  for (const auto& s : a) {
    if (!s.hit) continue;
    const auto it = bv.find(std::llround(s.azimuth_deg * 1e6));
    if (it == bv.end()) continue;
    const double diff = s.shear_deg - it->second;
    ++d.azimuths;
    sq += diff * diff;
    sum += diff;
    if (std::abs(diff) > worst) {
      worst = std::abs(diff);
      d.max_at_azimuth_deg = s.azimuth_deg;
    }
  }
  if (d.azimuths > 0) {
    d.rms_deg = std::sqrt(sq / d.azimuths);
    d.mean_deg = sum / d.azimuths;
    d.max_abs_deg = worst;
  }
  return d;
}

namespace {

// The ring the imported files are read on, checked (bad input names the option).
RingImportOptions checked_import(const CompareOptions& opt) {
  if (opt.sources.empty())
    throw InputError("", "sources", "give at least one run folder or .vtu / .csv file");
  if (opt.out_dir.empty()) throw InputError("", "--output", "an empty output folder");
  RingImportOptions imp = opt.import;
  drape::RingSpec& ring = imp.ring;
  if (!(norm(ring.axis) > 0) || !std::isfinite(norm(ring.axis)))
    throw InputError("", "--ring-axis", "must be a finite, non-zero vector");
  ring.axis = normalized(ring.axis);
  if (!std::isfinite(norm(ring.centre)) || !std::isfinite(norm(ring.zero_direction)))
    throw InputError("", "--ring-centre / --ring-zero-direction", "must be finite");
  if (!std::isfinite(ring.height))
    throw InputError::out_of_range("", "--ring-height", ring.height, Range{});
  if (!(ring.step_deg > 0 && ring.step_deg <= 90))
    throw InputError::out_of_range("", "--ring-step", ring.step_deg, Range::open_closed(0, 90));
  try {
    ring.validate();
  } catch (const std::invalid_argument& e) {
    throw InputError("", "--ring-zero-direction", e.what());
  }
  if (!(opt.import.tolerance >= 0) || !std::isfinite(opt.import.tolerance))
    throw InputError::out_of_range("", "--tolerance", opt.import.tolerance, Range::non_negative());
  return imp;
}

// Every source read before anything is written: bad input leaves no output folder. `notes` are
// logged once the folder (and its log.txt) exists. Labels are made unique (columns of
// rings.csv, legend entries).
std::vector<RingSource> read_sources(const CompareOptions& opt, const RingImportOptions& imp,
                                     std::vector<std::string>& notes) {
  const drape::RingSpec& ring = imp.ring;
  std::vector<RingSource> sources;
  std::error_code ec;
  for (const auto& arg : opt.sources) {
    auto [label, path] = split_source(arg);
    if (!fs::exists(path, ec))
      throw InputError(path.string(), "", "no such file or folder (a source of ncfsim compare)");
    if (fs::exists(opt.out_dir, ec) && fs::equivalent(path, opt.out_dir, ec))
      throw InputError(opt.out_dir.string(), "--output",
                       "is one of the sources; write the comparison into another folder");
    if (fs::is_directory(path)) {
      for (auto& s : read_run_folder(path, label.empty() ? folder_label(path) : label)) {
        bool dup = false;
        for (const auto& o : sources)
          dup =
              dup || (s.kind == "kinematic" && o.kind == "kinematic" && same_ring(s.ring, o.ring));
        if (dup) {
          notes.push_back(fmt::format("{}: its {} ring equals one already read; left out",
                                      s.path.string(), s.column));
          continue;
        }
        // Its ring should lie where the imported files are read: the hits' height.
        for (const auto& r : s.ring) {
          if (!r.hit) continue;
          const double h = dot(r.point - ring.centre, ring.axis);
          if (std::abs(h - ring.height) > 1e-6) {
            notes.push_back(fmt::format(
                "warning: {}: its ring lies {:.4g} m above the reference plane, not at the ring "
                "height {:.4g} m the imported files are read at (--ring-height)",
                s.path.string(), h, ring.height));
          }
          break;
        }
        sources.push_back(std::move(s));
      }
    } else {
      RingSource s;
      s.kind = "imported";
      s.path = path;
      s.label = label.empty() ? path.stem().string() : label;
      s.import = import_ring(path, imp);
      s.ring = std::move(s.import.ring);
      s.column = s.import.field;
      sources.push_back(std::move(s));
    }
  }
  for (std::size_t i = 0; i < sources.size(); ++i)
    for (int n = 2;; ++n) {
      bool clash = false;
      for (std::size_t j = 0; j < i; ++j) clash = clash || sources[j].label == sources[i].label;
      if (!clash) break;
      sources[i].label += fmt::format(" ({})", n);
    }
  return sources;
}

// What the comparison writes: summary.json, comparison.csv, pairs.csv, comparison.md.
struct ComparisonFiles {
  json js = json::object();
  std::string qcsv, pcsv, md;
};

// Per source: its quadrant maxima (the summary's own keys checked against them).
void add_source_maxima(const std::vector<RingSource>& sources, const drape::RingSpec& ring,
                       spdlog::logger& log, ComparisonFiles& f) {
  f.qcsv =
      "label,kind,source,column,ring_samples,ring_samples_hit,max_shear_deg_q1,max_shear_deg_q2,"
      "max_shear_deg_q3,max_shear_deg_q4\n";
  f.md = "# Shear round the ring\n\n";
  f.md += fmt::format(
      "Ring {:.4g} m above {} along the axis {}, azimuth from {} (the wale direction), every "
      "{:.4g} deg; quadrants: the 90 deg sectors centred on 0, 90, 180, 270 deg.\n\n",
      ring.height, v3(ring.centre), v3(ring.axis), v3(ring.zero_direction), ring.step_deg);
  f.md +=
      "| source | kind | from | azimuths hit | q1 max [deg] | q2 max [deg] | q3 max [deg] | q4 "
      "max [deg] |\n|---|---|---|---|---|---|---|---|\n";
  json jsrc = json::array();
  for (const auto& s : sources) {
    const auto m = maxima(s.ring);
    const int n_hit = hits(s.ring);
    json e = {{"label", s.label},
              {"kind", s.kind},
              {"path", s.path.string()},
              {"column", s.column},
              {"ring_samples", s.ring.size()},
              {"ring_samples_hit", n_hit}};
    for (std::size_t k = 0; k < 4; ++k)
      e[fmt::format("max_shear_deg_q{}", k + 1)] = number_or_null(m[k]);
    if (s.kind == "imported") {
      e["method"] = s.import.method;
      e["field_location"] = s.import.location;
      e["points"] = s.import.points;
      if (s.import.method == "surface") e["triangles"] = s.import.triangles;
      if (s.import.method == "points") e["tolerance_m"] = s.import.tolerance;
      e["ring_file"] = "imported_" + file_safe(s.label) + ".csv";
    } else {
      e["summary"] = s.summary_maxima;
      for (std::size_t k = 0; k < 4; ++k) {  // the run's own keys should be these maxima
        for (const auto& [key, v] : s.summary_maxima.items())
          if (key.ends_with(fmt::format("q{}", k + 1)) && v.is_number() && std::isfinite(m[k]) &&
              std::abs(v.get<double>() - m[k]) > 1e-3)
            log.warn("{}: summary.json {} = {:.4f} deg, its ring_shear.csv gives {:.4f} deg",
                     s.path.string(), key, v.get<double>(), m[k]);
      }
    }
    if (n_hit < static_cast<int>(s.ring.size()))
      log.warn("{}: {} of {} azimuths without a value", s.label,
               static_cast<int>(s.ring.size()) - n_hit, s.ring.size());
    jsrc.push_back(e);
    f.qcsv += fmt::format("{},{},{},{},{},{},{},{},{},{}\n", csv_safe(s.label), s.kind,
                          csv_safe(s.path.string()), csv_safe(s.column), s.ring.size(), n_hit,
                          cell(m[0], "{:.6g}"), cell(m[1], "{:.6g}"), cell(m[2], "{:.6g}"),
                          cell(m[3], "{:.6g}"));
    f.md += fmt::format("| {} | {} | `{}` | {} / {} | {} | {} | {} | {} |\n", md_safe(s.label),
                        s.kind, md_safe(s.path.string()), n_hit, s.ring.size(), cell(m[0]),
                        cell(m[1]), cell(m[2]), cell(m[3]));
    log.info("{} ({}, {}): max shear q1 {} q2 {} q3 {} q4 {} deg, {} of {} azimuths", s.label,
             s.kind, s.column, cell(m[0], "{:.2f}"), cell(m[1], "{:.2f}"), cell(m[2], "{:.2f}"),
             cell(m[3], "{:.2f}"), n_hit, s.ring.size());
  }
  f.js["sources"] = jsrc;
}

// Per pair: differences over the common azimuths.
void add_pair_differences(const std::vector<RingSource>& sources, spdlog::logger& log,
                          ComparisonFiles& f) {
  f.pcsv =
      "a,b,azimuths_compared,rms_difference_deg,mean_difference_deg,max_abs_difference_deg,"
      "max_difference_azimuth_deg\n";
  f.md +=
      "\n| a | b | azimuths compared | RMS (a - b) [deg] | mean (a - b) [deg] | max abs (a - b) "
      "[deg] | at azimuth [deg] |\n|---|---|---|---|---|---|---|\n";
  json jpairs = json::array();
  for (std::size_t i = 0; i < sources.size(); ++i)
    for (std::size_t j = i + 1; j < sources.size(); ++j) {
      const auto d = ring_difference(sources[i].ring, sources[j].ring);
      jpairs.push_back({{"a", sources[i].label},
                        {"b", sources[j].label},
                        {"azimuths_compared", d.azimuths},
                        {"rms_difference_deg", number_or_null(d.rms_deg)},
                        {"mean_difference_deg", number_or_null(d.mean_deg)},
                        {"max_abs_difference_deg", number_or_null(d.max_abs_deg)},
                        {"max_difference_azimuth_deg", number_or_null(d.max_at_azimuth_deg)}});
      f.pcsv += fmt::format("{},{},{},{},{},{},{}\n", csv_safe(sources[i].label),
                            csv_safe(sources[j].label), d.azimuths, cell(d.rms_deg, "{:.6g}"),
                            cell(d.mean_deg, "{:.6g}"), cell(d.max_abs_deg, "{:.6g}"),
                            cell(d.max_at_azimuth_deg, "{:.6g}"));
      f.md += fmt::format("| {} | {} | {} | {} | {} | {} | {} |\n", md_safe(sources[i].label),
                          md_safe(sources[j].label), d.azimuths, cell(d.rms_deg), cell(d.mean_deg),
                          cell(d.max_abs_deg), cell(d.max_at_azimuth_deg, "{:.0f}"));
      log.info("{} - {}: RMS {} deg, max {} deg at {} deg over {} azimuths", sources[i].label,
               sources[j].label, cell(d.rms_deg, "{:.3f}"), cell(d.max_abs_deg, "{:.3f}"),
               cell(d.max_at_azimuth_deg, "{:.0f}"), d.azimuths);
      if (d.azimuths == 0)
        log.warn("{} and {}: no azimuth that both hit (rings of another step?)", sources[i].label,
                 sources[j].label);
    }
  f.js["pairs"] = jpairs;
}

// rings.csv: every ring on the azimuths of all of them.
std::string rings_csv(const std::vector<RingSource>& sources) {
  std::map<long long, double> azimuths;
  for (const auto& s : sources)
    for (const auto& r : s.ring) azimuths.emplace(std::llround(r.azimuth_deg * 1e6), r.azimuth_deg);
  std::vector<std::map<long long, double>> value(sources.size());
  for (std::size_t i = 0; i < sources.size(); ++i)
    for (const auto& r : sources[i].ring)
      if (r.hit) value[i][std::llround(r.azimuth_deg * 1e6)] = r.shear_deg;
  std::string rcsv = "azimuth_deg";
  for (const auto& s : sources) {
    rcsv += ',';
    rcsv += csv_safe(s.label);
  }
  rcsv += "\n";
  for (const auto& [key, az] : azimuths) {
    rcsv += fmt::format("{:.6g}", az);
    for (const auto& v : value) {
      const auto it = v.find(key);
      rcsv += it == v.end() ? std::string(",nan") : fmt::format(",{:.9g}", it->second);
    }
    rcsv += "\n";
  }
  return rcsv;
}

// One plot of all rings (the workflow report's ring plot, for any sources).
void draw_ring_plot(const std::vector<RingSource>& sources, const drape::RingSpec& ring,
                    const fs::path& dir, spdlog::logger& log, ComparisonFiles& f) {
  render::CurvePlot plot;
  plot.title = fmt::format("Shear angle round the ring at {:.0f} mm", ring.height * 1e3);
  plot.x_label = "azimuth from the wale direction [deg]";
  plot.y_label = "shear angle [deg]";
  for (const auto& s : sources) {
    render::CurveSeries c;
    c.label = s.label + (s.kind == "imported" ? " (imported)" : "");
    c.dashed = s.kind == "kinematic";
    for (const auto& r : s.ring)
      if (r.hit) c.x.push_back(r.azimuth_deg), c.y.push_back(r.shear_deg);
    if (!c.x.empty()) plot.series.push_back(std::move(c));
  }
  const fs::path png = dir / "figures" / "ring_shear_compared.png";
  try {
    fs::create_directories(png.parent_path());
    render::plot_curves_png(plot, png);
    f.js["figure"] = "figures/ring_shear_compared.png";
    f.md += "\n![rings](figures/ring_shear_compared.png)\n";
  } catch (const std::exception& e) {
    f.js["figure"] = nullptr;
    f.js["figure_error"] = e.what();
    log.warn("the ring plot was not drawn: {}", e.what());
  }
}

}  // namespace

int compare_rings(const CompareOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const RingImportOptions imp = checked_import(opt);
  const drape::RingSpec& ring = imp.ring;
  std::vector<std::string> notes;
  const std::vector<RingSource> sources = read_sources(opt, imp, notes);

  const OutputFolder folder = OutputFolder::claim(opt.out_dir, opt.overwrite, {}, "comparison");
  const fs::path& dir = opt.out_dir;
  auto log = make_run_logger(dir, opt.verbosity);
  log->info("ncfsim {} | compare | {} source{} -> {}", kVersion, sources.size(),
            sources.size() == 1 ? "" : "s", dir.string());
  log->info("ring: {:.4g} m above {} along {}, azimuth 0 along {}, every {:.4g} deg", ring.height,
            v3(ring.centre), v3(ring.axis), v3(ring.zero_direction), ring.step_deg);
  for (const auto& n : notes) {
    if (n.rfind("warning: ", 0) == 0)
      log->warn("{}", n.substr(9));
    else
      log->info("{}", n);
  }

  ComparisonFiles f;
  f.js["stage"] = "compare";
  f.js["ncfsim_version"] = kVersion;
  f.js["status"] = "completed";
  f.js["ring"] = {{"height_m", ring.height},
                  {"centre_m", ring.centre.arr()},
                  {"axis", ring.axis.arr()},
                  {"zero_direction", ring.zero_direction.arr()},
                  {"step_deg", ring.step_deg}};
  add_source_maxima(sources, ring, *log, f);
  add_pair_differences(sources, *log, f);
  write_file_atomically(dir / "comparison.csv", f.qcsv);
  write_file_atomically(dir / "pairs.csv", f.pcsv);
  write_file_atomically(dir / "rings.csv", rings_csv(sources));
  for (const auto& s : sources)
    if (s.kind == "imported")
      write_file_atomically(dir / ("imported_" + file_safe(s.label) + ".csv"),
                            drape::ring_csv(s.ring, "shear_deg"));
  draw_ring_plot(sources, ring, dir, *log, f);
  write_file_atomically(dir / "comparison.md", f.md);
  f.js["wall_seconds"] =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_file_atomically(dir / "summary.json", f.js.dump(2) + "\n");
  log->info("wrote comparison.csv, pairs.csv, comparison.md, rings.csv, summary.json{}",
            f.js["figure"].is_null() ? "" : ", figures/ring_shear_compared.png");
  folder.finish();
  return kSuccess;
}

}  // namespace ncfsim::workflow
