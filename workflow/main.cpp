// ncfsim: the command line (docs/cli.md). Subcommands run, check, status, render, report, export,
// calibrate, compare.
// Exit codes: 0 success, 1 other error (incl. an interrupted run), 2 bad input, 3 numerical
// failure.
#include <signal.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iostream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "fem/case/stage_kinds.hpp"
#include "fem/errors.hpp"
#include "fem/petsc_vector.hpp"
#include "fem/solver.hpp"
#include "workflow/calibrate/calibrate_macro.hpp"
#include "workflow/calibrate/calibrate_stitch.hpp"
#include "workflow/calibrate/calibrate_tow_bending.hpp"
#include "workflow/case/engine_case.hpp"
#include "workflow/compare/compare.hpp"
#include "workflow/compare/crush_compare.hpp"
#include "workflow/figures/figures.hpp"
#include "workflow/output/run_status.hpp"
#include "workflow/report/report.hpp"
#include "workflow/run/engine_run.hpp"
#include "workflow/run/mpi_launch.hpp"
#include "workflow/run/run_output.hpp"
#include "workflow/stages/stage_registry.hpp"
#include "workflow/stages/transfer_export.hpp"
#include "workflow/stages/workflow_stage.hpp"
#include "workflow/version.hpp"

namespace wf = ncfsim::workflow;

namespace {

int bad_input(const std::exception& e) {
  std::fprintf(stderr, "ncfsim: bad input: %s\n", e.what());
  return wf::kBadInput;
}

// What a subcommand (or one case of a check) ends with: its own exit code, or that of the error
// it threw, reported on stderr.
template <class Body>
int exit_code_of(const Body& body) {
  try {
    return body();
  } catch (const ncfsim::InputError& e) {
    return bad_input(e);
  } catch (const ncfsim::NumericalError& e) {
    std::fprintf(stderr, "ncfsim: numerical failure: %s\n", e.what());
    return wf::kNumericalFailure;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ncfsim: error: %s\n", e.what());
    return wf::kOtherError;
  }
}

void require_output_folder(const std::filesystem::path& dir) {
  if (!std::filesystem::is_directory(dir))
    throw ncfsim::InputError(dir.string(), "", "not a folder (give the output folder of a run)");
}

// Each subcommand: its options (a struct), where they are declared on the command line
// (add_*), and what it does (run_*). main() parses and dispatches.

struct RunArgs {
  CLI::App* cmd = nullptr;
  std::string case_file, out_dir, inputs_hash;
  std::vector<std::string> overrides, force_stages;
  int ranks = 1;
  double progress = 5.0;
  bool overwrite = false, resume = false;
};

void add_run(CLI::App& app, RunArgs& a) {
  auto* run = app.add_subcommand("run",
                                 "Run a case: writes summary.json, history.csv, log.txt, "
                                 "results.h5/.xdmf and figures to the output folder");
  a.cmd = run;
  run->add_option("case", a.case_file, "Case file (TOML)")->required();
  run->add_option("-o,--output", a.out_dir, "Output folder (default results/<case name>)")
      ->check(CLI::Validator(
          [](const std::string& s) {
            return s.empty() ? std::string("an empty output folder") : std::string();
          },
          "FOLDER"));
  run->add_option("--set", a.overrides,
                  "Override a case key: --set KEY=VALUE (repeatable), e.g. "
                  "--set mesh.resolution=coarse");
  run->add_option("--np", a.ranks, "MPI ranks (default 1)")->check(CLI::Range(1, 1 << 20));
  run->add_flag("--overwrite", a.overwrite,
                "Write into an output folder that holds files ncfsim did not write (those of the "
                "same names are replaced, nothing else is touched)");
  run->add_option("--force", a.force_stages,
                  "Workflow: rerun this stage although its inputs have not changed (repeatable)");
  run->add_flag("--resume", a.resume,
                "Continue an interrupted run in its output folder from its checkpoint.h5 (the "
                "same case and --set; time.max_cycles may differ)");
  // A workflow's engine stage started on several ranks: its inputs hash.
  run->add_option("--inputs-hash", a.inputs_hash, "(internal: set by a workflow for its stages)")
      ->group("");
  run->add_option("--progress-interval", a.progress, "Seconds between progress lines (default 5)")
      ->check(CLI::Validator(
          [](const std::string& s) {
            double v = 0;
            try {
              v = std::stod(s);
            } catch (const std::exception&) {
              return std::string("not a number");
            }
            // NaN passes CLI11's PositiveNumber and Range (every comparison with it is false)
            return std::isfinite(v) && v > 0 ? std::string()
                                             : std::string("must be a finite number > 0");
          },
          "SECONDS"));
}

// `ncfsim run ... --np N` outside a launcher: starts N ranks of this same executable with the
// launcher CMake found, the same arguments less --np (docs/cli.md), and waits for them: one
// Ctrl-C (or SIGTERM) is passed on to the ranks, which checkpoint at one cycle; if this process
// is killed, so is the launcher. A rank lost (killed, out of memory, crashed) ends the job
// without the run's status: this process writes it (failed, naming the rank) into summary.json.
int relaunch_with_mpiexec(const RunArgs& a, int argc, char** argv) {
  std::vector<std::string> args = wf::mpi_launch_command(a.ranks);
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--np") {
      ++i;
      continue;
    }
    if (arg.rfind("--np=", 0) == 0) continue;
    args.push_back(arg);
  }
  wf::LauncherExit ex;
  try {
    ex = wf::run_launcher(args, wf::launcher_environment(), SIGKILL, wf::StopRequest::requested);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ncfsim: bad input: --np %d: %s\n", a.ranks, e.what());
    return wf::kBadInput;
  }
  if (ex.exit_code == 0) return 0;
  if (!ex.lost_rank.empty())
    std::fprintf(stderr, "ncfsim: MPI %s was lost; the launcher ended the other ranks\n",
                 ex.lost_rank.c_str());
  try {
    const std::filesystem::path dir = wf::run_output_folder(a.case_file, a.overrides, a.out_dir);
    if (!dir.empty() && wf::record_lost_rank(dir, ex.lost_rank, ex.exit_code, a.ranks))
      std::fprintf(stderr, "ncfsim: %s/summary.json: status failed (it said running)\n",
                   dir.string().c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ncfsim: the run's status could not be checked: %s\n", e.what());
  }
  return ex.exit_code;
}

