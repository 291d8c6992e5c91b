#pragma once
// Stage "kinematic_drape": the pin-jointed net drape of drape/kinematic_drape.hpp with the ring
// shear measure, from a case of its own (drape/case/kinematic_case.hpp).
#include "workflow/stages/stage_registry.hpp"

namespace ncfsim::workflow {

int run_kinematic_drape_stage(const StageCall& call);

}  // namespace ncfsim::workflow
