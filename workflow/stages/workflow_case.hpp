#pragma once
// The workflow case (`[case] kind = "workflow"`, issue #22): a list of stages, each a case file of
// its own (drape, fishnet, transfer, crush, ...), run in the order their inputs ask for, each into
// a sub-folder of the workflow's output folder. docs/case-file.md, "Workflow".
//
//   [[stage]]
//   name = "transfer"
//   case = "transfer_dome.toml"                 # relative to the workflow file
//   inputs = { "source.results" = "drape" }     # this key of its case <- drape/results.h5
//   after = ["fishnet"]                         # optional: order without a file handed over
//   set = ["mesh.resolution=coarse"]            # optional: changes to its case, as --set
//
// Overrides (--set) whose first key names a stage reach that stage only
// (`drape.mesh.resolution=coarse`); any other reaches every stage whose case has the first key's
// table (`mesh.resolution=coarse`).
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

namespace ncfsim::workflow {

struct WorkflowStageSpec {
  std::string name;
  std::filesystem::path case_file;
  /// Case key of this stage -> upstream stage whose results.h5 it reads.
  std::vector<std::pair<std::string, std::string>> inputs;
  std::vector<std::string> after;      // upstream stages (inputs' stages and `after`), unique
  std::vector<std::string> overrides;  // `set`, then --set items routed to this stage (key
                                       // without the stage)
  int ranks = 0;  // `ranks`: MPI ranks of an engine/crush stage (0: the workflow's --np)
};

struct WorkflowCase {
  std::filesystem::path file;
  std::string name, description;
  std::vector<WorkflowStageSpec> stages;  // in run order (every stage after its upstream stages)
};

/// Reads a workflow case and routes the overrides to its stages. Throws InputError (file, key)
/// for a missing stage case, an input or `after` naming no stage, a cycle between stages, two
/// stages of one name, an override that no stage takes.
WorkflowCase load_workflow_case(const std::filesystem::path& file,
                                const std::vector<std::string>& overrides);

}  // namespace ncfsim::workflow
