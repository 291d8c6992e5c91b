#include "workflow/calibrate/calibration_stage.hpp"

#include <fmt/format.h>
#include <spdlog/logger.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <sstream>

#include "fem/case/fem_case.hpp"
#include "fem/case/stage_kinds.hpp"
#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"
#include "fem/petsc_vector.hpp"
#include "workflow/output/output_files.hpp"
#include "workflow/run/engine_run.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace fs = std::filesystem;
using json = nlohmann::json;
using fem::TableReader;

namespace {

fs::path relative_to(const TableReader& t, const std::string& value) {
  const fs::path p = value;
  return p.is_relative() ? t.file().parent_path() / p : p;
}

// A virtual test's run folder: the folder, or a file in it (a workflow's input hands over the
// stage's results.h5). It must exist when the stage runs; `ncfsim check` only reads the key.
fs::path run_folder(const TableReader& t, std::string_view key, bool must_exist) {
  fs::path p = relative_to(t, t.string(key));
  std::error_code ec;
  if (fs::is_regular_file(p, ec) || p.filename() == "results.h5") p = p.parent_path();
  if (must_exist && (!fs::is_directory(p, ec) || !fs::is_regular_file(p / "summary.json", ec)))
    t.fail(key, "no run of a virtual test in " + p.string() +
                    " (no summary.json there): run the test first, or name its output folder");
  return p;
}

// The sections a calibration case may include for their data (a fabric file: [fabric.NAME],
// its [[material]] and [[bar_law]] tables, read by reference as "&fabric.NAME.key"): the stage
// reads none of them itself, so they are not unknown keys here; the cases that use them check
// them.
void mark_included_sections(const TableReader& root) {
  const auto mark_all = [](const TableReader& t) {
    for (const auto& k : t.keys()) t.mark(k);
  };
  if (const auto fabric = root.table("fabric"))
    for (const auto& name : fabric->keys())
      if (const auto one = fabric->table(name)) mark_all(*one);
  for (const char* a : {"material", "bar_law", "membrane_law"})
    for (const auto& t : root.tables(a)) mark_all(t);
}

void read_macro(const TableReader& t, CalibrationCase& cc, bool runs) {
  MacroCalibrationOptions& m = cc.macro;
  m.positive = run_folder(t, "positive", runs);
  m.negative = run_folder(t, "negative", runs);
  cc.sources = {{"positive shear curve", m.positive}, {"negative shear curve", m.negative}};
  if (t.has("unstitched")) {
    m.unstitched = run_folder(t, "unstitched", runs);
    cc.sources.emplace_back("unstitched curve", m.unstitched);
  }
  if (t.has("bias_positive")) {
    m.bias_positive = run_folder(t, "bias_positive", runs);
    cc.sources.emplace_back("positive bias-extension check", m.bias_positive);
  }
  if (t.has("bias_negative")) {
    m.bias_negative = run_folder(t, "bias_negative", runs);
    cc.sources.emplace_back("negative bias-extension check", m.bias_negative);
  }
  m.frame = t.string("frame", m.frame);
  m.name = t.string("law_name", m.name);
  m.symmetric = t.boolean("symmetric", false);
  m.stitch_bars = t.boolean("stitch_bars", false);
  m.step_deg = t.number("step_deg", m.step_deg, Range::open_closed(0, 45));
  m.max_angle_deg = t.number("max_angle_deg", 0.0, Range::closed(0, 90));
  m.areal_density = t.number("areal_density", m.areal_density, Range::positive());
  if (t.has("fibre_angles_deg")) {
    const auto a = t.numbers("fibre_angles_deg", Range::closed(-180, 180), 2);
    if (a.size() != 2) t.fail("fibre_angles_deg", "must hold 2 angles (deg from the wale)");
    m.fibre_angles_deg = {a[0], a[1]};
  }
  m.fibre_tension_stiffness =
      t.number("fibre_tension_stiffness", m.fibre_tension_stiffness, Range::positive());
  m.fibre_compression_ratio =
      t.number("fibre_compression_ratio", m.fibre_compression_ratio, Range::closed(0, 1));
  m.bending_stiffness = t.number("bending_stiffness", m.bending_stiffness, Range::non_negative());
  m.coupon_length = t.number("coupon_length", m.coupon_length, Range::positive());
  m.coupon_width = t.number("coupon_width", m.coupon_width, Range::positive());
}

void read_tow_bending(const TableReader& t, CalibrationCase& cc) {
  TowBendingCalibration& b = cc.bending;
  b.case_file = relative_to(t, t.string("case"));
  if (!fs::is_regular_file(b.case_file))
    t.fail("case", "no such case file: " + b.case_file.string());
  if (t.has("set")) b.overrides = t.strings("set");
  b.target_bending_length = t.number("target_bending_length", Range::positive());
  b.tolerance = t.number("tolerance", b.tolerance, Range::closed(1e-4, 0.2));
  b.max_runs = static_cast<int>(t.integer("max_runs", b.max_runs, 1, 50));
  cc.sources = {{"cantilever bending (ASTM D1388)", b.case_file}};
}

void read_stitch(const TableReader& t, CalibrationCase& cc) {
  StitchCalibrationOptions& s = cc.stitch;
  s.data = relative_to(t, t.string("data"));
  if (!fs::is_regular_file(s.data)) t.fail("data", "no such file: " + s.data.string());
  s.extension_column = t.string("extension_column", s.extension_column);
  s.force_column = t.string("force_column", s.force_column);
  s.extension_scale = t.number("extension_scale", 1.0, Range::positive());
  s.force_scale = t.number("force_scale", 1.0, Range::positive());
  s.sign = t.choice("shear", {"positive", "negative"}, "positive") == "negative"
               ? drape::ShearSign::Negative
               : drape::ShearSign::Positive;
  s.coupon.length = t.number("coupon_length", s.coupon.length, Range::positive());
  s.coupon.width = t.number("coupon_width", s.coupon.width, Range::positive());
  if (!(s.coupon.length > s.coupon.width))
    t.fail("coupon_length", "must be longer than coupon_width (the free length H - W is Eq. 2's)");
  s.coupon.stitch_length = t.number("stitch_length", s.coupon.stitch_length, Range::positive());
  s.coupon.gauge = t.number("gauge", s.coupon.gauge, Range::positive());
  s.max_shear_deg = t.number("max_shear_deg", s.max_shear_deg, Range::closed(1, 60));
  s.points = static_cast<int>(t.integer("points", s.points, 2, 200));
  s.law_name = t.string("law_name", s.law_name);
  cc.sources = {{"bias-extension force data", s.data}};
}

// laws.toml of a tow-bending calibration: the bent part's whole [[material]] table with the
// calibrated E11f, so that a case taking it in case.laws gets that material and nothing else.
std::string bending_laws(const CalibrationCase& cc, const TowBendingResult& r) {
  const fem::CaseDocument doc = fem::CaseDocument::load(cc.bending.case_file, cc.bending.overrides);
  const toml::array* mats = doc.root()["material"].as_array();
  if (!mats || r.material_index >= mats->size() || !mats->get(r.material_index)->as_table())
    throw InputError(cc.bending.case_file.string(), "material",
                     "the bent part's [[material]] table was not found");
  toml::table m = *mats->get(r.material_index)->as_table();
  m.insert_or_assign("E11f", r.E11f);
  toml::array out;
  out.push_back(m);
  toml::table root;
  root.insert("material", out);
  std::ostringstream os;
  os << fmt::format(
            "# Tow law calibrated by the stage '{}' (ncfsim {}, method tow_bending): E11f gives a\n"
            "# bending length of {:.5g} m in the virtual cantilever test {} (target {:.5g} m,\n"
            "# tolerance {:.3g}, {} runs). A case takes it in case.laws.\n",
            cc.name, kVersion, r.bending_length, cc.bending.case_file.string(),
            cc.bending.target_bending_length, cc.bending.tolerance, r.runs)
     << toml::toml_formatter(root) << "\n";
  return os.str();
}

}  // namespace

