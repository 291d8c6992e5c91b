// The engine run: the time loop and what it writes (log, history.csv, summary.json, frames,
// figures, report). What is measured comes from the case's measures (run_measures.hpp; the
// fabric tests' in drape/probes), the summary pieces from run_summary.hpp, the frames' data from
// result_mesh.hpp.
#include "workflow/run/engine_run.hpp"

#include <fmt/format.h>
#include <spdlog/logger.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <map>
#include <optional>
#include <sstream>

#include "fem/checkpoint.hpp"
#include "fem/errors.hpp"
#include "fem/io/hdf5_checkpoint.hpp"
#include "fem/io/result_writers.hpp"
#include "fem/memory_estimate.hpp"
#include "fem/parallel/domain.hpp"
#include "fem/petsc_vector.hpp"
#include "fem/solver.hpp"
#include "workflow/figures/figures.hpp"
#include "workflow/report/report.hpp"
#include "workflow/run/result_mesh.hpp"
#include "workflow/run/run_checkpoint.hpp"
#include "workflow/run/run_history.hpp"
#include "workflow/run/run_measures.hpp"
#include "workflow/run/run_summary.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace {

using Clock = std::chrono::steady_clock;
using json = nlohmann::json;

double seconds_since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// results.h5/.xdmf and .vtu frames; a frame that cannot be written is logged, the run goes on.
class FrameOutput {
 public:
  /// New files, or with `resume` none yet: load_state() takes over those of the run it resumes.
  FrameOutput(const std::filesystem::path& dir, const OutputSettings& o,
              const fem::ExplicitSolver& s, bool resume = false)
      : dir_(dir), settings_(o) {
    if ((!o.xdmf && !o.vtu) || resume) return;
    const fem::io::ResultMesh mesh = result_mesh(s);
    if (o.xdmf) xdmf_ = std::make_unique<fem::io::XdmfResultWriter>(dir, mesh);
    if (o.vtu) vtu_ = std::make_unique<fem::io::VtuSeriesWriter>(dir, mesh);
  }
  void save_state(fem::CheckpointWriter& w) const {
    w.write_int("frames_written", static_cast<std::int64_t>(written_));
    w.write_int("frame_errors", static_cast<std::int64_t>(errors_));
    fem::save_array(w, "frame_time", times_);
    fem::save_array(w, "frame_cycle", cycles_);
    std::string fields;
    if (xdmf_)
      for (const auto& fr : xdmf_->written_frames()) {
        for (std::size_t i = 0; i < fr.fields.size(); ++i)
          fields += (i ? ";" : "") + fr.fields[i].name + "," + (fr.fields[i].on_cells ? "1" : "0") +
                    "," + std::to_string(fr.fields[i].n_components);
        fields += '\n';
      }
    w.write_string("frame_fields", fields);
  }
  /// The frames written up to the checkpoint are kept where they are; those written after it
  /// go (their results.h5 groups, their .vtu files).
  void load_state(fem::CheckpointReader& r, const fem::ExplicitSolver& s) {
    written_ = static_cast<std::size_t>(r.read_int("frames_written"));
    errors_ = static_cast<std::size_t>(r.read_int("frame_errors"));
    r.read_array("frame_time", times_, written_);
    r.read_array("frame_cycle", cycles_, written_);
    if (!settings_.xdmf && !settings_.vtu) return;
    const fem::io::ResultMesh mesh = result_mesh(s);
    if (settings_.xdmf) {
      // The frames' fields as results.xdmf listed them: "name,cells,components;..." per line.
      std::vector<fem::io::WrittenFrame> kept(written_);
      std::stringstream lines(r.read_string("frame_fields"));
      std::string line;
      for (std::size_t k = 0; k < written_; ++k) {
        kept[k].time = times_[k];
        kept[k].cycle = static_cast<int>(cycles_[k]);
        if (!std::getline(lines, line)) r.mismatch("frame_fields", "lists fewer frames");
        std::stringstream fields(line);
        for (std::string f; std::getline(fields, f, ';');) {
          const auto c1 = f.find(','), c2 = f.rfind(',');
          if (c1 == std::string::npos || c2 == c1) r.mismatch("frame_fields", "cannot be read");
          kept[k].fields.push_back(
              {f.substr(0, c1), f.substr(c1 + 1, c2 - c1 - 1) == "1", std::stoi(f.substr(c2 + 1))});
        }
      }
      try {
        xdmf_ = std::make_unique<fem::io::XdmfResultWriter>(
            fem::io::XdmfResultWriter::reopen(dir_, mesh, kept));
      } catch (const std::runtime_error& e) {
        throw InputError((dir_ / "results.h5").string(), "--resume",
                         std::string("cannot be continued: ") + e.what());
      }
    }
    if (settings_.vtu) {
      vtu_ = std::make_unique<fem::io::VtuSeriesWriter>(dir_, mesh);
      try {
        vtu_->keep_frames(times_);
      } catch (const std::runtime_error& e) {
        throw InputError((dir_ / "results.pvd").string(), "--resume", e.what());
      }
    }
  }
  void write(const fem::ExplicitSolver& s, const MeasureList& measures, spdlog::logger& log) {
    if (!xdmf_ && !vtu_) return;
    fem::io::Frame fr = make_frame(s);
    std::vector<fem::MeasureCellField> extra;
    for (const auto& m : measures) m->add_frame_fields(s, extra);
    for (auto& f : extra)
      fr.fields.push_back({std::move(f.name), true, f.n_components, std::move(f.values)});
    try {
      if (xdmf_) xdmf_->write_frame(fr);
      if (vtu_) vtu_->write_frame(fr);
      ++written_;
      times_.push_back(fr.time);
      cycles_.push_back(fr.cycle);
    } catch (const std::runtime_error& e) {
      ++errors_;
      log.error("frame at t = {:.6g} s not written: {}", s.time(), e.what());
    }
  }
  void close() {
    if (xdmf_) xdmf_->close();
    if (vtu_) vtu_->close();
  }
  std::size_t written() const { return written_; }
  std::size_t errors() const { return errors_; }

