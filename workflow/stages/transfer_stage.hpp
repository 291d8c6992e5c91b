#pragma once
// The transfer stage (`[case] kind = "transfer"`, issue #20): a drape result's frame becomes the
// impregnated composite model of the formed part (transfer/transfer_model.hpp), written as a run
// folder the crush reads (results.h5/xdmf with the model's element fields, materials.csv,
// ties.csv, vf_histogram.csv, summary.json, figures). docs/output.md, "Transfer".
#include "workflow/stages/stage_registry.hpp"

namespace ncfsim::workflow {

int run_transfer_stage(const StageCall& call);
int check_transfer_stage(const StageCall& call);

}  // namespace ncfsim::workflow