// [case] kind -> its stage (workflow/stages/stage_registry.hpp).
int run_run(const RunArgs& a, wf::Verbosity verbosity, int argc, char** argv) {
  // A workflow is not relaunched: it runs its engine stages on --np ranks each.
  if (a.ranks > 1 && !wf::started_by_mpi_launcher() &&
      !wf::find_stage(wf::case_kind(a.case_file, a.overrides), a.case_file).holds_stages)
    return relaunch_with_mpiexec(a, argc, argv);
  wf::StageCall call;
  call.case_file = a.case_file;
  call.overrides = a.overrides;
  call.options.out_dir = a.out_dir;
  call.options.verbosity = verbosity;
  call.options.overrides = a.overrides;
  call.options.ranks = a.ranks;
  call.options.progress_interval_s = a.progress;
  call.options.force_stages = a.force_stages;
  call.options.overwrite = a.overwrite;
  call.options.resume = a.resume;
  call.options.inputs_hash = a.inputs_hash;
  return wf::run_stage(call);
}

struct CheckArgs {
  CLI::App* cmd = nullptr;
  std::vector<std::string> case_files;
  std::vector<std::string> overrides;
};

void add_check(CLI::App& app, CheckArgs& a) {
  a.cmd = app.add_subcommand("check",
                             "Validate cases without running them (exit 0, or 2 with the "
                             "file, key and allowed range)");
  a.cmd->add_option("case", a.case_files, "Case files (TOML); several are checked one by one")
      ->required();
  a.cmd->add_option("--set", a.overrides,
                    "Override a case key: --set KEY=VALUE (repeatable, applies to every case)");
}

// [case] kind -> its stage's check.
int check_one(const std::string& case_file, const std::vector<std::string>& overrides) {
  wf::StageCall call;
  call.case_file = case_file;
  call.overrides = overrides;
  return wf::check_stage(call);
}

