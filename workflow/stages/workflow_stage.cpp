#include "workflow/stages/workflow_stage.hpp"

#include <fmt/format.h>
#include <spdlog/logger.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstring>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "fem/case/stage_kinds.hpp"
#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"
#include "fem/io/hdf5_checkpoint.hpp"
#include "fem/petsc_vector.hpp"
#include "workflow/case/case_hash.hpp"
#include "workflow/output/output_files.hpp"
#include "workflow/output/run_status.hpp"
#include "workflow/render/render.hpp"
#include "workflow/report/report.hpp"
#include "workflow/run/mpi_launch.hpp"
#include "workflow/run/run_checkpoint.hpp"
#include "workflow/run/run_output.hpp"
#include "workflow/stages/workflow_case.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace fs = std::filesystem;
using json = nlohmann::json;

namespace {

constexpr const char* kInputsFile = "stage_inputs.json";

struct StagePlan {
  WorkflowStageSpec spec;
  fs::path folder;
  std::vector<std::string> overrides;  // routed + inputs
  std::string kind;
  std::string hash;
  json inputs;    // what the hash covers (stage_inputs.json)
  int ranks = 1;  // MPI ranks it runs on (several: a launcher of its own, run_on_ranks)
};

// The stage's inputs and their hash; the upstream hashes are those of plans already made.
// An input key is hashed as the name of its upstream stage, whose own hash stands for its
// results: the results' path (in the workflow's folder) is not an input, so a workflow folder
// moved or copied elsewhere reruns nothing.
void hash_stage(StagePlan& p, const std::map<std::string, std::string>& upstream_hash) {
  std::vector<std::string> hashed = p.spec.overrides;
  for (const auto& [key, up] : p.spec.inputs)
    hashed.push_back(key + "=" + json("results of stage " + up).dump());
  const fem::CaseDocument doc = fem::CaseDocument::load(p.spec.case_file, hashed);
  Md5 md5;
  md5.add(kVersion);
  md5.add(hashed_case_text(doc.root()));
  std::set<std::string> input_keys;
  for (const auto& [key, up] : p.spec.inputs) input_keys.insert(key);
  std::vector<std::pair<std::string, std::string>> strings;
  string_values(doc.root(), "", strings);
  json files = json::array();
  const fs::path dir = p.spec.case_file.parent_path();
  for (const auto& [key, value] : strings) {
    if (input_keys.count(key) || value.empty() || value.size() > 4096) continue;
    std::error_code ec;
    const fs::path f = fs::path(value).is_absolute() ? fs::path(value) : dir / value;
    if (!fs::is_regular_file(f, ec)) continue;
    md5.add(key);
    if (!md5.add_file(f)) md5.add("");  // the bytes, read in pieces
    files.push_back(f.lexically_normal().string());
  }
  json up = json::object();
  for (const auto& u : p.spec.after) {
    md5.add(u);
    md5.add(upstream_hash.at(u));
    up[u] = upstream_hash.at(u);
  }
  p.hash = md5.hex();
  p.inputs = {{"hash", p.hash},
              {"ncfsim_version", kVersion},
              {"case_file", p.spec.case_file.lexically_normal().string()},
              {"overrides", hashed},
              {"files", files},
              {"upstream", up}};
}

bool unchanged(const StagePlan& p) {
  const json old = read_json_file(p.folder / kInputsFile);
  const json sum = read_json_file(p.folder / "summary.json");
  return old.is_object() && old.value("hash", "") == p.hash && sum.is_object() &&
         sum.value("status", "") == "completed";
}

std::vector<StagePlan> plan(const WorkflowCase& wc, const fs::path& out, int ranks) {
  std::vector<StagePlan> plans;
  std::map<std::string, std::string> hashes, handoff;  // per stage name
  for (const auto& s : wc.stages) {
    StagePlan p;
    p.spec = s;
    p.folder = out / s.name;
    p.overrides = s.overrides;
    for (const auto& [key, up] : s.inputs)
      p.overrides.push_back(key + "=" +
                            json(fs::absolute(out / up / handoff.at(up)).string()).dump());
    p.kind = case_kind(s.case_file, p.overrides);
    // A known kind, or bad input naming the stage's file.
    const Stage& stage = find_stage(p.kind, s.case_file);
    if (stage.holds_stages)
      throw InputError(
          wc.file.string(), "stage",
          "stage '" + s.name + "' is itself a " + p.kind + " (" + s.case_file.string() + ")");
    if (s.ranks > 1 && !stage.time_loop)
      throw InputError(wc.file.string(), "stage.ranks",
                       "stage '" + s.name + "' is a '" + p.kind +
                           "' stage: it runs on one MPI rank (only time-loop stages are split "
                           "over ranks): ranks = 1 or leave it out");
    p.ranks = s.ranks > 0 ? s.ranks : stage.time_loop ? ranks : 1;
    hash_stage(p, hashes);
    hashes[s.name] = p.hash;
    handoff[s.name] = stage.handoff;
    plans.push_back(std::move(p));
  }
  return plans;
}

struct StageOutcome {
  int rc = kOtherError;
  std::string status;  // the stage's summary status, or bad_input / numerical_failure / failed
  std::string error;   // the message of bad input or a numerical failure thrown by the stage
};

// An engine or crush stage on several ranks: `launcher -n N ncfsim run CASE -o FOLDER --set ...`
// as a child process in a process group of its own (so that the terminal's Ctrl-C reaches the
// workflow only, which passes one SIGINT on to the stage's ranks: they checkpoint at one cycle).
// The child gets SIGTERM if the workflow dies. A rank lost ends the stage failed, the rank named
// in its summary. Returns the child's exit code.
int run_on_ranks(const StagePlan& p, const StageCall& sc, spdlog::logger& log,
                 const std::string& tag) {
  if (std::string(mpi_launcher()).empty())
    throw InputError(p.spec.case_file.string(), "--np",
                     "no MPI launcher was found when ncfsim was built: run the stage on one rank "
                     "(ranks = 1 in the workflow's [[stage]], or no --np)");
  std::vector<std::string> args = mpi_launch_command(p.ranks);
  if (sc.options.verbosity == Verbosity::Quiet) args.push_back("-q");
  if (sc.options.verbosity == Verbosity::Verbose) args.push_back("-v");
  for (const char* a : {"run", sc.case_file.c_str(), "-o", sc.options.out_dir.c_str()})
    args.emplace_back(a);
  for (const auto& ov : sc.overrides) {
    args.emplace_back("--set");
    args.push_back(ov);
  }
  args.emplace_back("--progress-interval");
  args.push_back(fmt::format("{}", sc.options.progress_interval_s));
  args.emplace_back("--inputs-hash");
  args.push_back(sc.options.inputs_hash);
  if (sc.options.resume) args.emplace_back("--resume");
  std::string shown;
  for (std::size_t k = 0; k < args.size(); ++k)
    if (!(k > 0 && args[k - 1] == "--inputs-hash")) shown += (shown.empty() ? "" : " ") + args[k];
  log.info("{} on {} MPI ranks: {}", tag, p.ranks, shown);
  log.flush();
  // run_launcher asks until the answer is yes, once.
  const LauncherExit ex = run_launcher(args, launcher_environment(), SIGTERM, [&] {
    if (!StopRequest::requested()) return false;
    log.info("{} interrupt passed on to the stage's ranks", tag);
    return true;
  });
  if (ex.exit_code != 0) {
    if (!ex.lost_rank.empty())
      log.error("{} MPI {} was lost; the launcher ended the other ranks", tag, ex.lost_rank);
    if (record_lost_rank(sc.options.out_dir, ex.lost_rank, ex.exit_code, p.ranks))
      log.error("{} its summary.json said running: now failed", tag);
  }
  return ex.exit_code;
}

// Runs one stage into its folder; its stage_inputs.json is removed first, so a stage stopped
// half-way is never taken as done.
StageOutcome run_planned_stage(const StagePlan& p, const RunOptions& options, spdlog::logger& log,
                               const std::string& tag) {
  fs::create_directories(p.folder);
  fs::remove(p.folder / kInputsFile);
  StageCall sc;
  sc.case_file = p.spec.case_file;
  sc.overrides = p.overrides;
  sc.options = options;
  sc.options.out_dir = p.folder;
  sc.options.overrides = p.overrides;
  sc.options.force_stages.clear();
  // --resume reaches the stage that stopped with a checkpoint of these very inputs.
  sc.options.inputs_hash = p.hash;
  sc.options.resume = false;
  if (options.resume && fs::exists(p.folder / kCheckpointFile)) {
    std::string hash;
    try {
      fem::CheckpointTree t = fem::io::read_checkpoint_file(p.folder / kCheckpointFile);
      t.set_reading(true);
      hash = t.read_string("inputs_hash");
    } catch (const std::exception&) {
    }
    if (hash == p.hash) {
      sc.options.resume = true;
      log.info("{} resuming from its checkpoint", tag);
    } else {
      log.warn("{} checkpoint of other inputs discarded: the stage runs from the start", tag);
    }
  }
  StageOutcome o;
  try {
    o.rc =
        p.ranks > 1 ? run_on_ranks(p, sc, log, tag) : find_stage(p.kind, p.spec.case_file).run(sc);
  } catch (const InputError& e) {
    o.rc = kBadInput;
    o.error = e.what();
    log.error("{} bad input: {}", tag, e.what());
  } catch (const NumericalError& e) {
    o.rc = kNumericalFailure;
    o.error = e.what();
    log.error("{} numerical failure: {}", tag, e.what());
  }
  if (p.ranks > 1 && o.rc != kSuccess && o.error.empty())
    o.error = fmt::format("exit {} on {} MPI ranks (its message is above and in {})", o.rc, p.ranks,
                          (p.folder / "log.txt").string());
  const json ss = read_json_file(p.folder / "summary.json");
  o.status = ss.is_object() ? ss.value("status", "failed") : "failed";
  if (o.rc == kBadInput)
    o.status = "bad_input";  // found before the stage wrote its summary
  else if (o.rc == kNumericalFailure && o.status == "completed")
    o.status = "numerical_failure";
  else if (o.rc != kSuccess && o.status == "completed")
    o.status = "failed";
  return o;
}

}  // namespace

