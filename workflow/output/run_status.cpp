#include "workflow/output/run_status.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include "fem/case/stage_kinds.hpp"
#include "fem/errors.hpp"
#include "workflow/output/folder_lock.hpp"
#include "workflow/output/output_files.hpp"

namespace ncfsim::workflow {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string number_of(const json& s, const char* key) {
  return s.contains(key) && s[key].is_number() ? fmt::format("{:.4g}", s[key].get<double>())
                                               : std::string("?");
}

enum class Rewrite { written, not_running, started };

// A summary that says running while nobody holds the folder: rewritten with `status` and
// `error` under the folder's lock, so that a run starting now does not see a half-changed
// folder.
Rewrite rewrite_unfinished(const fs::path& dir, const std::string& status,
                           const std::string& error) {
  std::unique_ptr<FolderLock> lock;
  try {
    lock = FolderLock::acquire(dir, "status");
  } catch (const InputError&) {
    return Rewrite::started;
  }
  json s = read_json_file(dir / "summary.json");
  if (!s.is_object() || s.value("status", "") != "running") return Rewrite::not_running;
  s["status"] = status;
  s["error"] = error;
  write_file_atomically(dir / "summary.json", s.dump(2) + "\n");
  return Rewrite::written;
}

FolderStatus status_of(const fs::path& dir) {
  FolderStatus f;
  f.dir = dir;
  json s = read_json_file(dir / "summary.json");
  if (!s.is_object())
    throw InputError((dir / "summary.json").string(), "",
                     "missing or unreadable: not the output folder of a run (or a run that "
                     "ended before it wrote anything)");
  f.stage = s.value("stage", fem::stage_kind::kEngine);
  f.status = s.value("status", "?");
  std::string where;
  if (s.contains("cycles")) where += ", cycle " + s["cycles"].dump();
  if (s.contains("time_reached_s"))
    where += ", t = " + number_of(s, "time_reached_s") + " of " + number_of(s, "end_time_s") + " s";
  if (f.status == "running") {
    if (FolderLock::held(dir)) {
      const json h = FolderLock::last_holder(dir);
      f.line = fmt::format("running{} (process {} on {}, since {})", where,
                           h.is_object() ? h.value("pid", -1L) : -1L,
                           h.is_object() ? h.value("host", "?") : "?",
                           h.is_object() ? h.value("since", "?") : "?");
      return f;
    }
    const Rewrite r = rewrite_unfinished(
        dir, "killed",
        "the run ended without writing its status: its process was killed, or an MPI rank "
        "was lost (found by ncfsim status: summary.json said running, no process held the "
        "folder)");
    if (r == Rewrite::started) {  // a run started meanwhile: it is running after all
      f.line = "running (a run started just now)";
      return f;
    }
    if (r == Rewrite::written) f.status = "killed", f.rewritten = true;
    s = read_json_file(dir / "summary.json");
  }
  f.line = f.status + where;
  if (f.rewritten)
    f.line +=
        ": summary.json said running but no process holds the folder (killed, or an MPI "
        "rank lost); summary.json now says killed";
  else if (s.contains("error") && s["error"].is_string())
    f.line += ": " + s["error"].get<std::string>();
  if (f.status != "completed" && fs::exists(dir / "checkpoint.h5"))
    f.line += "; checkpoint.h5 kept: the same `ncfsim run` with --resume continues it";
  return f;
}

}  // namespace

std::vector<FolderStatus> folder_status(const fs::path& dir) {
  std::vector<FolderStatus> all{status_of(dir)};
  if (all.front().stage != fem::stage_kind::kWorkflow) return all;
  // The stage folders (a workflow killed early has not listed them in its summary yet).
  std::vector<fs::path> stages;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(dir, ec))
    if (e.is_directory() && fs::exists(e.path() / "summary.json")) stages.push_back(e.path());
  std::sort(stages.begin(), stages.end());
  for (const auto& p : stages) all.push_back(status_of(p));
  return all;
}

bool record_lost_rank(const fs::path& dir, const std::string& lost_rank, int launcher_exit,
                      int ranks) {
  // Only a job that lost a rank, or whose launcher was killed: a run that ended by itself
  // (refused, bad input, a numerical failure) wrote its own status, and a summary that said
  // running before it started is an older run's, for ncfsim status to find killed.
  if (lost_rank.empty() && launcher_exit < 128) return false;
  const json s = read_json_file(dir / "summary.json");
  if (!s.is_object() || s.value("status", "") != "running") return false;
  // The ranks the launcher ended may hold the folder a moment longer.
  for (int i = 0; i < 100 && FolderLock::held(dir); ++i)
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  if (FolderLock::held(dir)) return false;
  const std::string error =
      lost_rank.empty()
          ? fmt::format(
                "the run ended without writing its status: its MPI launcher exited with "
                "{} ({} ranks; the launcher reported no rank lost)",
                launcher_exit, ranks)
          : fmt::format(
                "MPI {} of {} was lost: the launcher ended the other ranks (exit {}) "
                "before the run could write its status",
                lost_rank, ranks, launcher_exit);
  return rewrite_unfinished(dir, "failed", error) == Rewrite::written;
}

}  // namespace ncfsim::workflow
