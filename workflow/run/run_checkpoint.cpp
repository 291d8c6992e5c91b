#include "workflow/run/run_checkpoint.hpp"

#include <sstream>

#include "fem/case/toml_reader.hpp"
#include "fem/errors.hpp"
#include "fem/io/hdf5_checkpoint.hpp"
#include "fem/petsc_vector.hpp"
#include "workflow/case/case_hash.hpp"
#include "workflow/output/output_files.hpp"
#include "workflow/run/engine_run.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

namespace fs = std::filesystem;

namespace {
constexpr const char* kFormat = "ncfsim-checkpoint";
constexpr std::int64_t kFormatVersion = 2;  // 2: mpi_ranks, rank state files

std::string join(const std::vector<std::string>& v, const char* sep) {
  std::string s;
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? sep : "") + v[i];
  return s;
}
}  // namespace

std::string checkpoint_case_hash(const fs::path& case_file,
                                 const std::vector<std::string>& overrides) {
  const fem::CaseDocument doc = fem::CaseDocument::load(case_file, overrides);
  Md5 md5;
  md5.add(kVersion);
  md5.add(hashed_case_text(doc.root()));
  std::vector<std::pair<std::string, std::string>> strings;
  string_values(doc.root(), "", strings);
  const fs::path dir = case_file.parent_path();
  for (const auto& [key, value] : strings) {
    if (value.empty() || value.size() > 4096) continue;
    std::error_code ec;
    const fs::path f = fs::path(value).is_absolute() ? fs::path(value) : dir / value;
    if (!fs::is_regular_file(f, ec)) continue;
    md5.add(key);
    if (!md5.add_file(f)) md5.add("");
  }
  return md5.hex();
}

void write_checkpoint_header(fem::CheckpointWriter& w, const EngineCase& ec,
                             const RunOptions& options, const std::string& case_hash, double time,
                             std::int64_t cycle, double wall_seconds, std::int64_t segments) {
  w.write_string("format", kFormat);
  w.write_int("format_version", kFormatVersion);
  w.write_string("ncfsim_version", kVersion);
  w.write_string("case_name", ec.name);
  w.write_string("case_file", ec.file.string());
  w.write_string("case_hash", case_hash);
  w.write_string("inputs_hash", options.inputs_hash);
  w.write_string("overrides", join(options.overrides, "\n"));
  w.write_double("time", time);
  w.write_int("cycle", cycle);
  w.write_double("wall_seconds", wall_seconds);
  w.write_int("segments", segments);
  w.write_int("mpi_ranks", fem::PetscSession::size());
}