int run_workflow_stage(const StageCall& call) {
  const WorkflowCase wc = load_workflow_case(call.case_file, call.overrides);
  const fs::path out = output_folder(wc.name, call.options);
  for (const auto& f : call.options.force_stages)
    if (std::none_of(wc.stages.begin(), wc.stages.end(),
                     [&](const auto& s) { return s.name == f; }))
      throw InputError(call.case_file.string(), "--force",
                       "'" + f + "' is not a stage of this workflow");
  const std::vector<StagePlan> plans = plan(wc, out, call.options.ranks);
  // One PETSc/MPI session over every stage: MPI cannot start again once a stage's own session
  // has finalised it (the stages' sessions nest in this one).
  fem::PetscSession petsc;
  if (const int rc = refuse_many_ranks()) return rc;
  std::vector<std::string> stage_dirs;
  for (const auto& p : plans) stage_dirs.push_back(p.spec.name);
  const OutputFolder folder =
      OutputFolder::claim(out, call.options.overwrite, stage_dirs, fem::stage_kind::kWorkflow);
  auto log = make_run_logger(out, call.options.verbosity);
  if (!folder.note().empty()) log->warn("{}", folder.note());
  const auto t0 = std::chrono::steady_clock::now();
  const auto wall = [&] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  log->info("workflow '{}' ({}): {} stages into {}", wc.name, call.case_file.string(), plans.size(),
            out.string());

  json summary = stage_summary_header(wc.name, call, fem::stage_kind::kWorkflow);
  summary["status"] = "running";
  summary["stages"] = json::array();
  const std::size_t n = plans.size();
  // Stage estimates for the ETA: the wall time of its last completed run, where there is one.
  std::vector<double> estimate(n, -1);
  for (std::size_t k = 0; k < n; ++k) {
    const json old = read_json_file(plans[k].folder / "summary.json");
    if (old.is_object() && old.contains("wall_seconds") && old["wall_seconds"].is_number())
      estimate[k] = old["wall_seconds"].get<double>();
  }
  int code = kSuccess;
  std::string stop_reason;
  const StagePlan* resumable = nullptr;  // the stage that stopped with a checkpoint
  for (std::size_t k = 0; k < n; ++k) {
    const StagePlan& p = plans[k];
    const std::string tag = fmt::format("[{}/{} {}]", k + 1, n, p.spec.name);
    json entry = {
        {"name", p.spec.name},   {"kind", p.kind},        {"case_file", p.spec.case_file.string()},
        {"folder", p.spec.name}, {"inputs_hash", p.hash}, {"mpi_ranks", p.ranks}};
    if (!stop_reason.empty()) {
      entry["status"] = "not_run";
      summary["stages"].push_back(entry);
      continue;
    }
    const bool forced =
        std::find(call.options.force_stages.begin(), call.options.force_stages.end(),
                  p.spec.name) != call.options.force_stages.end();
    if (!forced && unchanged(p)) {
      log->info("{} unchanged since its last run (inputs {}): skipped, results in {}", tag,
                p.hash.substr(0, 12), p.folder.string());
      entry["status"] = "skipped";
      entry["wall_seconds"] = 0.0;
      summary["stages"].push_back(entry);
      estimate[k] = 0;
      continue;
    }
    double left = 0;
    bool known = true;
    for (std::size_t j = k; j < n; ++j) {
      known = known && estimate[j] >= 0;
      left += std::max(0.0, estimate[j]);
    }
    log->info("{} {} {} -> {}{} | workflow wall {} | ETA {}", tag, forced ? "forced:" : "running",
              p.spec.case_file.string(), p.folder.string(),
              p.overrides.empty() ? "" : " (with --set)", hms(wall()),
              known ? hms(left) + " (from the last run's stage times)" : "unknown (first run)");
    for (const auto& o : p.overrides) log->debug("{}   --set {}", tag, o);
    const double ts = wall();
    const StageOutcome o = run_planned_stage(p, call.options, *log, tag);
    const int rc = o.rc;
    const std::string& status = o.status;
    if (!o.error.empty()) entry["error"] = o.error;
    entry["wall_seconds"] = wall() - ts;
    entry["status"] = status;
    summary["stages"].push_back(entry);
    if (rc == kSuccess && status == "completed") {
      write_file_atomically(p.folder / kInputsFile, p.inputs.dump(2) + "\n");
      log->info("{} completed in {}", tag, hms(wall() - ts));
    } else {
      code = rc == kSuccess ? kOtherError : rc;
      stop_reason = fmt::format("stage '{}' ended {} (exit {})", p.spec.name, status, rc);
    }
    if (StopRequest::requested() && stop_reason.empty() && k + 1 < n)
      stop_reason = "interrupted (SIGINT/SIGTERM)";
    if (!stop_reason.empty() && StopRequest::requested()) code = kOtherError;
    if (!stop_reason.empty() && fs::exists(p.folder / kCheckpointFile)) resumable = &p;
  }
  summary["wall_seconds"] = wall();
  summary["status"] = stop_reason.empty()        ? "completed"
                      : StopRequest::requested() ? "interrupted"
                                                 : "failed";
  if (!stop_reason.empty()) summary["error"] = stop_reason;
  write_file_atomically(out / "summary.json", summary.dump(2) + "\n");
  try {
    write_workflow_report(out);
    log->info("report: {}", (out / "report.html").string());
  } catch (const std::exception& e) {
    log->warn("report not written: {}", e.what());
  }
  if (!stop_reason.empty()) {
    std::string kept;
    for (const auto& e : summary["stages"])
      if (e["status"] == "completed" || e["status"] == "skipped")
        kept += (kept.empty() ? "" : ", ") + e["name"].get<std::string>();
    if (resumable) {
      std::string command = "ncfsim run " + call.case_file.string() + " -o " + out.string();
      if (call.options.ranks > 1) command += " --np " + std::to_string(call.options.ranks);
      for (const auto& ov : call.overrides)  // a cycle limit would stop it again
        if (ov.find("time.max_cycles=") == std::string::npos) command += " --set " + ov;
      log->warn(
          "workflow stopped: {}; kept: {} (their results stand); stage '{}' kept its checkpoint "
          "({}): {} --resume continues it (the kept stages are skipped)",
          stop_reason, kept.empty() ? "none" : kept, resumable->spec.name,
          (resumable->folder / kCheckpointFile).string(), command);
    } else {
      log->warn(
          "workflow stopped: {}; kept: {} (their results stand); {} the same command to go "
          "on: the kept stages are skipped",
          stop_reason, kept.empty() ? "none" : kept,
          code == kBadInput ? "correct the input and rerun" : "rerun");
    }
  } else {
    log->info("workflow '{}' completed in {}: {}", wc.name, hms(wall()), out.string());
  }
  folder.finish();
  return code;
}