// Several case files: each checked as alone, its outcome on a line of its own; the exit code is
// the worst of them (any other failure, else 2 for any bad input, else 0). MPI is started once
// for all of them: what a check costs is mostly the start of the process and of MPI.
int run_check(const CheckArgs& a) {
  if (a.case_files.size() == 1) return check_one(a.case_files[0], a.overrides);
  ncfsim::fem::PetscSession petsc;
  if (const int code = wf::refuse_many_ranks()) return code;
  int worst = wf::kSuccess;
  std::size_t valid = 0, bad = 0;
  for (const auto& file : a.case_files) {
    const int code = exit_code_of([&]() -> int { return check_one(file, a.overrides); });
    std::fflush(stderr);
    std::printf("check %s: %s (exit %d)\n", file.c_str(),
                code == wf::kSuccess    ? "valid"
                : code == wf::kBadInput ? "bad input"
                                        : "failed",
                code);
    std::fflush(stdout);
    valid += code == wf::kSuccess;
    bad += code == wf::kBadInput;
    if (code != wf::kSuccess && code != wf::kBadInput)
      worst = code;
    else if (code == wf::kBadInput && worst == wf::kSuccess)
      worst = code;
  }
  std::printf("checked %zu case files: %zu valid, %zu bad input, %zu failed\n", a.case_files.size(),
              valid, bad, a.case_files.size() - valid - bad);
  return worst;
}

// render, status, report, export: the output folder of a finished (or running) run.
struct FolderArgs {
  CLI::App* render = nullptr;
  CLI::App* status = nullptr;
  CLI::App* report = nullptr;
  CLI::App* exporter = nullptr;
  std::string folder, deck_format;
  std::string export_output;  // export of a crush case: where the deck goes
  std::vector<std::string> export_overrides;
};

void add_render_and_status(CLI::App& app, FolderArgs& a) {
  a.render = app.add_subcommand("render", "(Re)draw the figures of a finished run (off-screen)");
  a.render->add_option("outdir", a.folder, "Output folder of a run")->required();
  a.status = app.add_subcommand(
      "status",
      "Say how a run or workflow in an output folder stands (running, completed, failed, ...); "
      "a summary that still says running with no process holding the folder becomes killed");
  a.status->add_option("outdir", a.folder, "Output folder of a run or workflow")->required();
}

void add_report_and_export(CLI::App& app, FolderArgs& a) {
  a.report = app.add_subcommand("report", "Write report.html for a finished run");
  a.report->add_option("outdir", a.folder, "Output folder of a run")->required();
  a.exporter = app.add_subcommand(
      "export",
      "Write a crush case as a deck another solver runs (LS-DYNA, OpenRadioss: the whole crush; "
      "Abaqus: the model, elastic), or the impregnated model of a transfer run's folder");
  a.exporter
      ->add_option("source", a.folder,
                   "A crush case file (kind = \"crush\"), or the output folder of a transfer run")
      ->required();
  a.exporter->add_option("-o,--output", a.export_output,
                         "Crush case: folder for the deck (default results/<case name>_<format>)");
  a.exporter->add_option("--set", a.export_overrides,
                         "Crush case: override a case key, KEY=VALUE (repeatable)");
  a.exporter->add_option("--format", a.deck_format, "abaqus | lsdyna | radioss (a crush case)")
      ->required()
      ->check(CLI::IsMember({"abaqus", "lsdyna", "radioss"}));
}

int run_render(const std::string& folder, wf::Verbosity verbosity) {
  require_output_folder(folder);
  const auto lock = wf::FolderLock::acquire(folder, "render");  // not while a run writes
  auto log = wf::make_run_logger({}, verbosity);
  const auto pngs = wf::render_figures(folder, *log);
  wf::OutputFolder::record(folder, pngs);
  for (const auto& p : pngs) log->info("{}", p.string());
  return pngs.empty() ? wf::kOtherError : wf::kSuccess;
}

int run_export(const FolderArgs& a) {
  const std::string& folder = a.folder;
  const std::string& deck_format = a.deck_format;
  if (std::filesystem::is_regular_file(folder)) {  // a crush case
    ncfsim::fem::PetscSession petsc;  // the Radioss deck's ties are the crush solver's own
    const auto r = wf::export_crush_case(folder, a.export_overrides, deck_format, a.export_output);
    std::printf("%s: %zu nodes, %zu elements, %zu materials, %zu tie faces, %zu stitch bars\n",
                r.result.file.c_str(), r.result.nodes, r.result.elements, r.result.materials,
                r.result.tie_pairs, r.result.bars);
    for (const auto& line : r.carried) std::printf("  carried: %s\n", line.c_str());
    for (const auto& line : r.left_out) std::printf("  left out: %s\n", line.c_str());
    return wf::kSuccess;
  }
  if (!a.export_output.empty() || !a.export_overrides.empty())
    throw ncfsim::InputError(folder, "--output / --set",
                             "given with a transfer run's folder: those are for a crush case file");
  require_output_folder(folder);
  const auto lock = wf::FolderLock::acquire(folder, "export");
  const auto r = wf::export_impregnated(folder, deck_format);
  wf::OutputFolder::record(folder, {r.file});
  std::printf("%s: %zu nodes, %zu elements, %zu materials, %zu tie pairs, %zu stitch bars\n",
              r.file.c_str(), r.nodes, r.elements, r.materials, r.tie_pairs, r.bars);
  return wf::kSuccess;
}