CalibrationCase load_calibration_case(const fs::path& file,
                                      const std::vector<std::string>& overrides,
                                      bool runs_must_exist) {
  fem::CaseDocument doc = fem::CaseDocument::load(file, overrides);
  const TableReader root(doc, doc.root(), "");
  CalibrationCase cc;
  cc.file = file;
  const auto header = fem::read_stage_case_header(root, fem::stage_kind::kCalibration);
  cc.name = header.name;
  cc.description = header.description;
  mark_included_sections(root);
  const TableReader t =
      root.required_table("calibration");  // the [calibration] table: not a stage kind
  if (!t.has("method")) t.fail("method", "missing (required): macro, tow_bending or stitch");
  cc.method = t.choice("method", {"macro", "tow_bending", "stitch"}, "macro");
  if (cc.method == "macro") read_macro(t, cc, runs_must_exist);
  if (cc.method == "tow_bending") read_tow_bending(t, cc);
  if (cc.method == "stitch") read_stitch(t, cc);
  doc.check_unknown_keys();
  return cc;
}

int check_calibration_stage(const StageCall& call) {
  const CalibrationCase cc = load_calibration_case(call.case_file, call.overrides);
  std::string from;
  for (const auto& [what, p] : cc.sources) from += (from.empty() ? "" : ", ") + p.string();
  std::printf("%s: OK (case '%s', calibration by %s from %s)\n", call.case_file.c_str(),
              cc.name.c_str(), cc.method.c_str(), from.c_str());
  return kSuccess;
}