int check_workflow_stage(const StageCall& call) {
  const WorkflowCase wc = load_workflow_case(call.case_file, call.overrides);
  fem::PetscSession petsc;  // see run_workflow_stage
  if (const int rc = refuse_many_ranks()) return rc;
  std::string list;
  for (const auto& s : wc.stages) {
    StageCall sc;
    sc.case_file = s.case_file;
    sc.overrides = s.overrides;
    const std::string kind = case_kind(s.case_file, s.overrides);
    const Stage& st = find_stage(kind, s.case_file);
    if (st.holds_stages)
      throw InputError(call.case_file.string(), "stage",
                       "stage '" + s.name + "' is itself a " + kind);
    if (s.inputs.empty()) {
      if (const int rc = st.check(sc)) return rc;
    } else {  // its inputs do not exist before the upstream stages ran: the case must parse
      fem::CaseDocument::load(s.case_file, s.overrides);
      std::printf("%s: parsed (stage '%s' reads the results of %s when it runs)\n",
                  s.case_file.c_str(), s.name.c_str(), s.inputs.front().second.c_str());
    }
    list += (list.empty() ? "" : " -> ") + s.name;
  }
  std::printf("%s: OK (workflow '%s': %s)\n", call.case_file.c_str(), wc.name.c_str(),
              list.c_str());
  return kSuccess;
}