int run_status(const std::string& folder) {
  require_output_folder(folder);
  for (const auto& f : wf::folder_status(folder))
    std::printf("%s: %s%s\n", f.dir.c_str(),
                f.stage == ncfsim::fem::stage_kind::kEngine ? "" : (f.stage + " ").c_str(),
                f.line.c_str());
  return wf::kSuccess;
}

int run_report(const std::string& folder) {
  require_output_folder(folder);
  const auto lock = wf::FolderLock::acquire(folder, "report");
  const auto js = wf::read_json_file(std::filesystem::path(folder) / "summary.json");
  const wf::Stage* stage = js.is_object() ? wf::stage_of_kind(js.value("stage", "")) : nullptr;
  if (stage && stage->holds_stages)
    wf::write_workflow_report(folder);
  else
    wf::write_report(folder);
  wf::OutputFolder::record(folder, {std::filesystem::path(folder) / "report.html"});
  std::printf("%s\n", (std::filesystem::path(folder) / "report.html").c_str());
  return wf::kSuccess;
}

struct StitchCalibrationArgs {
  CLI::App* cmd = nullptr;
  wf::StitchCalibrationOptions sc;
  std::string shear = "positive";
};

void add_calibrate_stitch(CLI::App& calibrate, StitchCalibrationArgs& a) {
  wf::StitchCalibrationOptions& sc = a.sc;
  auto* cal_stitch = calibrate.add_subcommand(
      "stitch",
      "Stitch force-strain law from bias-extension force data (Eq. 2-6): positive shear "
      "calibrates the 'I' stitches, negative shear the 'Lambda' stitches");
  a.cmd = cal_stitch;
  cal_stitch->add_option("data", sc.data, "CSV with a header row")
      ->required()
      ->check(CLI::ExistingFile);
  cal_stitch->add_option("--extension-column", sc.extension_column,
                         "Extension column (default extension_m)");
  cal_stitch->add_option("--force-column", sc.force_column, "Force column (default force_N)");
  cal_stitch->add_option("--extension-scale", sc.extension_scale, "Factor to m (1e-3 for mm)")
      ->check(CLI::PositiveNumber);
  cal_stitch->add_option("--force-scale", sc.force_scale, "Factor to N")
      ->check(CLI::PositiveNumber);
  cal_stitch->add_option("--shear", a.shear, "positive | negative")
      ->check(CLI::IsMember({"positive", "negative"}));
  cal_stitch->add_option("--coupon-length", sc.coupon.length, "Free length H, m (default 0.25)")
      ->check(CLI::PositiveNumber);
  cal_stitch->add_option("--coupon-width", sc.coupon.width, "Width W, m (default 0.05)")
      ->check(CLI::PositiveNumber);
  cal_stitch
      ->add_option("--stitch-length", sc.coupon.stitch_length,
                   "Stitch length c0, m (default 2.5e-3)")
      ->check(CLI::PositiveNumber);
  cal_stitch->add_option("--gauge", sc.coupon.gauge, "Wale spacing h0, m (default 5.08e-3)")
      ->check(CLI::PositiveNumber);
  cal_stitch
      ->add_option("--max-shear-deg", sc.max_shear_deg,
                   "Use data up to this central shear (default 30)")
      ->check(CLI::Range(1.0, 60.0));
  cal_stitch->add_option("--points", sc.points, "Points of the law (default 12)")
      ->check(CLI::Range(2, 200));
  cal_stitch->add_option("--name", sc.law_name, "Name of the [[bar_law]] (default stitch)");
  cal_stitch->add_option("-o,--output", sc.out_dir, "Output folder (default stitch_calibration)");
}

