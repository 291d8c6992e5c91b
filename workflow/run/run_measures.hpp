#pragma once
// The measures of a run (fem/run_measure.hpp), made from the case in the order of their
// history.csv columns (docs/output.md): energies, tools, reactions, picture frames, probes, shear
// probes, bending-length probes, Eq. 2, contact resultants; the fabric report. The generic ones
// are here; the fabric tests' come from drape/probes.
#include <memory>
#include <string>
#include <vector>

#include "fem/run_measure.hpp"
#include "workflow/case/engine_case.hpp"

namespace ncfsim::workflow {

using MeasureList = std::vector<std::unique_ptr<fem::RunMeasure>>;

/// Builds the case's measures for the solver (which must outlive them). Bad input (a shear probe
/// box without elements) throws InputError.
MeasureList make_run_measures(const EngineCase& ec, const fem::ExplicitSolver& s);

/// The summary-sample key suffix of a sample point: "_at_<at><unit>" (e.g. "_at_10mm").
std::string sample_suffix(double at, const std::string& unit);

}  // namespace ncfsim::workflow