// ---------------------------------------------------------------------------------------------
// report.html of a workflow

namespace {

std::string escape(const std::string& s) { return html_escape(s); }

std::string number(const json& s, const std::string& key, const char* fmt_spec = "{:.4g}") {
  if (!s.is_object() || !s.contains(key) || !s[key].is_number()) return "-";
  return fmt::format(fmt::runtime(fmt_spec), s[key].get<double>());
}

// The shear rings of every stage that measured one, on one plot (the meso drape's own column
// shear_deg, a macro drape's macro_shear_deg, a kinematic drape's kinematic_shear_deg).
bool ring_plot(const fs::path& dir, const json& stages, std::string& why) {
  render::CurvePlot plot;
  plot.title = "Shear angle round the ring";
  plot.x_label = "azimuth [deg]";
  plot.y_label = "shear angle [deg]";
  for (const auto& e : stages) {
    const fs::path csv = dir / e["folder"].get<std::string>() / "ring_shear.csv";
    if (!fs::exists(csv)) continue;
    try {
      const CsvTable t = read_csv(csv);
      const auto az = t.column("azimuth_deg");
      const Stage* stage = stage_of_kind(e.value("kind", ""));
      const bool own_column = stage && !stage->ring_column.empty();
      const bool macro =
          std::find(t.columns.begin(), t.columns.end(), "macro_shear_deg") != t.columns.end();
      const auto y = t.column(own_column ? stage->ring_column
                              : macro    ? "macro_shear_deg"
                                         : "shear_deg");
      render::CurveSeries s;
      s.label = e["name"].get<std::string>() + (own_column ? stage->ring_label
                                                : macro    ? " (macro shells)"
                                                           : "");
      s.dashed = own_column;  // a reference drape beside the meso ones
      for (std::size_t i = 0; i < az.size(); ++i)
        if (std::isfinite(y[i])) s.x.push_back(az[i]), s.y.push_back(y[i]);
      plot.series.push_back(std::move(s));
    } catch (const std::exception& ex) {
      why = csv.string() + ": " + ex.what();
    }
  }
  if (plot.series.empty()) return false;
  fs::create_directories(dir / "figures");
  render::plot_curves_png(plot, dir / "figures" / "ring_shear_compared.png");
  return true;
}

}  // namespace