int run_calibrate_stitch(StitchCalibrationArgs& a) {
  a.sc.sign = a.shear == "negative" ? ncfsim::drape::ShearSign::Negative
                                    : ncfsim::drape::ShearSign::Positive;
  wf::calibrate_stitch(a.sc);
  std::printf(
      "%s: stitch_law.csv, stitch_law.toml, figures/stitch_law.png, figures/stitch_fit.png\n",
      a.sc.out_dir.c_str());
  return wf::kSuccess;
}

struct TowBendingArgs {
  CLI::App* cmd = nullptr;
  wf::TowBendingCalibration tb;
};

void add_calibrate_tow_bending(CLI::App& calibrate, TowBendingArgs& a) {
  wf::TowBendingCalibration& tb = a.tb;
  auto* cal_bend = calibrate.add_subcommand(
      "tow-bending",
      "Tow fibre modulus E11f that gives a target ASTM D1388 bending length in the "
      "virtual cantilever test (the case needs an [[output.bending_length]] probe)");
  a.cmd = cal_bend;
  cal_bend->add_option("case", tb.case_file, "Cantilever-bending case (TOML)")
      ->required()
      ->check(CLI::ExistingFile);
  cal_bend
      ->add_option("--target-bending-length", tb.target_bending_length,
                   "Measured bending length c, m")
      ->required()
      ->check(CLI::PositiveNumber);
  cal_bend->add_option("--tolerance", tb.tolerance, "Relative tolerance on c (default 0.01)")
      ->check(CLI::Range(1e-4, 0.2));
  cal_bend->add_option("--max-runs", tb.max_runs, "Most simulation runs (default 6)")
      ->check(CLI::Range(1, 50));
  cal_bend->add_option("--set", tb.overrides, "Override a case key (repeatable)");
  cal_bend->add_option("-o,--output", tb.out_dir,
                       "Output folder (default tow_bending_calibration)");
}

int run_calibrate_tow_bending(const TowBendingArgs& a) {
  ncfsim::fem::PetscSession petsc;
  if (const int code = wf::refuse_many_ranks()) return code;
  const auto r = wf::calibrate_tow_bending(a.tb);
  std::printf(
      "E11f = %.6g Pa gives a bending length of %.6g m (target %.6g m) after %d runs%s; see "
      "%s\n",
      r.E11f, r.bending_length, a.tb.target_bending_length, r.runs,
      r.converged ? "" : " (NOT converged)", (a.tb.out_dir / "calibration.json").c_str());
  return r.converged ? wf::kSuccess : wf::kNumericalFailure;
}

struct MacroCalibrationArgs {
  CLI::App* cmd = nullptr;
  wf::MacroCalibrationOptions mc;
  std::vector<double> angles;
};

void add_calibrate_macro(CLI::App& calibrate, MacroCalibrationArgs& a) {
  wf::MacroCalibrationOptions& mc = a.mc;
  auto* cal_macro = calibrate.add_subcommand(
      "macro",
      "Macro fabric membrane law ([[membrane_law]] type fabric) from the meso picture-frame "
      "runs: normalised shear force vs shear angle per sign, monotone, as a TOML block");
  a.cmd = cal_macro;
  cal_macro->add_option("--positive", mc.positive, "Meso picture-frame run folder, positive shear")
      ->required();
  cal_macro->add_option("--negative", mc.negative, "Meso picture-frame run folder, negative shear")
      ->required();
  cal_macro->add_option(
      "--unstitched", mc.unstitched,
      "Unstitched meso frame run folder: a second, symmetric law <name>_unstitched");
  cal_macro->add_option(
      "--bias-positive", mc.bias_positive,
      "Meso bias-extension run folder, positive (a check, in the file's comments)");
  cal_macro->add_option("--bias-negative", mc.bias_negative,
                        "Meso bias-extension run folder, negative (a check)");
  cal_macro->add_flag("--symmetric", mc.symmetric, "One curve: the mean of the two signs");
  cal_macro->add_flag("--stitch-bars", mc.stitch_bars,
                      "The stitch as bars on the shells ([[mesh.shell_stitch]]): the positive "
                      "curve less the pillars' kinematic force, and the pillar law");
  cal_macro->add_option("--frame", mc.frame, "Picture-frame name in the runs (default frame)");
  cal_macro->add_option("--name", mc.name, "[[membrane_law]] name (default ncf_macro)");
  cal_macro->add_option("--step", mc.step_deg, "Angle step of the curve, deg (default 2.5)");
  cal_macro->add_option("--max-angle", mc.max_angle_deg,
                        "Last angle of the curve, deg (default: as far as the runs reach)");
  cal_macro->add_option("--areal-density", mc.areal_density, "kg/m^2 (default 0.482)");
  cal_macro->add_option("--fibre-angles", a.angles, "From the wale, deg (default 45,-45)")
      ->expected(2)
      ->delimiter(',');
  cal_macro->add_option("--fibre-tension-stiffness", mc.fibre_tension_stiffness,
                        "N/m per family (default 2e5)");
  cal_macro->add_option("--fibre-compression-ratio", mc.fibre_compression_ratio,
                        "Compression / tension stiffness (default 1e-3)");
  cal_macro->add_option("--bending-stiffness", mc.bending_stiffness, "N m (default 1e-4)");
  cal_macro->add_option("--coupon-length", mc.coupon_length,
                        "Bias-extension check: free length H, m (default 0.25)");
  cal_macro->add_option("--coupon-width", mc.coupon_width,
                        "Bias-extension check: width W, m (default 0.10)");
  cal_macro->add_option("--curves-csv", mc.curves_csv,
                        "Also write the meso curves on the grid (fitted and clipped) to this CSV");
  cal_macro->add_option("-o,--output", mc.output,
                        "The TOML file written (default macro_membrane_law.toml)");
}