 private:
  std::filesystem::path dir_;
  OutputSettings settings_;
  std::unique_ptr<fem::io::XdmfResultWriter> xdmf_;
  std::unique_ptr<fem::io::VtuSeriesWriter> vtu_;
  std::size_t written_ = 0, errors_ = 0;
  std::vector<double> times_;         // of the frames written
  std::vector<std::int64_t> cycles_;  // of the frames written
};

// What the loop and the summary share while a case runs.
struct Run {
  Run(const EngineCase& c, const RunOptions& o)
      : ec(c),
        options(o),
        dir(output_folder(c, o)),
        wall0(Clock::now()),
        summary(summary_header(c, o)) {}
  const EngineCase& ec;
  const RunOptions& options;
  std::filesystem::path dir;
  std::shared_ptr<spdlog::logger> log;  // console + log.txt, made once the folder is clean
  Clock::time_point wall0;
  json summary;
  std::string status = "completed", failure;
  std::vector<std::string> target_warnings;  // [[output.target]] entries missed (add_targets)
  // Largest energy-balance error per decade of the energy in play so far (scale_max): the
  // summary's maximum skips the decades far below the run's largest energy, where the residual
  // is round-off on next to nothing (a model at rest before the tool arrives).
  std::map<int, double> max_error_by_decade;
  double max_error() const {
    if (max_error_by_decade.empty()) return 0.0;
    const int top = max_error_by_decade.rbegin()->first;
    double m = 0;
    for (const auto& [decade, err] : max_error_by_decade)
      if (decade >= top - kBalanceDecades) m = std::max(m, err);
    return m;
  }
  static constexpr int kBalanceDecades = 3;
  double ke_ie_max =
      0;  // kinetic / internal energy at the history rows from time.quasi_static_from
  bool ke_ie_exceeded = false;

  // The time loop's own state (saved in a checkpoint).
  struct LoopState {
    double next_history = 0, next_frame = 0;
    bool exceeded_reported = false;
    std::size_t erosions_logged = 0;
  } loop;
  // Checkpoints (issue #22).
  std::string case_hash;               // checkpoint_case_hash of the case and overrides
  double wall_before = 0;              // wall seconds of the segments before this one
  std::int64_t segments = 1;           // this run's segment (1 + the resumes)
  Clock::time_point last_checkpoint;   // wall time of the last checkpoint (or the start)
  std::int64_t checkpoint_cycle = -1;  // cycle of the last checkpoint written or loaded
  double wall_seconds() const { return wall_before + seconds_since(wall0); }
  // (wall s, simulated s) at each progress line: the ETA's recent rate (log_progress).
  mutable std::vector<std::pair<double, double>> progress;
  // This segment's time loop: wall and CPU seconds of the main thread and its cycles. The phase
  // timers are wall time; on a shared machine a run is off the CPU part of it, which the
  // benchmarks (thread CPU time) do not count: loop_cpu / loop_wall scales them to CPU time.
  double loop_wall = 0, loop_cpu = 0;
  std::int64_t loop_cycles = 0;

  void write_summary() const {
    write_file_atomically(dir / "summary.json", summary.dump(2) + "\n");
  }
};