namespace {

// Stages, their status, wall times, energy balance, reports.
void process_section(std::ostream& h, const fs::path& dir, const json& stages,
                     const std::map<std::string, json>& sums) {
  h << "<h2>Process</h2>\n<table><tr><th>stage</th><th>kind</th><th>case</th><th>this run</th>"
       "<th>wall (this run)</th><th>wall (stage)</th><th>energy balance "
       "error</th><th>report</th></tr>\n";
  for (const auto& e : stages) {
    const std::string st = e.value("status", "?"), nm = e["name"].get<std::string>();
    const json& ss = sums.at(nm);
    std::string balance = "-";
    if (ss.is_object() && ss.contains("energy_balance_error") &&
        ss["energy_balance_error"].is_number()) {
      const double err = ss["energy_balance_error"].get<double>();
      const double lim = ss.value("energy_balance_limit", 0.05);
      balance = fmt::format("<span class=\"{}\">{:.3g} %</span> (limit {:.3g} %)",
                            err <= lim ? "ok" : "bad", 100 * err, 100 * lim);
    }
    h << "<tr><td>" << escape(nm) << "</td><td>" << escape(e.value("kind", "")) << "</td><td>"
      << escape(e.value("case_file", "")) << "</td><td class=\""
      << (st == "completed" || st == "skipped" ? "ok" : "bad") << "\">" << escape(st) << "</td><td>"
      << hms(e.value("wall_seconds", 0.0)) << "</td><td>"
      << (ss.is_object() ? hms(ss.value("wall_seconds", 0.0)) : "-") << "</td><td>" << balance
      << "</td><td>"
      << (fs::exists(dir / nm / "report.html")
              ? "<a href=\"" + escape(nm) + "/report.html\">report</a>"
              : "-")
      << "</td></tr>\n";
  }
  h << "</table>\n";
}

// The drapes compared: the rings of every drape stage on one plot and the quadrant maxima.
void drapes_section(std::ostream& h, const fs::path& dir, const json& stages,
                    const std::map<std::string, json>& sums) {
  std::string why;
  bool any_ring = false;
  try {
    any_ring = ring_plot(dir, stages, why);
  } catch (const std::exception& ex) {
    why = ex.what();
  }
  std::ostringstream q;
  for (const auto& e : stages) {
    const std::string nm = e["name"].get<std::string>();
    const json& ss = sums.at(nm);
    for (const char* prefix : {"", "macro_", "kinematic_"}) {
      if (!ss.is_object() || !ss.contains(std::string(prefix) + "max_shear_deg_q1")) continue;
      const std::string pre = prefix;
      q << "<tr><td>" << escape(nm)
        << (pre == "kinematic_" ? " (pin-jointed net)"
            : pre == "macro_"   ? " (macro shells)"
                                : "")
        << "</td>";
      for (int k = 1; k <= 4; ++k)
        q << "<td>" << number(ss, fmt::format("{}max_shear_deg_q{}", prefix, k), "{:.1f}")
          << "</td>";
      q << "</tr>\n";
    }
  }
  if (any_ring || !q.str().empty()) {
    h << "<h2>Drapes compared: shear angle on the ring</h2>\n";
    if (any_ring)
      h << "<figure><img src=\"figures/ring_shear_compared.png\" alt=\"ring "
           "shear\"><figcaption>shear "
           "angle round the ring, every drape of the workflow</figcaption></figure>\n";
    else if (!why.empty())
      h << "<p class=\"bad\">ring plot: " << escape(why) << "</p>\n";
    if (!q.str().empty())
      h << "<table><tr><th>drape</th><th>max q1 [deg]</th><th>max q2 [deg]</th><th>max q3 "
           "[deg]</th><th>max q4 [deg]</th></tr>\n"
        << q.str() << "</table>\n";
  }
}

// Key results of every stage that has them.
void key_results_section(std::ostream& h, const json& stages,
                         const std::map<std::string, json>& sums) {
  static const std::vector<std::pair<const char*, const char*>> keys{
      {"punch_displacement_m", "punch stroke [m]"},
      {"kinetic_to_internal_max", "kinetic / internal, max"},
      {"elements_mapped", "elements mapped"},
      {"vf_mean", "fibre volume fraction, mean"},
      {"vf_min", "fibre volume fraction, min"},
      {"vf_max", "fibre volume fraction, max"},
      {"tie_pairs", "resin tie pairs"},
      {"peak_force_N", "peak punch force [N]"},
      {"stroke_at_peak_m", "stroke at peak [m]"},
      {"energy_absorbed_J", "energy absorbed [J]"},
      {"dominant_failure_mode", "dominant failure mode"}};
  h << "<h2>Key results</h2>\n<table><tr><th>stage</th><th>quantity</th><th>value</th></tr>\n";
  for (const auto& e : stages) {
    const std::string nm = e["name"].get<std::string>();
    const json& ss = sums.at(nm);
    if (!ss.is_object()) continue;
    for (const auto& [k, label] : keys) {
      if (!ss.contains(k)) continue;
      std::string value =
          escape(ss[k].is_number() ? fmt::format("{:.4g}", ss[k].get<double>()) : ss[k].dump());
      // A check the stage failed shows as a warning, not as a plain number; a dynamic run
      // (no limit set, e.g. a crush) states its kinetic share as such.
      if (std::string(k) == "kinetic_to_internal_max" &&
          !(ss.value("kinetic_to_internal_limit", 0.0) > 0))
        value += " (a dynamic run: stated, not checked)";
      if (std::string(k) == "kinetic_to_internal_max" &&
          ss.value("kinetic_to_internal_exceeded", false))
        value = fmt::format(
            "<span class=\"bad\">&#9888; {} &gt; its limit {:.3g} from {:.3g} s: not "
            "quasi-static</span>",
            value, ss.value("kinetic_to_internal_limit", 0.1),
            ss.value("kinetic_to_internal_from_s", 0.0));
      h << "<tr><td>" << escape(nm) << "</td><td>" << label << "</td><td>" << value
        << "</td></tr>\n";
    }
  }
  h << "</table>\n";
}

// Every stage's `targets` (the virtual tests' [[output.target]] entries, a calibration's target):
// what was measured against what it should be, and where the target comes from; then what each
// calibration stage calibrated from which test (a characterisation's report, issue #43).
void targets_section(std::ostream& h, const json& stages, const std::map<std::string, json>& sums) {
  std::ostringstream rows;
  std::size_t n = 0, missed = 0;
  for (const auto& e : stages) {
    const std::string nm = e["name"].get<std::string>();
    const json& ss = sums.at(nm);
    if (!ss.is_object() || !ss.contains("targets")) continue;
    for (const auto& t : ss["targets"]) {
      const json& met = t.contains("met") ? t["met"] : json();
      std::string tol = "shown, not checked";
      if (t.contains("tolerance")) tol = "&plusmn; " + number(t, "tolerance");
      if (t.contains("relative_tolerance"))
        tol = fmt::format("&plusmn; {:.3g} %", 100 * t["relative_tolerance"].get<double>());
      std::string verdict = "-";
      if (met.is_boolean()) {
        verdict = met.get<bool>() ? "<span class=\"ok\">met</span>"
                                  : "<span class=\"bad\">&#9888; missed</span>";
        missed += met.get<bool>() ? 0 : 1;
      }
      std::string target = number(t, "target");
      if (t.contains("target_quantity"))
        target += " (" + escape(t["target_quantity"].get<std::string>()) + ")";
      rows << "<tr><td>" << escape(nm) << "</td><td>" << escape(t.value("quantity", ""))
           << "</td><td>" << number(t, "value") << "</td><td>" << target << "</td><td>" << tol
           << "</td><td>" << verdict << "</td><td>" << escape(t.value("source", ""))
           << "</td></tr>\n";
      ++n;
    }
  }
  std::ostringstream cal;
  for (const auto& e : stages) {
    const std::string nm = e["name"].get<std::string>();
    const json& ss = sums.at(nm);
    if (!ss.is_object() || !ss.contains("calibrated_from")) continue;
    std::string what;
    if (ss.contains("membrane_law"))
      what = "[[membrane_law]] " + ss["membrane_law"].get<std::string>();
    if (ss.contains("E11f_Pa")) what = fmt::format("E11f = {:.4g} Pa", ss["E11f_Pa"].get<double>());
    if (ss.contains("bar_law")) what = "[[bar_law]] " + ss["bar_law"].get<std::string>();
    std::string from;
    for (const auto& [k, v] : ss["calibrated_from"].items())
      from += (from.empty() ? "" : "; ") + k + ": " + v.get<std::string>();
    cal << "<tr><td>" << escape(nm) << "</td><td>" << escape(ss.value("method", "")) << "</td><td>"
        << escape(what) << "</td><td>" << escape(from) << "</td><td>"
        << (ss.contains("laws_file")
                ? "<a href=\"" + escape(nm) + "/" + escape(ss["laws_file"].get<std::string>()) +
                      "\">" + escape(ss["laws_file"].get<std::string>()) + "</a>"
                : std::string("none (see its summary)"))
        << "</td></tr>\n";
  }
  if (n > 0)
    h << "<h2>Against their targets (" << n << ", " << missed << " missed)</h2>\n"
      << "<table><tr><th>stage</th><th>quantity</th><th>value</th><th>target</th>"
         "<th>tolerance</th><th>verdict</th><th>target from</th></tr>\n"
      << rows.str() << "</table>\n";
  if (!cal.str().empty())
    h << "<h2>Calibrated laws</h2>\n<table><tr><th>stage</th><th>method</th><th>law</th>"
         "<th>from</th><th>file</th></tr>\n"
      << cal.str() << "</table>\n";
}

// A history plot whose every curve is zero (a tool that never touched, a fixed tool's
// displacement) says nothing: its name, to be listed instead of drawn.
std::vector<std::string> zero_plots(const fs::path& stage_dir) {
  std::vector<std::string> zero;
  const json specs = read_json_file(stage_dir / "figures.json");
  if (!specs.is_object() || !specs.contains("plots")) return zero;
  CsvTable history;
  try {
    history = read_csv(stage_dir / "history.csv");
  } catch (const std::exception&) {
    return zero;
  }
  for (const auto& p : specs["plots"]) {
    if (p.value("source", "") != "history.csv" || !p.contains("y")) continue;
    double largest = 0;
    bool read = false;
    for (const auto& col : p["y"]) {
      try {
        for (const double y : history.column(col.get<std::string>()))
          if (std::isfinite(y)) largest = std::max(largest, std::abs(y)), read = true;
      } catch (const std::exception&) {
      }
    }
    if (read && largest <= 1e-6) zero.push_back(p.value("name", ""));
  }
  return zero;
}

// What a reader came for, first: the formed part by shear angle, the crush curve and the failed
// modes (the ring comparison follows in its own section).
void headline_section(std::ostream& h, const fs::path& dir, const json& stages) {
  std::ostringstream f;
  const auto add = [&](const std::string& stage, const std::string& png,
                       const std::string& caption) {
    if (!fs::exists(dir / stage / "figures" / png)) return;
    f << "<figure><img src=\"" << escape(stage) << "/figures/" << escape(png) << "\" alt=\""
      << escape(caption) << "\"><figcaption>" << escape(caption) << "</figcaption></figure>\n";
  };
  for (const auto& e : stages) {
    const std::string nm = e["name"].get<std::string>();
    if (const Stage* stage = stage_of_kind(e.value("kind", "")))
      for (const auto& h : stage->headline) add(nm, h.png, nm + ": " + h.caption);
  }
  if (!f.str().empty()) h << "<h2>Results</h2>\n" << f.str();
}

// Every stage's figures (formed part by shear angle, Vf map, failure modes, force curves,
// energy balances).
void figures_section(std::ostream& h, const fs::path& dir, const json& stages) {
  for (const auto& e : stages) {
    const std::string nm = e["name"].get<std::string>();
    const fs::path figs = dir / nm / "figures";
    if (!fs::is_directory(figs)) continue;
    std::vector<std::string> pngs;
    for (const auto& f : fs::directory_iterator(figs))
      if (f.path().extension() == ".png") pngs.push_back(f.path().filename().string());
    std::sort(pngs.begin(), pngs.end());
    if (pngs.empty()) continue;
    const std::vector<std::string> zero = zero_plots(dir / nm);
    h << "<h2>" << escape(nm) << " (" << escape(e.value("kind", "")) << ")</h2>\n";
    std::string left_out;
    for (const auto& f : pngs) {
      if (std::find(zero.begin(), zero.end(), fs::path(f).stem().string()) != zero.end()) {
        left_out += (left_out.empty() ? "" : ", ") + f;
        continue;
      }
      h << "<figure><img src=\"" << escape(nm) << "/figures/" << escape(f) << "\" alt=\""
        << escape(f) << "\"><figcaption>" << escape(nm) << ": " << escape(f)
        << "</figcaption></figure>\n";
    }
    if (!left_out.empty()) h << "<p>Not shown, zero throughout: " << escape(left_out) << "</p>\n";
  }
}

// The warnings of every stage, in one list.
void warnings_section(std::ostream& h, const fs::path& dir, const json& stages) {
  std::ostringstream w;
  std::size_t n_warn = 0;
  for (const auto& e : stages) {
    const std::string nm = e["name"].get<std::string>();
    std::ifstream in(dir / nm / "warnings.txt");
    std::string line;
    while (std::getline(in, line))
      if (!line.empty()) w << "<li>[" << escape(nm) << "] " << escape(line) << "</li>\n", ++n_warn;
  }
  h << "<h2>Warnings (" << n_warn << ")</h2>\n";
  if (n_warn == 0)
    h << "<p>None.</p>\n";
  else
    h << "<ul>\n" << w.str() << "</ul>\n";
}

}  // namespace

