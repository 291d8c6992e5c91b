#pragma once
// summary.json of a run (docs/output.md): the header, the model, the state at a frame and at the
// end (energies, erosion, timers), and the summary samples and means over the history rows. The
// measures add their own entries (fem/run_measure.hpp).
#include <spdlog/logger.h>

#include <nlohmann/json.hpp>

#include "fem/solver.hpp"
#include "workflow/case/engine_case.hpp"
#include "workflow/run/run_history.hpp"

namespace ncfsim::workflow {

struct RunOptions;

/// case, stage, ncfsim_version, case_file, overrides, resolution, status = "starting".
nlohmann::json summary_header(const EngineCase& ec, const RunOptions& options);

/// Logs the model (mesh, stable step, part masses, end time) and writes elements, nodes, parts,
/// end_time_s, time_step_initial_s, energy_balance_limit.
void describe_model(const fem::ExplicitSolver& s, spdlog::logger& log, nlohmann::json& summary);

/// "N hexahedra, M bars" over every element kind (for the log and `ncfsim check`).
std::string element_counts(const fem::ExplicitSolver& s);

/// One log line per part: its physical mass and the mass added by mass scaling so far.
void log_part_masses(const fem::ExplicitSolver& s, spdlog::logger& log);

/// Where this rank's time loop went, phase by phase (wall seconds, in cycle order): each element
/// kind's internal forces, clearing the force arrays with the erosion checks and the step, each
/// rigid tool, each contact (stitch joints among them), other contact forces (rigs' walls), the
/// node update with the sums, and on several ranks the exchange. The phases add up to the loop less
/// the output.
std::vector<std::pair<std::string, double>> cycle_phases(const fem::ExplicitSolver& s);

/// cycles, time reached, steps, the energy balance and its terms, hourglass ratio, erosion, timers.
void add_state_summary(const fem::ExplicitSolver& s, double energy_balance_error_max,
                       nlohmann::json& summary);

/// The case's [[output.mean]] and [[output.sample]] values over the kept history rows (null where
/// they cannot be measured).
void add_history_summary(const EngineCase& ec, const RunHistory& history, nlohmann::json& summary);

/// The case's [[output.target]] entries against the summary's numbers (so after every other
/// entry): summary `targets` (quantity, value, target, target_quantity, tolerance,
/// relative_tolerance, source, met: true / false / null where no tolerance is given or a number
/// is missing) and `targets_met` (false where any checked target is missed). Returns one line
/// per target missed or not measured, for the log's warnings.
std::vector<std::string> add_targets(const EngineCase& ec, nlohmann::json& summary);

}  // namespace ncfsim::workflow