// CPU time of the calling thread, s (what bench/ counts).
double thread_cpu_seconds() {
  timespec ts{};
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

void log_start(const Run& r) {
  r.log->info("ncfsim {} | case '{}' ({}) | resolution {}", kVersion, r.ec.name, r.ec.file.string(),
              r.ec.resolution);
  if (!r.ec.description.empty()) r.log->info("  {}", r.ec.description);
  for (const auto& ov : r.options.overrides) r.log->info("  --set {}", ov);
  for (const auto& law : r.ec.laws_replaced) r.log->info("  law {} (case.laws)", law);
  if (fem::PetscSession::size() > 1)
    r.log->info("on {} MPI ranks (domain decomposition, docs/parallel.md)",
                fem::PetscSession::size());
}

std::unique_ptr<fem::ExplicitSolver> make_solver(EngineCase& ec, Run& r) {
  try {
    return std::make_unique<fem::ExplicitSolver>(ec.model);
  } catch (const InputError& e) {
    r.summary["status"] = "bad_input";
    r.summary["error"] = e.what();
    r.write_summary();
    if (!e.file().empty()) throw;
    // The model's checks name the key; the case file is this run's.
    throw InputError(ec.file.string(), e.key(), e.message(), e.value(), e.allowed());
  }
}

void fill_summary(Run& r, const fem::ExplicitSolver& s, const MeasureList& measures,
                  const RunHistory& history, const FrameOutput& frames) {
  r.summary["status"] = r.status;
  r.summary["wall_seconds"] = r.wall_seconds();
  r.summary["peak_memory_MB"] = fem::peak_resident_mb();
  r.summary["huge_pages_MB"] = static_cast<double>(s.huge_pages().huge_bytes >> 20);
  r.summary["frames"] = frames.written();
  r.summary["frame_write_errors"] = frames.errors();
  add_state_summary(s, r.max_error(), r.summary);
  if (r.loop_wall > 0) {
    r.summary["timers_s"]["loop_wall"] = r.loop_wall;
    r.summary["timers_s"]["loop_cpu"] = r.loop_cpu;
    r.summary["timers_s"]["loop_cycles"] = r.loop_cycles;
  }
  r.summary["kinetic_to_internal_from_s"] = r.ec.model.time.quasi_static_from;
  r.summary["kinetic_to_internal_limit"] = r.ec.model.time.kinetic_to_internal_limit;
  r.summary["kinetic_to_internal_max"] = r.ke_ie_max;
  r.summary["kinetic_to_internal_end"] =
      s.energy().internal > 0 ? s.energy().kinetic / s.energy().internal : 0.0;
  r.summary["kinetic_to_internal_exceeded"] = r.ke_ie_exceeded;
  for (const auto& m : measures) m->add_summary(s, r.summary);
  add_history_summary(r.ec, history, r.summary);
  r.target_warnings = add_targets(r.ec, r.summary);
  if (!r.failure.empty()) r.summary["error"] = r.failure;
}

// On several ranks a checkpoint is collective (docs/parallel.md "Checkpoints"): every rank
// writes its share, then the root commits checkpoint.h5 only if all did, and says so.
bool all_ranks_wrote(const fem::ExplicitSolver& s, bool wrote) {
  if (!s.domain()) return wrote;
  int all = wrote ? 1 : 0;
  MPI_Allreduce(MPI_IN_PLACE, &all, 1, MPI_INT, MPI_MIN, s.domain()->comm());
  return all != 0;
}
bool root_committed(const fem::ExplicitSolver& s, bool committed) {
  if (!s.domain()) return committed;
  int c = committed ? 1 : 0;
  MPI_Bcast(&c, 1, MPI_INT, 0, s.domain()->comm());
  return c != 0;
}

// checkpoint.h5 at a cycle boundary (the top of the time loop): the whole state, atomically.
// A checkpoint that cannot be written is logged; the run goes on.
void write_checkpoint(Run& r, const fem::ExplicitSolver& s, const MeasureList& measures,
                      const RunHistory& history, const FrameOutput& frames) {
  if (r.checkpoint_cycle == s.cycle()) return;
  const auto t0 = Clock::now();
  const std::filesystem::path file = r.dir / kCheckpointFile;
  std::string failure;
  fem::CheckpointTree t;
  try {
    write_checkpoint_header(t, r.ec, r.options, r.case_hash, s.time(), s.cycle(), r.wall_seconds(),
                            r.segments);
    s.save_state(t);
    {
      fem::CheckpointScope<fem::CheckpointWriter> ms(t, "measures");
      t.write_int("count", static_cast<std::int64_t>(measures.size()));
      for (std::size_t k = 0; k < measures.size(); ++k) {
        fem::CheckpointScope<fem::CheckpointWriter> m(t, fem::checkpoint_index(k));
        measures[k]->save_state(t);
      }
    }
    {
      fem::CheckpointScope<fem::CheckpointWriter> run(t, "run");
      t.write_double("next_history", r.loop.next_history);
      t.write_double("next_frame", r.loop.next_frame);
      t.write_int("exceeded_reported", r.loop.exceeded_reported ? 1 : 0);
      t.write_int("erosions_logged", static_cast<std::int64_t>(r.loop.erosions_logged));
      std::vector<std::int64_t> decades;
      std::vector<double> errors;
      for (const auto& [d, e] : r.max_error_by_decade) decades.push_back(d), errors.push_back(e);
      fem::save_array(t, "max_error_decades", decades);
      fem::save_array(t, "max_error_values", errors);
      t.write_double("ke_ie_max", r.ke_ie_max);
      t.write_int("ke_ie_exceeded", r.ke_ie_exceeded ? 1 : 0);
      history.save_state(t);
      frames.save_state(t);
      t.write_string("summary", r.summary.dump());
    }
  } catch (const std::exception& e) {
    failure = e.what();
  }
  if (!all_ranks_wrote(s, failure.empty()) && failure.empty())
    failure = "another MPI rank could not write its state file (its message is on the console)";
  if (failure.empty()) {
    try {
      fem::io::write_checkpoint_file(file, t);
    } catch (const std::exception& e) {
      failure = e.what();
    }
  }
  root_committed(s, failure.empty());
  if (failure.empty()) {
    r.checkpoint_cycle = s.cycle();
    std::error_code ec;
    const auto bytes = std::filesystem::file_size(file, ec);
    r.log->info("checkpoint at t = {:.6g} s, cycle {} ({:.1f} MB{}, {:.2f} s)", s.time(), s.cycle(),
                ec ? 0.0 : static_cast<double>(bytes) / 1e6,
                s.domain() ? fmt::format(" and a state file from each of the {} other ranks",
                                         s.domain()->size() - 1)
                           : std::string(),
                seconds_since(t0));
  } else {
    r.log->error("checkpoint at t = {:.6g} s not written: {}", s.time(), failure);
  }
  r.last_checkpoint = Clock::now();
}

// A rank other than the root in a checkpoint: its own state (the solver's share and the loop's
// output times) into its state file, kept once the root has committed checkpoint.h5.
struct RankCheckpoints {
  std::filesystem::path dir;
  std::string case_hash;
  std::int64_t cycle = -1;  // of the last checkpoint committed or loaded
};

void write_rank_checkpoint(RankCheckpoints& ck, const fem::ExplicitSolver& s,
                           const Run::LoopState& loop) {
  if (ck.cycle == s.cycle()) return;
  const int rank = s.domain()->rank();
  const std::filesystem::path file = rank_checkpoint_file(ck.dir, rank, s.cycle());
  bool wrote = true;
  try {
    fem::CheckpointTree t;
    write_rank_checkpoint_header(t, ck.case_hash, rank, s.domain()->size(), s.cycle());
    s.save_state(t);
    fem::CheckpointScope<fem::CheckpointWriter> run(t, "run");
    t.write_double("next_history", loop.next_history);
    t.write_double("next_frame", loop.next_frame);
    fem::io::write_checkpoint_file(file, t);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "ncfsim: MPI rank %d: checkpoint state file %s not written: %s\n", rank,
                 file.c_str(), e.what());
    wrote = false;
  }
  all_ranks_wrote(s, wrote);
  std::error_code err;
  if (root_committed(s, false)) {
    ck.cycle = s.cycle();
    remove_rank_checkpoints(ck.dir, rank, ck.cycle);
  } else {
    std::filesystem::remove(file, err);
  }
}