int run_calibration_stage(const StageCall& call) {
  const auto t0 = std::chrono::steady_clock::now();
  CalibrationCase cc = load_calibration_case(call.case_file, call.overrides, true);
  fem::PetscSession petsc;  // the tow-bending runs are engine runs
  if (const int rc = refuse_many_ranks()) return rc;
  const fs::path dir = output_folder(cc.name, call.options);
  const OutputFolder folder =
      OutputFolder::claim(dir, call.options.overwrite, {}, fem::stage_kind::kCalibration);
  auto log = make_run_logger(dir, call.options.verbosity);
  log->info("ncfsim {} | case '{}' ({}) | calibration by {}", kVersion, cc.name,
            call.case_file.string(), cc.method);
  if (!cc.description.empty()) log->info("  {}", cc.description);
  for (const auto& o : call.overrides) log->info("  --set {}", o);
  for (const auto& [what, p] : cc.sources) log->info("  {}: {}", what, p.string());

  json s = stage_summary_header(cc.name, call, fem::stage_kind::kCalibration);
  s["method"] = cc.method;
  json from = json::object();
  for (const auto& [what, p] : cc.sources) from[what] = p.string();
  s["calibrated_from"] = from;
  json targets = json::array();
  int code = kSuccess;
  const fs::path laws = dir / kLawsFile;
  try {
    if (cc.method == "macro") {
      MacroCalibrationOptions o = cc.macro;
      o.output = laws;
      o.curves_csv = dir / "frame_curves.csv";
      const MacroCalibration r = calibrate_macro(o);
      for (const auto& n : r.notes) log->info("{}", n);
      s["membrane_law"] = o.name;
      s["curve_points_positive"] = r.positive.curve.angle_deg.size();
      s["curve_points_negative"] = o.symmetric ? 0 : r.negative.curve.angle_deg.size();
      s["symmetric"] = o.symmetric;
      s["stitch_bars"] = o.stitch_bars;
      // The bias coupons against the force the law gives an ideal trellis: shown, not a target
      // (the meso coupon slips between its tows, the trellis does not).
      for (const auto& [sign, rows] :
           {std::pair{"positive", &r.bias_positive}, std::pair{"negative", &r.bias_negative}}) {
        json a = json::array();
        for (const auto& b : *rows)
          a.push_back({{"extension_mm", b.extension_mm},
                       {"meso_force_N", b.meso_force_N},
                       {"law_trellis_force_N", b.curve_force_N},
                       {"eq2_shear_deg", b.eq2_shear_deg}});
        if (!a.empty()) s[std::string("bias_check_") + sign] = a;
      }
      log->info("wrote {} ([[membrane_law]] '{}', {} + {} curve points)", laws.string(), o.name,
                r.positive.curve.angle_deg.size(),
                o.symmetric ? std::size_t{0} : r.negative.curve.angle_deg.size());
    } else if (cc.method == "tow_bending") {
      TowBendingCalibration b = cc.bending;
      b.out_dir = dir / "runs";
      const TowBendingResult r = calibrate_tow_bending(b);
      s["E11f_Pa"] = r.E11f;
      s["bending_length_m"] = r.bending_length;
      s["target_bending_length_m"] = b.target_bending_length;
      s["runs"] = r.runs;
      s["converged"] = r.converged;
      targets.push_back({{"quantity", "bending_length_m"},
                         {"value", r.bending_length},
                         {"target", b.target_bending_length},
                         {"relative_tolerance", b.tolerance},
                         {"source", "the tow's bending length (ASTM D1388), calibrated E11f"},
                         {"met", r.converged}});
      log->info(
          "E11f = {:.6g} Pa gives a bending length of {:.6g} m (target {:.6g} m) after {} runs",
          r.E11f, r.bending_length, b.target_bending_length, r.runs);
      if (r.converged) {
        write_file_atomically(laws, bending_laws(cc, r));
      } else {
        s["status"] = "numerical_failure";
        s["error"] =
            fmt::format("not converged in {} runs (calibration.max_runs): no laws written", r.runs);
        log->error("{}", s["error"].get<std::string>());
        code = kNumericalFailure;
      }
    } else {
      StitchCalibrationOptions o = cc.stitch;
      o.out_dir = dir;
      calibrate_stitch(o);
      write_file_atomically(laws, read_file(dir / "stitch_law.toml"));
      s["bar_law"] = o.law_name;
      log->info("wrote {} ([[bar_law]] '{}')", laws.string(), o.law_name);
    }
  } catch (const std::exception& e) {
    // The folder says what stopped it (a frame run not completed, a law that cannot be fitted),
    // as an engine run's does; the caller reports the error and its exit code.
    s["status"] = dynamic_cast<const InputError*>(&e)       ? "bad_input"
                  : dynamic_cast<const NumericalError*>(&e) ? "numerical_failure"
                                                            : "failed";
    s["error"] = e.what();
    write_file_atomically(dir / "summary.json", s.dump(2) + "\n");
    log->error("{}", e.what());
    throw;
  }
  if (code == kSuccess) s["laws_file"] = kLawsFile;
  if (!targets.empty()) {
    bool met = true;
    for (const auto& t : targets) met = met && t["met"].get<bool>();
    s["targets"] = targets;
    s["targets_met"] = met;
  }
  s["wall_seconds"] = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  write_file_atomically(dir / "summary.json", s.dump(2) + "\n");
  log->info("results in {}", dir.string());
  folder.finish();
  return code;
}

}  // namespace ncfsim::workflow
