#pragma once
// checkpoint.h5 of an engine run (issue #22, docs/output.md "checkpoint.h5"): what identifies it
// (ncfsim version, the case's hash) and the refusals of `ncfsim run ... --resume`. The state
// itself is written by the solver, the measures and the run (engine_run.cpp).
#include <filesystem>
#include <string>
#include <vector>

#include "fem/checkpoint.hpp"
#include "workflow/case/engine_case.hpp"

namespace ncfsim::workflow {

struct RunOptions;

inline constexpr const char* kCheckpointFile = "checkpoint.h5";

/// MD5 of the ncfsim version, the resolved case (file + overrides) less the keys that do not
/// change the trajectory (time.max_cycles, output.checkpoint_interval,
/// output.checkpoint_every_cycles) and the bytes of the files its string keys name.
std::string checkpoint_case_hash(const std::filesystem::path& case_file,
                                 const std::vector<std::string>& overrides);

/// The root attributes of a checkpoint (format, version, case, hash, where the run stands).
void write_checkpoint_header(fem::CheckpointWriter& w, const EngineCase& ec,
                             const RunOptions& options, const std::string& case_hash, double time,
                             std::int64_t cycle, double wall_seconds, std::int64_t segments);

/// dir/checkpoint.h5, checked against this ncfsim and this case (the hash): ready to read.
/// InputError (exit 2) naming the file: no checkpoint ("run without --resume"), not readable,
/// another ncfsim version, another case or other overrides, written on another number of MPI
/// ranks, or a rank's state file of that checkpoint missing.
fem::CheckpointTree read_run_checkpoint(const std::filesystem::path& dir, const EngineCase& ec,
                                        const std::string& case_hash);

// On several MPI ranks (docs/parallel.md "Checkpoints") every rank saves its own share of the
// state: rank k > 0 into checkpoint.rank<k>.cycle<c>.h5, then the root, once every rank has
// written its file, into checkpoint.h5, which names the cycle. A run killed between the two
// resumes from the previous checkpoint, whose rank files are removed only after the root's.

/// The state file of MPI rank `rank` > 0 for the checkpoint at `cycle`.
std::filesystem::path rank_checkpoint_file(const std::filesystem::path& dir, int rank,
                                           std::int64_t cycle);
/// Removes the state files of `rank` except the one of `keep_cycle` (-1: all of them).
void remove_rank_checkpoints(const std::filesystem::path& dir, int rank, std::int64_t keep_cycle);
/// The root attributes of a rank's state file.
void write_rank_checkpoint_header(fem::CheckpointWriter& w, const std::string& case_hash, int rank,
                                  int ranks, std::int64_t cycle);
/// Rank `rank`'s state file of the checkpoint at `cycle`, checked (version, case, rank, cycle):
/// ready to read. InputError naming the file otherwise.
fem::CheckpointTree read_rank_checkpoint(const std::filesystem::path& dir, int rank, int ranks,
                                         std::int64_t cycle, const std::string& case_hash);

}  // namespace ncfsim::workflow
