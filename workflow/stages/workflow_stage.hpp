#pragma once
// The workflow stage (`[case] kind = "workflow"`, issue #22): runs the stages of a workflow case
// (workflow/stages/workflow_case.hpp) into sub-folders of one output folder, skipping a stage
// whose inputs have not changed since it last completed; writes the workflow's summary.json
// and report.html (every stage's figures, the shear rings of the drapes on one plot, the
// quadrant table, the energy balances, the warnings). docs/output.md, "Workflow".
//
// A stage's inputs hash (MD5, stage_inputs.json in its folder): the ncfsim version, its case as
// resolved (base case, overrides, the inputs' paths), the content of every file its case names,
// and the hashes of its upstream stages; so changing a drape key reruns the drape and the stages
// downstream of it, and nothing else.
#include "workflow/stages/stage_registry.hpp"

namespace ncfsim::workflow {

int run_workflow_stage(const StageCall& call);
int check_workflow_stage(const StageCall& call);

/// Writes dir/report.html of a workflow's output folder from its summary.json and the stages'
/// folders (`ncfsim report` on a workflow folder).
void write_workflow_report(const std::filesystem::path& dir);

}  // namespace ncfsim::workflow
