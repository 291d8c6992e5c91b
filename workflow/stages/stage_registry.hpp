#pragma once
// `[case] kind` -> the stage that runs it. Today one stage, "engine" (any explicit model:
// virtual tests, forming, crush); kinematic_drape, transfer, crush and workflow register here as
// their issues land (docs/architecture.md). A stage reads its own case file (its module's
// reader), runs into the output folder and returns the exit code of the command line; it hands the
// next stage its results.h5 (fem/io/stage_handoff.hpp).
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

struct Stage {
  std::string kind;         // the [case] kind value
  std::string description;  // one line, for messages and --help
  /// Reads the case, runs it; returns the exit code (ExitCode). Bad input throws InputError.
  int (*run)(const StageCall& call) = nullptr;
  /// `ncfsim check`: reads and checks the case (and what only the built model shows), prints one
  /// line, returns the exit code. Bad input throws InputError.
  int (*check)(const StageCall& call) = nullptr;
};

/// The registered stages, in the order they are listed in messages.
const std::vector<Stage>& stages();

/// The stage of `kind`; throws InputError(file, "case.kind") listing the allowed kinds.
const Stage& find_stage(const std::string& kind, const std::filesystem::path& file = {});

/// `[case] kind` of a case file after the overrides ("engine" when absent). Throws InputError for
/// a file that does not parse or a kind that is not a string.
std::string case_kind(const std::filesystem::path& file, const std::vector<std::string>& overrides);

/// Whether a stage kind is a time-loop run (engine, crush): the kinds that keep checkpoints and
/// are split over MPI ranks; the others are short and run on one rank.
bool is_time_loop_kind(const std::string& kind);

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