fem::CheckpointTree read_run_checkpoint(const fs::path& dir, const EngineCase& ec,
                                        const std::string& case_hash) {
  const fs::path file = dir / kCheckpointFile;
  std::error_code err;
  if (!fs::is_regular_file(file, err))
    throw InputError(dir.string(), "--resume",
                     "holds no " + std::string(kCheckpointFile) +
                         " (the run completed, or stopped before its first checkpoint): run "
                         "without --resume");
  fem::CheckpointTree t;
  try {
    t = fem::io::read_checkpoint_file(file);
  } catch (const fem::CheckpointMismatch& e) {
    throw InputError(file.string(), "--resume", std::string("cannot be read: ") + e.what());
  }
  t.set_reading(true);
  try {
    if (t.read_string("format") != kFormat || t.read_int("format_version") != kFormatVersion)
      throw InputError(file.string(), "--resume", "is not an ncfsim checkpoint of this format");
    const std::string version = t.read_string("ncfsim_version");
    if (version != kVersion)
      throw InputError(file.string(), "--resume",
                       "is a checkpoint of ncfsim " + version + ", this is ncfsim " +
                           std::string(kVersion) +
                           ": a run cannot be resumed by another version; run without --resume");
    if (t.read_string("case_hash") != case_hash) {
      std::string ov;
      for (char c : t.read_string("overrides"))
        ov += c == '\n' ? std::string(" --set ") : std::string(1, c);
      throw InputError(file.string(), "--resume",
                       "is a checkpoint of case '" + t.read_string("case_name") + "' (" +
                           t.read_string("case_file") +
                           (ov.empty() ? std::string(", no --set") : ", --set " + ov) +
                           "), not of this case '" + ec.name +
                           "' with these overrides (a key other than time.max_cycles and "
                           "output.checkpoint_* differs, or a file it reads changed); run "
                           "without --resume");
    }
    const auto ranks = t.read_int("mpi_ranks");
    const int here = fem::PetscSession::size();
    if (ranks != here)
      throw InputError(file.string(), "--resume",
                       "was written on " + std::to_string(ranks) + " MPI rank" +
                           (ranks == 1 ? "" : "s") + ", this run has " + std::to_string(here) +
                           ": resume it with --np " + std::to_string(ranks) +
                           " (each rank reloads its own share of the state)");
    const std::int64_t cycle = t.read_int("cycle");
    for (int k = 1; k < here; ++k) {
      const fs::path rf = rank_checkpoint_file(dir, k, cycle);
      if (!fs::is_regular_file(rf, err))
        throw InputError(file.string(), "--resume",
                         "names cycle " + std::to_string(cycle) + " but rank " + std::to_string(k) +
                             "'s state file " + rf.filename().string() +
                             " is missing: the checkpoint cannot be resumed");
    }
  } catch (const fem::CheckpointMismatch& e) {
    throw InputError(file.string(), "--resume",
                     std::string("is not a run checkpoint: ") + e.what());
  }
  return t;
}

fs::path rank_checkpoint_file(const fs::path& dir, int rank, std::int64_t cycle) {
  return dir /
         ("checkpoint.rank" + std::to_string(rank) + ".cycle" + std::to_string(cycle) + ".h5");
}

void remove_rank_checkpoints(const fs::path& dir, int rank, std::int64_t keep_cycle) {
  const std::string prefix = "checkpoint.rank" + std::to_string(rank) + ".cycle";
  const std::string keep =
      keep_cycle >= 0 ? rank_checkpoint_file(dir, rank, keep_cycle).filename().string() : "";
  std::error_code err;
  std::vector<fs::path> gone;
  for (const auto& e : fs::directory_iterator(dir, err)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) == 0 && name != keep) gone.push_back(e.path());
  }
  for (const auto& p : gone) fs::remove(p, err);
}

void write_rank_checkpoint_header(fem::CheckpointWriter& w, const std::string& case_hash, int rank,
                                  int ranks, std::int64_t cycle) {
  w.write_string("format", kFormat);
  w.write_int("format_version", kFormatVersion);
  w.write_string("ncfsim_version", kVersion);
  w.write_string("case_hash", case_hash);
  w.write_int("mpi_rank", rank);
  w.write_int("mpi_ranks", ranks);
  w.write_int("cycle", cycle);
}

fem::CheckpointTree read_rank_checkpoint(const fs::path& dir, int rank, int ranks,
                                         std::int64_t cycle, const std::string& case_hash) {
  const fs::path file = rank_checkpoint_file(dir, rank, cycle);
  fem::CheckpointTree t;
  try {
    t = fem::io::read_checkpoint_file(file);
    t.set_reading(true);
    if (t.read_string("format") != kFormat || t.read_int("format_version") != kFormatVersion ||
        t.read_string("ncfsim_version") != kVersion || t.read_string("case_hash") != case_hash ||
        t.read_int("mpi_rank") != rank || t.read_int("mpi_ranks") != ranks ||
        t.read_int("cycle") != cycle)
      throw InputError(file.string(), "--resume",
                       "is not rank " + std::to_string(rank) +
                           "'s state of this checkpoint (another "
                           "version, case, rank count or cycle)");
  } catch (const fem::CheckpointMismatch& e) {
    throw InputError(file.string(), "--resume", std::string("cannot be read: ") + e.what());
  }
  return t;
}

}  // namespace ncfsim::workflow
