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
/// another ncfsim version, another case or other overrides.
fem::CheckpointTree read_run_checkpoint(const std::filesystem::path& dir, const EngineCase& ec,
                                        const std::string& case_hash);

}  // namespace ncfsim::workflow
