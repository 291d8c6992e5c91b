#pragma once
// `[case] kind` -> the stage that runs it (stages(): engine, crush, kinematic_drape, transfer,
// workflow; docs/architecture.md). A stage reads its own case file (its module's reader), runs
// into the output folder and returns the exit code of the command line; it hands the next stage
// its results.h5 (fem/io/stage_handoff.hpp). What else the program must know of a kind (time
// loop or not, ranks, its headline figures) is in its Stage record, not in the code that uses it.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "workflow/run/engine_run.hpp"

namespace ncfsim::workflow {

/// What `ncfsim run` passes a stage.
struct StageCall {
  std::filesystem::path case_file;
  std::vector<std::string> overrides;  // --set items
  RunOptions options;
};

/// A figure of a stage's folder that a workflow's report puts first (figures/<png>).
struct HeadlineFigure {
  std::string png, caption;  // the caption follows the stage's name
};

/// Everything the rest of the program needs to know of a stage kind, in one record: adding a kind
/// is its files (reader, run, check) and one entry in stages().
struct Stage {
  std::string kind;         // the [case] kind value
  std::string description;  // one line, for messages and --help
  /// Reads the case, runs it; returns the exit code (ExitCode). Bad input throws InputError.
  int (*run)(const StageCall& call) = nullptr;
  /// `ncfsim check`: reads and checks the case (and what only the built model shows), prints one
  /// line, returns the exit code. Bad input throws InputError.
  int (*check)(const StageCall& call) = nullptr;
  /// A time-loop run: keeps checkpoints (--resume) and is split over MPI ranks (--np, a
  /// workflow stage's `ranks`); the other kinds are short and run on one rank.
  bool time_loop = false;
  /// Runs other stages into folders of its own (a workflow): on one rank, passing --np and
  /// --resume on to them; never itself a stage of a workflow.
  bool holds_stages = false;
  /// What a workflow's report shows first of a stage of this kind.
  std::vector<HeadlineFigure> headline;
  /// The ring_shear.csv column a workflow's ring plot reads for this kind, and the label after
  /// the stage's name ("": the meso column shear_deg, or macro_shear_deg where a macro drape
  /// wrote it).
  std::string ring_column, ring_label;
  /// The file of its folder a downstream stage's input key receives (a workflow's `inputs`).
  std::string handoff = "results.h5";
};

/// The registered stages, in the order they are listed in messages.
const std::vector<Stage>& stages();

/// The stage of `kind`; throws InputError(file, "case.kind") listing the allowed kinds.
const Stage& find_stage(const std::string& kind, const std::filesystem::path& file = {});
/// The stage of `kind`, or nullptr (a summary's `stage` value read back, say).
const Stage* stage_of_kind(const std::string& kind);

/// `[case] kind` of a case file after the overrides ("engine" when absent). Throws InputError for
/// a file that does not parse or a kind that is not a string.
std::string case_kind(const std::filesystem::path& file, const std::vector<std::string>& overrides);
/// The output folder of `ncfsim run file -o out_dir`: out_dir, or results/<the case's name> (the
/// folder the run itself chooses; empty where the case names none).
std::filesystem::path run_output_folder(const std::filesystem::path& file,
                                        const std::vector<std::string>& overrides,
                                        const std::string& out_dir);

/// Looks the case's kind up and runs its stage.
int run_stage(const StageCall& call);
/// Looks the case's kind up and checks it (`ncfsim check`).
int check_stage(const StageCall& call);

/// The keys every stage's summary.json starts with: case, case_file, stage, ncfsim_version,
/// overrides, status ("completed").
nlohmann::json stage_summary_header(const std::string& case_name, const StageCall& call,
                                    const std::string& stage);

/// For commands that run on one MPI rank only (checks, calibrations, workflows: only `run` of
/// engine and crush cases is split over ranks, docs/parallel.md): started by mpirun on more,
/// every rank would do the whole work and write the same files. Returns the exit code (0: one
/// rank); rank 0 says why. Needs an active PetscSession.
int refuse_many_ranks();
/// Whether an MPI launcher started this process (its environment), on any number of ranks.
bool started_by_mpi_launcher();
/// The number of ranks the MPI launcher started (its environment; 1 outside a launcher).
int launcher_world_size();

}  // namespace ncfsim::workflow