int run_calibrate_macro(MacroCalibrationArgs& a) {
  wf::MacroCalibrationOptions& mc = a.mc;
  if (!a.angles.empty()) mc.fibre_angles_deg = {a.angles[0], a.angles[1]};
  const auto r = wf::calibrate_macro(mc);
  for (const auto& n : r.notes) std::printf("%s\n", n.c_str());
  std::printf("%s: [[membrane_law]] \"%s\" (%zu + %zu curve points)\n", mc.output.c_str(),
              mc.name.c_str(), r.positive.curve.angle_deg.size(),
              mc.symmetric ? std::size_t{0} : r.negative.curve.angle_deg.size());
  return wf::kSuccess;
}

struct CompareArgs {
  CLI::App* cmd = nullptr;
  wf::CompareOptions cmp;
  std::vector<double> ring_centre, ring_axis, ring_zero;
};

void add_compare(CLI::App& app, CompareArgs& a) {
  wf::CompareOptions& cmp = a.cmp;
  auto* compare = app.add_subcommand(
      "compare",
      "Shear rings (the Fig. 18 measure) of drape runs and imported macro results side by side: "
      "quadrant maxima, RMS and largest differences, one plot");
  a.cmd = compare;
  compare
      ->add_option("sources", cmp.sources,
                   "Run folders (meso drape, kinematic_drape, macro drape, workflow) and macro "
                   "results (.vtu, .csv); LABEL=PATH names one")
      ->required();
  compare->add_option("-o,--output", cmp.out_dir, "Output folder (default comparison)");
  compare->add_option("--field", cmp.import.field,
                      "Shear-angle field / column of the imported files (deg; default: the first "
                      "of shear_angle_deg, shear_deg, shear_angle, shear)");
  compare->add_option("--tolerance", cmp.import.tolerance,
                      "Point clouds: search radius about each ring ray, m (default 1.5 x the "
                      "median point spacing, at most 10 mm)");
  compare->add_option("--length-scale", cmp.import.length_scale,
                      "Imported files: factor from their length unit to m (default 1; 1e-3: mm)");
  compare->add_option("--ring-height", cmp.import.ring.height,
                      "Ring height above the reference plane, m (default 0.04)");
  compare->add_option("--ring-centre", a.ring_centre, "Point of the axis in the plane: x,y,z (m)")
      ->expected(3)
      ->delimiter(',');
  compare->add_option("--ring-axis", a.ring_axis, "Ring axis: x,y,z (default 0,0,1)")
      ->expected(3)
      ->delimiter(',');
  compare->add_option("--ring-zero-direction", a.ring_zero, "Azimuth 0, the wale: x,y,z (1,0,0)")
      ->expected(3)
      ->delimiter(',');
  compare->add_option("--ring-step", cmp.import.ring.step_deg, "Azimuth step, deg (default 1)");
  compare->add_flag("--overwrite", cmp.overwrite,
                    "Write into a folder that holds files ncfsim did not write");
}

struct CrushCompareArgs {
  CLI::App* cmd = nullptr;
  wf::CrushCompareOptions cmp;
  double slope_window_mm = 0;
};