// Overwrites the state of the run just built from the same case with the checkpoint's.
void load_checkpoint(Run& r, fem::CheckpointTree& t, fem::ExplicitSolver& s, MeasureList& measures,
                     RunHistory& history, FrameOutput& frames) {
  const double wall = t.read_double("wall_seconds");
  const std::int64_t segments = t.read_int("segments");
  try {
    s.load_state(t);
    {
      fem::CheckpointScope<fem::CheckpointReader> ms(t, "measures");
      t.check_int("count", static_cast<std::int64_t>(measures.size()));
      for (std::size_t k = 0; k < measures.size(); ++k) {
        fem::CheckpointScope<fem::CheckpointReader> m(t, fem::checkpoint_index(k));
        measures[k]->load_state(t);
      }
    }
    fem::CheckpointScope<fem::CheckpointReader> run(t, "run");
    r.loop.next_history = t.read_double("next_history");
    r.loop.next_frame = t.read_double("next_frame");
    r.loop.exceeded_reported = t.read_int("exceeded_reported") != 0;
    r.loop.erosions_logged = static_cast<std::size_t>(t.read_int("erosions_logged"));
    std::vector<std::int64_t> decades;
    std::vector<double> errors;
    t.read_array("max_error_decades", decades);
    t.read_array("max_error_values", errors, decades.size());
    r.max_error_by_decade.clear();
    for (std::size_t k = 0; k < decades.size(); ++k)
      r.max_error_by_decade[static_cast<int>(decades[k])] = errors[k];
    r.ke_ie_max = t.read_double("ke_ie_max");
    r.ke_ie_exceeded = t.read_int("ke_ie_exceeded") != 0;
    history.load_state(t);
    frames.load_state(t, s);
    // The summary as it stood, under this run's header (version, overrides, options).
    json saved = json::parse(t.read_string("summary"), nullptr, false);
    if (saved.is_object()) {
      const json header = summary_header(r.ec, r.options);
      for (const auto& [key, value] : header.items()) saved[key] = value;
      for (const auto& [key, value] : r.summary.items())
        if (!saved.contains(key)) saved[key] = value;
      r.summary = std::move(saved);
    }
  } catch (const fem::CheckpointMismatch& e) {
    throw InputError((r.dir / kCheckpointFile).string(), "--resume",
                     std::string("does not fit this model: ") + e.what());
  }
  r.wall_before = wall;
  r.segments = segments + 1;
  r.checkpoint_cycle = s.cycle();
  json resumed = r.summary.value("resumed", json::array());
  resumed.push_back({{"time", s.time()}, {"cycle", s.cycle()}});
  r.summary["resumed"] = resumed;
}

// Logs the erosions since the last call; the measures then say what went with them.
void log_erosions(const fem::ExplicitSolver& s, MeasureList& measures, std::size_t& logged,
                  spdlog::logger& log) {
  const auto& tc = s.model().time;
  const std::size_t before = logged;
  for (; logged < s.erosions().size(); ++logged) {
    const auto& ev = s.erosions()[logged];
    const auto& part = s.model().mesh.part_names[static_cast<std::size_t>(ev.part)];
    if (ev.cause == fem::ErosionEvent::Cause::MaterialFailure) {
      // Part of a damage law's progress (thousands in a crush): the log file has them.
      log.debug(
          "hexahedron {} (part {}) eroded at t = {:.6g} s, cycle {}, at ({:.6g}, {:.6g}, {:.6g}) "
          "m: its "
          "material failed",
          ev.element, part, ev.time, ev.cycle, ev.centroid.x, ev.centroid.y, ev.centroid.z);
      continue;
    }
    using Cause = fem::ErosionEvent::Cause;
    const std::string why =
        ev.cause == Cause::InvertedCorner ? "a corner folded over (corner Jacobian <= 0)"
        : ev.cause == Cause::MassCap
            ? fmt::format(
                  "at the cap of dynamic mass scaling ({:g} times its mass added, "
                  "time.mass_scaling_max_ratio) its step {:.3g} s fell below "
                  "time.mass_scaling_dt = {:.3g} s (time.mass_scaling_erode_at_cap)",
                  tc.mass_scaling_max_ratio, ev.step, tc.mass_scaling_dt)
            : fmt::format(
                  "its step {:.3g} s fell below time.erosion_step_ratio = {:g} of the "
                  "initial one",
                  ev.step, tc.erosion_step_ratio);
    log.warn(
        "hexahedron {} (part {}) eroded at t = {:.6g} s, cycle {}, at ({:.6g}, {:.6g}, {:.6g}) m: "
        "{}",
        ev.element, part, ev.time, ev.cycle, ev.centroid.x, ev.centroid.y, ev.centroid.z, why);
  }
  if (logged > before)
    for (auto& m : measures)
      for (const auto& line : m->after_erosion(s)) log.warn("{}", line);
}

// What the top of a cycle asks of every rank at once: stop (Ctrl-C on any rank: a rank that
// stopped alone would leave the others waiting in the next exchange) and a checkpoint (the
// root's wall-time interval has passed). On several ranks the flags travel with the cycle's sums
// (ExplicitSolver::raise_requests: no collective of their own): a rank raises its flags for the
// next cycle (post_requests) and all ranks act on what was raised one cycle later, together.
struct LoopRequests {
  bool stop = false, checkpoint = false;
};
unsigned local_requests(bool checkpoint_due) {
  return (StopRequest::requested() ? 1u : 0u) | (checkpoint_due ? 2u : 0u);
}
LoopRequests pending_requests(const fem::ExplicitSolver& s, bool checkpoint_due) {
  const unsigned flags = s.domain() ? s.requests_all_ranks() : local_requests(checkpoint_due);
  return {(flags & 1u) != 0, (flags & 2u) != 0};
}
// After the requests were handled: this rank's flags go with the next cycle's sums.
void post_requests(fem::ExplicitSolver& s, bool checkpoint_due) {
  if (s.domain()) s.raise_requests(local_requests(checkpoint_due));
}

bool checkpoint_every_cycles_due(const OutputSettings& out, const fem::ExplicitSolver& s) {
  return out.checkpoint_every_cycles > 0 && s.cycle() > 0 &&
         s.cycle() % out.checkpoint_every_cycles == 0;
}