void write_workflow_report(const fs::path& dir) {
  const json s = read_json_file(dir / "summary.json");
  if (!s.is_object() || !s.contains("stages"))
    throw std::runtime_error((dir / "summary.json").string() + " is not a workflow's summary");
  const std::string name = s.value("case", fem::stage_kind::kWorkflow);
  std::ostringstream h;
  h << html_head(name + " - ncfsim workflow");
  const std::string status = s.value("status", "unknown");
  h << "<h1>" << escape(name) << "</h1>\n<p>ncfsim " << escape(s.value("ncfsim_version", "?"))
    << " &middot; workflow " << escape(s.value("case_file", ""))
    << " &middot; status <span class=\"" << (status == "completed" ? "ok" : "bad") << "\">"
    << escape(status) << "</span> &middot; wall " << hms(s.value("wall_seconds", 0.0)) << "</p>\n";
  if (s.contains("error"))
    h << "<p class=\"bad\">" << escape(s["error"].get<std::string>()) << "</p>\n";

  std::map<std::string, json> sums;
  for (const auto& e : s["stages"])
    sums[e["name"].get<std::string>()] =
        read_json_file(dir / e["folder"].get<std::string>() / "summary.json");

  const json& stages = s["stages"];
  headline_section(h, dir, stages);
  drapes_section(h, dir, stages, sums);
  targets_section(h, stages, sums);
  key_results_section(h, stages, sums);
  process_section(h, dir, stages, sums);
  figures_section(h, dir, stages);
  warnings_section(h, dir, stages);
  h << "<p><a href=\"summary.json\">summary.json</a> &middot; <a href=\"log.txt\">log.txt</a></p>\n"
       "</body></html>\n";
  write_file_atomically(dir / "report.html", h.str());
}

}  // namespace ncfsim::workflow
