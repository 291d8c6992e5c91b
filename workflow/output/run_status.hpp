#pragma once
// The true status of an output folder (`ncfsim status FOLDER`, issue #45): what its summary.json
// says, except that a run or workflow whose summary still says "running" while no process holds
// the folder's lock (FolderLock) did not end by itself: it was killed, or an MPI rank was lost.
// Such a summary is rewritten as `killed` (under the lock), so that a user, a script or a
// workflow deciding what to rerun reads a status that is true.
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

namespace ncfsim::workflow {

struct FolderStatus {
  std::filesystem::path dir;
  std::string stage;       // summary.json's `stage` (engine, crush, transfer, workflow, ...)
  std::string status;      // the true status
  std::string line;        // one line for the console: the status and what to do about it
  bool rewritten = false;  // summary.json was "running" with no live holder: now "killed"
};

/// The folder's status, and its stages' for a workflow (the workflow's first). InputError when
/// the folder holds no readable summary.json.
std::vector<FolderStatus> folder_status(const std::filesystem::path& dir);

/// After a run on `ranks` MPI ranks whose launcher reported `lost_rank` (lost_rank_of) or was
/// killed (`launcher_exit` >= 128): where the run's summary.json still says running and no
/// process holds the folder (waited for up to 5 s),
/// the run ended without writing its status (a rank was lost, the launcher ended the others):
/// summary.json becomes `failed`, its error naming the rank lost (lost_rank_of's text) or, if
/// none was reported, the launcher's exit. True when it was rewritten.
bool record_lost_rank(const std::filesystem::path& dir, const std::string& lost_rank,
                      int launcher_exit, int ranks);

}  // namespace ncfsim::workflow