// On several ranks the root gathers the whole state before a history row or a frame; the other
// ranks take part (run_engine_worker) at the same cycles, which they find from the same times.
bool output_due(double t, const Run::LoopState& loop) {
  return t >= loop.next_history || t >= loop.next_frame;
}

// Wall seconds to the end time at the rate of the last quarter of the wall time so far (at least
// the last progress interval): a forming cycle costs more as the contact grows (the paper model's
// 36 ms at the start, 54 ms at full depth), so the rate since the start under-read the time left.
double eta_seconds(const Run& r, double t, double wall, double end_time) {
  auto& p = r.progress;
  p.emplace_back(wall, t);
  std::size_t k = p.size() - 1;
  while (k > 0 && p[k].first > 0.75 * wall) --k;
  const double dw = wall - p[k].first, dt = t - p[k].second;
  if (!(dt > 0 && dw > 0)) return t > 0 ? wall * (end_time - t) / t : -1;
  return (end_time - t) * dw / dt;
}

void log_progress(const Run& r, const fem::ExplicitSolver& s, double err) {
  const auto& tc = s.model().time;
  const double t = s.time(), wall = r.wall_seconds(), frac = t / tc.end_time;
  const double eta = eta_seconds(r, t, wall, tc.end_time);
  r.log->info(
      "t = {:.4e} / {:.4e} s ({:4.1f} %) | cycle {} | dt {:.3e} s | wall {} | ETA {} | energy "
      "balance {:.3f} %",
      t, tc.end_time, 100 * frac, s.cycle(), s.time_step(), hms(wall),
      eta >= 0 ? hms(eta) : "--:--", 100 * err);
}

// The time loop to the end time (or the cycle limit, or an interrupt); returns the exit code.
int time_loop(Run& r, fem::ExplicitSolver& solver, MeasureList& measures, RunHistory& history,
              FrameOutput& frames) {
  const auto& tc = solver.model().time;
  double& next_history = r.loop.next_history;
  double& next_frame = r.loop.next_frame;
  auto last_progress = Clock::now();
  bool& exceeded_reported = r.loop.exceeded_reported;
  std::size_t& erosions_logged = r.loop.erosions_logged;
  const auto& out = r.ec.output;
  r.last_checkpoint = Clock::now();
  try {
    while (solver.time() < tc.end_time * (1 - 1e-12)) {
      if (tc.max_cycles > 0 && solver.cycle() >= tc.max_cycles) {
        r.status = "max_cycles";
        r.log->warn("stopped at the cycle limit time.max_cycles = {}", tc.max_cycles);
        write_checkpoint(r, solver, measures, history, frames);
        break;
      }
      const auto checkpoint_due = [&] {
        return out.checkpoint_interval_min > 0 &&
               seconds_since(r.last_checkpoint) >= 60 * out.checkpoint_interval_min;
      };
      const LoopRequests req = pending_requests(solver, checkpoint_due());
      if (req.stop) {
        r.status = "interrupted";
        r.log->warn(
            "interrupted at t = {:.6g} s, cycle {}: writing a checkpoint, the last frame "
            "and summary",
            solver.time(), solver.cycle());
        write_checkpoint(r, solver, measures, history, frames);
        break;
      }
      if (checkpoint_every_cycles_due(out, solver) || req.checkpoint)
        write_checkpoint(r, solver, measures, history, frames);
      post_requests(solver, checkpoint_due());
      // Only a history row or a frame reads x^n in the callback: in the other cycles the
      // positions move in the solver's velocity pass (one sweep over the nodal arrays).
      const bool reads_x = output_due(solver.time(), r.loop);
      const auto at_tn = [&] {
        const double t = solver.time();
        if (output_due(t, r.loop)) solver.gather_for_output();
        log_erosions(solver, measures, erosions_logged, *r.log);
        const auto& balance = solver.energy();
        const double err = balance.error();
        if (balance.scale_max > fem::kEnergyScaleFloor) {
          double& m =
              r.max_error_by_decade[static_cast<int>(std::floor(std::log10(balance.scale_max)))];
          m = std::max(m, err);
        }
        if (t >= next_history) {
          history.write_row(solver);
          next_history += tc.history_interval;
          const auto& en = solver.energy();
          if (t >= tc.quasi_static_from && en.internal > 0) {
            const double ratio = en.kinetic / en.internal;
            r.ke_ie_max = std::max(r.ke_ie_max, ratio);
            if (tc.kinetic_to_internal_limit > 0 && ratio > tc.kinetic_to_internal_limit &&
                !r.ke_ie_exceeded) {
              r.log->warn(
                  "kinetic / internal energy {:.3g} passed time.kinetic_to_internal_limit {:.3g} "
                  "at t = {:.6g} s: "
                  "not quasi-static (slower tool, less mass scaling)",
                  ratio, tc.kinetic_to_internal_limit, t);
              r.ke_ie_exceeded = true;
            }
          }
          if (!exceeded_reported && err > tc.energy_balance_limit && t > 0.05 * tc.end_time) {
            r.log->warn("energy balance error {:.3g} % passed its limit {:.3g} % at t = {:.6g} s",
                        100 * err, 100 * tc.energy_balance_limit, t);
            exceeded_reported = true;
          }
        }
        if (t >= next_frame) {
          frames.write(solver, measures, *r.log);
          fill_summary(r, solver, measures, history, frames);
          r.summary["status"] = "running";
          r.write_summary();
          next_frame += tc.frame_interval;
        }
        if (std::chrono::duration<double>(Clock::now() - last_progress).count() >=
            r.options.progress_interval_s) {
          last_progress = Clock::now();
          log_progress(r, solver, err);
        }
      };
      solver.step(at_tn, reads_x);
    }
    // Final state (positions at the end time; forces of the last cycle).
    solver.gather_for_output();
    history.write_row(solver);
    frames.write(solver, measures, *r.log);
  } catch (const NumericalError& e) {
    r.status = "numerical_failure";
    r.failure = e.what();
    r.log->error("{}", e.what());
    return kNumericalFailure;
  }
  return kSuccess;
}