void add_compare_crush(CLI::App& app, CrushCompareArgs& a) {
  a.cmd = app.add_subcommand(
      "compare-crush",
      "Punch force against stroke of crush runs and other solvers' curves side by side: elastic "
      "slope, peak, absorbed energy and their differences, one plot");
  a.cmd
      ->add_option("sources", a.cmp.sources,
                   "Crush run folders and CSV files with stroke_m, force_N (time_s optional); "
                   "LABEL=PATH names one")
      ->required();
  a.cmd->add_option("-o,--output", a.cmp.out_dir, "Output folder (default crush_comparison)");
  a.cmd->add_option("--cfc", a.cmp.cfc,
                    "SAE J211 class of the filtered force (default 600; 0: raw)");
  a.cmd
      ->add_option("--slope-window", a.slope_window_mm,
                   "Stroke after each curve's contact over which the elastic slope is fitted, "
                   "mm (default: the shortest first loading, contact to first peak, of all)")
      ->check(CLI::Range(0.0, 100.0));
  a.cmd->add_flag("--overwrite", a.cmp.overwrite,
                  "Write into a folder that holds files ncfsim did not write");
}

int run_compare(CompareArgs& a, wf::Verbosity verbosity) {
  wf::CompareOptions& cmp = a.cmp;
  cmp.verbosity = verbosity;
  if (!a.ring_centre.empty()) cmp.import.ring.centre = ncfsim::fem::V3::at(a.ring_centre.data());
  if (!a.ring_axis.empty()) cmp.import.ring.axis = ncfsim::fem::V3::at(a.ring_axis.data());
  if (!a.ring_zero.empty())
    cmp.import.ring.zero_direction = ncfsim::fem::V3::at(a.ring_zero.data());
  return wf::compare_rings(cmp);
}

}  // namespace

int main(int argc, char** argv) {
  wf::StopRequest::install();  // before anything: a signal at any time ends the run cleanly
  CLI::App app{
      "ncfsim: meso-mechanical drape-to-failure simulation of stitched carbon fabric "
      "(explicit finite elements)"};
  app.set_version_flag("--version", std::string("ncfsim ") + wf::kVersion);
  app.require_subcommand(1);
  bool quiet = false, verbose = false;
  app.add_flag("-q,--quiet", quiet,
               "Only warnings and errors on the console (log.txt keeps everything)");
  app.add_flag("-v,--verbose", verbose, "Debug messages on the console and in log.txt");

  RunArgs run;
  CheckArgs check;
  FolderArgs folder;
  StitchCalibrationArgs stitch;
  TowBendingArgs bending;
  MacroCalibrationArgs macro;
  CompareArgs compare;
  CrushCompareArgs compare_crush;
  add_run(app, run);
  add_check(app, check);
  add_render_and_status(app, folder);
  add_report_and_export(app, folder);
  auto* calibrate = app.add_subcommand("calibrate", "Calibrate model parameters from test data");
  add_calibrate_stitch(*calibrate, stitch);
  calibrate->require_subcommand(1);
  add_calibrate_tow_bending(*calibrate, bending);
  add_calibrate_macro(*calibrate, macro);
  add_compare(app, compare);
  add_compare_crush(app, compare_crush);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : wf::kBadInput;
  }
  const wf::Verbosity verbosity = quiet     ? wf::Verbosity::Quiet
                                  : verbose ? wf::Verbosity::Verbose
                                            : wf::Verbosity::Normal;
  return exit_code_of([&]() -> int {
    if (*check.cmd) return run_check(check);
    if (*run.cmd) return run_run(run, verbosity, argc, argv);
    if (*compare.cmd) return run_compare(compare, verbosity);
    if (*compare_crush.cmd) {
      compare_crush.cmp.verbosity = verbosity;
      compare_crush.cmp.slope_window = 1e-3 * compare_crush.slope_window_mm;
      return wf::compare_crushes(compare_crush.cmp);
    }
    if (*stitch.cmd) return run_calibrate_stitch(stitch);
    if (*macro.cmd) return run_calibrate_macro(macro);
    if (*bending.cmd) return run_calibrate_tow_bending(bending);
    if (*folder.render) return run_render(folder.folder, verbosity);
    if (*folder.exporter) return run_export(folder);
    if (*folder.status) return run_status(folder.folder);
    if (*folder.report) return run_report(folder.folder);
    return wf::kOtherError;
  });
}