void log_end(const Run& r, const fem::ExplicitSolver& solver) {
  const auto& en = solver.energy();
  const auto& tc = solver.model().time;
  r.log->info(
      "energy balance at t = {:.6g} s: kinetic {:.5g} J, internal {:.5g} J (stabilisation {:.5g} "
      "J), "
      "hourglass {:.5g} J, contact {:.5g} J (friction {:.5g} J), damping {:.5g} J, external work "
      "{:.5g} J, eroded kinetic {:.5g} J, error {:.3g} % (limit {:.3g} %)",
      en.time, en.kinetic, en.internal, en.stabilisation, en.hourglass, en.contact, en.friction,
      en.damping, en.external_work, en.eroded_kinetic, 100 * en.error(),
      100 * tc.energy_balance_limit);
  // The kinetic share, stated whether or not the case checks it (a crush is dynamic: it states
  // it; a forming run asks for quasi-static and is warned above when it is not).
  if (tc.quasi_static_from < en.time)
    r.log->info("kinetic / internal energy from t = {:.4g} s: at most {:.3g}, at the end {:.3g}{}",
                tc.quasi_static_from, r.ke_ie_max, en.internal > 0 ? en.kinetic / en.internal : 0.0,
                tc.kinetic_to_internal_limit > 0
                    ? fmt::format(" (limit {:.3g}{})", tc.kinetic_to_internal_limit,
                                  r.ke_ie_exceeded ? ", passed: not quasi-static" : "")
                    : std::string(" (a dynamic run: not checked, time.kinetic_to_internal_limit "
                                  "unset)"));
  if (solver.n_freed_nodes() > 0)
    r.log->info("{} nodes left with no element by erosion were taken out (held, out of contact)",
                solver.n_freed_nodes());
  const auto& tm = solver.timers();
  const double elem_cycles =
      static_cast<double>(solver.cycle()) * static_cast<double>(solver.n_elements());
  r.log->info(
      "{} cycles in {} | internal force {:.3g} s ({:.0f} ns per element-cycle), contact {:.3g} s, "
      "update {:.3g} s, output {:.3g} s",
      solver.cycle(), hms(r.summary["wall_seconds"].get<double>()), tm.internal_force,
      elem_cycles > 0 ? 1e9 * tm.internal_force / elem_cycles : 0.0, tm.contact, tm.update,
      tm.output);
  // The same in CPU time, as bench_engine counts it (docs/performance.md).
  const double loop_ec =
      static_cast<double>(r.loop_cycles) * static_cast<double>(solver.n_elements());
  if (r.loop_wall > 0 && loop_ec > 0) {
    const double share = r.loop_cpu / r.loop_wall;
    r.log->info(
        "time loop {:.3g} s wall, {:.3g} s CPU ({:.0f} % on the CPU): ~{:.0f} ns of CPU per "
        "element-cycle in the internal force, {:.0f} all in",
        r.loop_wall, r.loop_cpu, 100 * share,
        elem_cycles > 0 ? 1e9 * share * tm.internal_force / elem_cycles : 0.0,
        1e9 * r.loop_cpu / loop_ec);
  }
  if (solver.model().time.mass_scaling_dynamic) {
    r.log->info(
        "dynamic mass scaling: mass added in {} cycles (hexahedra below {:.4g} s); {} hexahedra "
        "reached the cap of {:.4g} times their physical mass added (time.mass_scaling_max_ratio), "
        "their step their own from there",
        solver.mass_scaling_events(), solver.model().time.mass_scaling_dt,
        solver.mass_scaling_capped(), solver.model().time.mass_scaling_max_ratio);
    log_part_masses(solver, *r.log);
  }
  if (solver.domain() && solver.contact_halo_builds() > 0)
    r.log->info(
        "contact halo built again {} times as the surfaces moved (parallel.contact_halo_refresh "
        "= {:.3g} of parallel.contact_halo = {:.3g} m)",
        solver.contact_halo_builds(), solver.model().parallel.contact_halo_refresh,
        solver.model().parallel.contact_halo);
  // Each counted contact's cost (bench_contact's figure: docs/performance.md), this rank's.
  const double cpu_share = r.loop_wall > 0 ? r.loop_cpu / r.loop_wall : 1.0;
  // The cycle phase by phase, in the unit of the forming benchmark (bench_forming): ns of CPU
  // per hexahedron-cycle of this rank, and the share of the loop.
  if (const auto n_hex = static_cast<double>(solver.n_elements(fem::ElementKind::Hex8));
      n_hex > 0 && r.loop_cycles > 0 && r.loop_wall > 0) {
    std::string line;
    const double per = 1e9 * cpu_share / (n_hex * static_cast<double>(r.loop_cycles));
    for (const auto& [name, secs] : cycle_phases(solver))
      if (secs > 0)
        line += fmt::format("{}{} {:.1f} ({:.0f} %)", line.empty() ? "" : ", ", name, per * secs,
                            100 * secs / r.loop_wall);
    r.log->info("cycle{} in ns of CPU per hexahedron-cycle (share of the loop): {}",
                solver.domain() ? " (rank 0)" : "", line);
  }
  const auto& contacts = solver.model().contacts;
  for (std::size_t k = 0; k < contacts.size(); ++k) {
    const double nodes = static_cast<double>(contacts[k]->n_contact_nodes());
    const std::int64_t searches = contacts[k]->n_broad_phase_searches();
    // Timers count this process's loop only (a resumed run: since the resume).
    const double cycles = static_cast<double>(r.loop_cycles);
    if (nodes <= 0 || cycles <= 0) continue;
    const double secs = solver.contact_seconds(k);
    r.log->info(
        "contact '{}'{}: {} contact nodes, {} broad-phase searches so far, {:.3g} s in {} cycles: "
        "~{:.0f} ns of CPU per contact node-cycle",
        contacts[k]->name(), solver.domain() ? " (rank 0's share)" : "", nodes, searches, secs,
        r.loop_cycles, 1e9 * cpu_share * secs / (nodes * cycles));
    if (const std::string d = contacts[k]->cost_details(); !d.empty())
      r.log->info("contact '{}': {}", contacts[k]->name(), d);
  }
}

void draw_figures_and_report(const Run& r) {
  if (r.ec.output.figures) {
    try {
      const auto written = render_figures(r.dir, *r.log);
      r.log->info("{} figures in {}", written.size(), (r.dir / "figures").string());
    } catch (const std::exception& e) {
      r.log->warn("figures not drawn: {}", e.what());
    }
  }
  if (r.ec.output.report) {
    try {
      write_report(r.dir);
      r.log->info("report: {}", (r.dir / "report.html").string());
    } catch (const std::exception& e) {
      r.log->warn("report not written: {}", e.what());
    }
  }
}

}  // namespace

int run_engine_worker(EngineCase& ec, const RunOptions& options) {
  RankCheckpoints ck{output_folder(ec, options), checkpoint_case_hash(ec.file, options.overrides)};
  // The root's word before any collective of the model: -1 when it refused the run (the folder
  // in use, a checkpoint refused, a file it could not write; it reports why), else the cycle of
  // the checkpoint to load (--resume; it checked checkpoint.h5 and that every rank's file is
  // there) or 0. Without it the other ranks would wait in the solver's first collective for a
  // root that has ended.
  std::int64_t resume_cycle = -1;
  MPI_Bcast(&resume_cycle, 1, MPI_INT64_T, 0, PETSC_COMM_WORLD);
  if (resume_cycle < 0) return kBadInput;
  std::unique_ptr<fem::ExplicitSolver> solver_ptr;
  try {
    solver_ptr = std::make_unique<fem::ExplicitSolver>(ec.model);
  } catch (const InputError&) {
    return kBadInput;  // the root reports it
  }
  fem::ExplicitSolver& solver = *solver_ptr;
  const auto& tc = solver.model().time;
  const auto& out = ec.output;
  Run::LoopState loop;
  if (options.resume) {
    const int rank = solver.domain()->rank();
    fem::CheckpointTree t =
        read_rank_checkpoint(ck.dir, rank, solver.domain()->size(), resume_cycle, ck.case_hash);
    try {
      solver.load_state(t);
      fem::CheckpointScope<fem::CheckpointReader> run(t, "run");
      loop.next_history = t.read_double("next_history");
      loop.next_frame = t.read_double("next_frame");
    } catch (const fem::CheckpointMismatch& e) {
      throw InputError(rank_checkpoint_file(ck.dir, rank, resume_cycle).string(), "--resume",
                       std::string("does not fit this model: ") + e.what());
    }
    ck.cycle = resume_cycle;
  }
  StopRequest::install();
  bool completed = false;
  try {
    while (true) {
      if (solver.time() >= tc.end_time * (1 - 1e-12)) {
        completed = true;
        break;
      }
      if (tc.max_cycles > 0 && solver.cycle() >= tc.max_cycles) {
        write_rank_checkpoint(ck, solver, loop);
        break;
      }
      const LoopRequests req = pending_requests(solver, false);
      if (req.stop) {
        write_rank_checkpoint(ck, solver, loop);
        break;
      }
      if (checkpoint_every_cycles_due(out, solver) || req.checkpoint)
        write_rank_checkpoint(ck, solver, loop);
      post_requests(solver, false);
      const auto at_tn = [&] {
        const double t = solver.time();
        if (!output_due(t, loop)) return;
        solver.gather_for_output();
        if (t >= loop.next_history) loop.next_history += tc.history_interval;
        if (t >= loop.next_frame) loop.next_frame += tc.frame_interval;
      };
      solver.step(at_tn, output_due(solver.time(), loop));  // x^n read only for output
    }
    solver.gather_for_output();
  } catch (const NumericalError& e) {
    // The root cannot report it (the launcher ends the job when this rank exits): say it here.
    std::fprintf(stderr, "ncfsim: numerical failure on MPI rank %d: %s\n", solver.domain()->rank(),
                 e.what());
    return kNumericalFailure;
  }
  if (completed) remove_rank_checkpoints(ck.dir, solver.domain()->rank(), -1);
  return kSuccess;
}

namespace {

// A run that ends by an exception after it said "running" (a file it cannot write, a disk that
// fills, a numerical failure outside the loop) says so in summary.json: `failed` (or
// `numerical_failure`) with the message as `error`. Best effort: the disk may refuse this too.
void record_failure(Run& r, const std::exception& e) {
  r.status = dynamic_cast<const NumericalError*>(&e) ? "numerical_failure" : "failed";
  r.summary["status"] = r.status;
  r.summary["error"] = e.what();
  try {
    r.log->error("run failed: {}", e.what());
    r.write_summary();
  } catch (...) {
  }
}

// The run from its first cycle to its last file, once the folder is claimed and the model built.
int finish_run(Run& r, fem::ExplicitSolver& solver, MeasureList& measures, RunHistory& history,
               FrameOutput& frames, const OutputFolder& folder) {
  const double cpu0 = thread_cpu_seconds();
  const auto wall_loop0 = Clock::now();
  const std::int64_t cycle0 = solver.cycle();
  int exit_code = time_loop(r, solver, measures, history, frames);
  r.loop_cpu = thread_cpu_seconds() - cpu0;
  r.loop_wall = seconds_since(wall_loop0);
  r.loop_cycles = solver.cycle() - cycle0;
  const bool stopped = r.status == "interrupted" || r.status == "max_cycles";
  frames.close();
  history.finish();

  const auto& tc = solver.model().time;
  const double err = solver.energy().error();
  if (exit_code == kSuccess && err > tc.energy_balance_limit) {
    r.status = "energy_balance_exceeded";
    r.failure = fmt::format(
        "energy balance error {:.3g} % is past its limit {:.3g} % (time.energy_balance_limit)",
        100 * err, 100 * tc.energy_balance_limit);
    r.log->error("{}", r.failure);
    exit_code = kNumericalFailure;
  }
  if (exit_code == kSuccess && (r.status == "interrupted" || r.status == "max_cycles"))
    exit_code = kOtherError;  // docs/cli.md: results valid, the run did not reach its end
  fill_summary(r, solver, measures, history, frames);
  r.write_summary();
  for (const auto& line : r.target_warnings) r.log->warn("{}", line);
  for (const auto& m : measures)
    for (const auto& f : m->write_files(solver, r.dir))
      r.log->info("wrote {}", (r.dir / f).string());
  log_end(r, solver);
  if (!StopRequest::requested()) {
    draw_figures_and_report(r);
    // The figures are drawn in this process: its peak counts them.
    r.summary["peak_memory_MB"] = fem::peak_resident_mb();
    r.write_summary();
  }
  if (StopRequest::requested() && r.status == "completed") {
    // Ctrl-C after the last cycle: the results are complete, the figures are not all drawn.
    r.status = "interrupted";
    r.summary["status"] = r.status;
    r.summary["figures_complete"] = false;
    r.write_summary();
    r.log->warn(
        "interrupted after the last cycle: results complete, figures and report not all "
        "drawn (ncfsim render {} draws them)",
        r.dir.string());
    if (exit_code == kSuccess) exit_code = kOtherError;
  }
  const std::filesystem::path ck = r.dir / kCheckpointFile;
  std::error_code ec_exists;
  if (stopped && std::filesystem::exists(ck, ec_exists)) {
    r.log->warn("checkpoint kept ({}): ncfsim run {} -o {}{}{} --resume continues the run",
                ck.string(), r.ec.file.string(), r.dir.string(),
                fem::PetscSession::size() > 1 ? fmt::format(" --np {}", fem::PetscSession::size())
                                              : std::string(),
                [&] {
                  std::string s;
                  for (const auto& ov : r.options.overrides)
                    if (ov.rfind("time.max_cycles=", 0) != 0) s += " --set " + ov;
                  return s;
                }());
  } else if (!stopped && r.status != "numerical_failure") {
    std::error_code ec_rm;
    std::filesystem::remove(ck, ec_rm);  // large, and nothing to resume
  }
  r.log->info("results in {} (status: {})", r.dir.string(), r.status);
  folder.finish();
  return exit_code;
}

}  // namespace

std::filesystem::path output_folder(const std::string& case_name, const RunOptions& o) {
  return o.out_dir.empty() ? std::filesystem::path("results") / case_name : o.out_dir;
}

int run_engine_case(EngineCase& ec, const RunOptions& options) {
  Run r(ec, options);
  r.case_hash = checkpoint_case_hash(ec.file, options.overrides);
  // --resume: the checkpoint is checked (version, case) before anything is written. The other
  // ranks wait for the root's word (run_engine_worker): the cycle to load (0 without --resume),
  // or -1 when the root refuses the run here, whatever the reason.
  fem::CheckpointTree checkpoint;
  std::optional<OutputFolder> folder;
  std::int64_t cycle = 0;
  const fem::MemoryEstimate memory =
      fem::estimate_memory(ec.model, fem::PetscSession::size(), ec.output.memory());
  try {
    // A model too large for the machine is bad input, refused before anything is written.
    fem::require_memory_fits(memory, ec.file.string());
    if (options.resume && options.overwrite)
      throw InputError(ec.file.string(), "--resume",
                       "continues a run in its own folder: --overwrite does not go with it");
    if (options.resume) {
      checkpoint = read_run_checkpoint(r.dir, ec, r.case_hash);
      cycle = checkpoint.read_int("cycle");
    }
    folder.emplace(options.resume ? OutputFolder::resume(r.dir)
                                  : OutputFolder::claim(r.dir, options.overwrite));
    r.log = make_run_logger(r.dir, options.verbosity, options.resume);
    if (!options.resume) {
      std::filesystem::copy_file(ec.file, r.dir / "case.toml",
                                 std::filesystem::copy_options::overwrite_existing);
      write_figure_specs(r.dir, ec);
    }
  } catch (...) {
    std::int64_t refused = -1;
    if (fem::PetscSession::size() > 1) MPI_Bcast(&refused, 1, MPI_INT64_T, 0, PETSC_COMM_WORLD);
    throw;
  }
  if (fem::PetscSession::size() > 1) MPI_Bcast(&cycle, 1, MPI_INT64_T, 0, PETSC_COMM_WORLD);
  log_start(r);
  if (!folder->note().empty()) r.log->warn("{}", folder->note());

  const auto solver_ptr = make_solver(ec, r);
  fem::ExplicitSolver& solver = *solver_ptr;
  describe_model(solver, *r.log, r.summary);
  r.log->info("memory: {:.0f} MB resident after the set-up; estimated {}", fem::resident_mb(),
              memory.describe());
  r.summary["memory_estimate_MB"] = memory.per_rank() / 1e6;
  MeasureList measures = make_run_measures(ec, solver);
  for (const auto& m : measures) {
    for (const auto& line : m->setup_lines()) r.log->info("{}", line);
    for (const auto& line : m->setup_warnings()) r.log->warn("{}", line);
  }
  RunHistory history(r.dir / "history.csv", measures, !ec.samples.empty() || !ec.means.empty());
  FrameOutput frames(r.dir, ec.output, solver, options.resume);
  if (options.resume) {
    load_checkpoint(r, checkpoint, solver, measures, history, frames);
    r.log->info("resumed from {} at t = {:.6g} s, cycle {} (segment {})",
                (r.dir / kCheckpointFile).string(), solver.time(), solver.cycle(), r.segments);
  }

  StopRequest::install();
  r.summary["status"] = "running";
  r.write_summary();
  try {
    return finish_run(r, solver, measures, history, frames, *folder);
  } catch (const std::exception& e) {
    record_failure(r, e);
    throw;
  }
}

}  // namespace ncfsim::workflow
