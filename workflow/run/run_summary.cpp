#include "workflow/run/run_summary.hpp"

#include <fmt/format.h>

#include <cmath>
#include <limits>

#include "fem/case/stage_kinds.hpp"
#include "workflow/run/engine_run.hpp"
#include "workflow/run/run_measures.hpp"
#include "workflow/version.hpp"

namespace ncfsim::workflow {

using json = nlohmann::json;

std::string element_counts(const fem::ExplicitSolver& s) {
  std::string out;
  for (const auto k : fem::kElementKinds)
    out +=
        (out.empty() ? "" : ", ") + std::to_string(s.n_elements(k)) + " " + fem::element_plural(k);
  return out;
}

json summary_header(const EngineCase& ec, const RunOptions& options) {
  json summary;
  summary["case"] = ec.name;
  summary["stage"] = ec.kind.empty() ? fem::stage_kind::kEngine : ec.kind;  // engine or crush
  summary["ncfsim_version"] = kVersion;
  summary["case_file"] = ec.file.string();
  summary["overrides"] = options.overrides;
  summary["resolution"] = ec.resolution;
  if (!ec.laws_replaced.empty()) summary["laws_replaced"] = ec.laws_replaced;
  summary["status"] = "starting";
  return summary;
}

namespace {
// A part's entry under summary.json "parts" (its masses as they stand).
json part_mass_entry(const fem::PartMassReport& pm) {
  return {{"mass_kg", pm.mass},
          {"added_mass_kg", pm.added_mass},
          {"added_mass_percent", pm.mass > 0 ? 100.0 * pm.added_mass / pm.mass : 0.0}};
}
}  // namespace

void log_part_masses(const fem::ExplicitSolver& s, spdlog::logger& log) {
  for (const auto& pm : s.part_masses())
    log.info("  part {:<16} mass {:.5g} kg, added by mass scaling {:.5g} kg ({:.3g} %)", pm.part,
             pm.mass, pm.added_mass, pm.mass > 0 ? 100.0 * pm.added_mass / pm.mass : 0.0);
}

void describe_model(const fem::ExplicitSolver& solver, spdlog::logger& log, json& summary) {
  const fem::Model& model = solver.model();
  log.info("mesh: {} nodes, {}, {} parts, {} tools", model.mesh.n_nodes(), element_counts(solver),
           model.mesh.part_names.size(), model.tools.size());
  log.info("memory: {}", solver.huge_pages().describe());
  const auto& st = solver.controlling_element();
  log.info("stable step {:.4g} s (safety factor {}), controlled by {} {}", solver.time_step(),
           model.time.safety_factor, fem::element_noun(st.kind), st.element);
  log_part_masses(solver, log);
  json parts = json::object();
  for (const auto& pm : solver.part_masses()) parts[pm.part] = part_mass_entry(pm);
  for (const auto& t : model.tools)
    if (t.motion.pressure > 0) {
      log.info("tool {}: {:.4g} Pa over the {:.5g} m^2 of blank it covers: {:.5g} N", t.name,
               t.motion.pressure, t.motion.pressed_area, t.motion.force);
      summary[t.name + "_pressed_area_m2"] = t.motion.pressed_area;
      summary[t.name + "_applied_force_N"] = t.motion.force;
    }
  log.info("end time {:.4g} s: about {:.3g} cycles", model.time.end_time,
           model.time.end_time / solver.time_step());
  summary["elements"] = nlohmann::json::object();
  for (const auto k : fem::kElementKinds)
    summary["elements"][fem::element_kind_name(k)] = solver.n_elements(k);
  summary["nodes"] = model.mesh.n_nodes();
  summary["parts"] = parts;
  summary["end_time_s"] = model.time.end_time;
  summary["time_step_initial_s"] = solver.time_step();
  summary["energy_balance_limit"] = model.time.energy_balance_limit;
}

void add_state_summary(const fem::ExplicitSolver& solver, double max_error, json& summary) {
  const auto& en = solver.energy();
  summary["cycles"] = solver.cycle();
  summary["time_reached_s"] = solver.time();
  summary["time_step_final_s"] = solver.time_step();
  summary["energy_balance_error"] = en.error();
  summary["energy_balance_error_max"] = max_error;
  if (solver.model().time.mass_scaling_dynamic) {
    // Mass is only ever added: the share now is also the largest of the run.
    json ratio = json::object();
    for (const auto& pm : solver.part_masses()) {
      ratio[pm.part] = pm.mass > 0 ? pm.added_mass / pm.mass : 0.0;
      if (summary.contains("parts") && summary["parts"].contains(pm.part))
        summary["parts"][pm.part] = part_mass_entry(pm);
    }
    summary["added_mass_ratio"] = ratio;
    summary["mass_scaling_events"] = solver.mass_scaling_events();
    summary["mass_scaling_capped_elements"] = solver.mass_scaling_capped();
  }
  summary["kinetic_energy_J"] = en.kinetic;
  summary["internal_energy_J"] = en.internal;
  summary["stabilisation_energy_J"] = en.stabilisation;
  summary["hourglass_energy_J"] = en.hourglass;
  summary["contact_energy_J"] = en.contact;
  summary["friction_energy_J"] = en.friction;
  summary["damping_energy_J"] = en.damping;
  summary["external_work_J"] = en.external_work;
  summary["hourglass_to_internal_ratio"] =
      en.internal != 0 ? en.hourglass / std::abs(en.internal) : 0.0;
  summary["eroded_elements"] = solver.erosions().size();
  {
    using Cause = fem::ErosionEvent::Cause;
    std::int64_t n[4] = {};
    for (const auto& ev : solver.erosions()) ++n[static_cast<int>(ev.cause)];
    const auto of = [&](Cause c) { return n[static_cast<int>(c)]; };
    summary["eroded_elements_by_cause"] = {{"stable_step", of(Cause::StableStep)},
                                           {"folded_corner", of(Cause::InvertedCorner)},
                                           {"material_failure", of(Cause::MaterialFailure)},
                                           {"mass_cap", of(Cause::MassCap)}};
  }
  summary["eroded_internal_energy_J"] = en.eroded_internal;
  summary["eroded_kinetic_energy_J"] = en.eroded_kinetic;
  summary["freed_nodes"] = solver.n_freed_nodes();
  const auto& tm = solver.timers();
  summary["timers_s"] = {{"internal_force", tm.internal_force},
                         {"contact", tm.contact},
                         {"update", tm.update},
                         {"output", tm.output}};
  auto& phases = summary["timers_s"]["phases"] = nlohmann::json::object();
  for (const auto& [name, secs] : cycle_phases(solver)) phases[name] = secs;
  // Several ranks (docs/parallel.md): each rank's share, so that load imbalance shows.
  const auto& ranks = solver.rank_reports();
  summary["mpi_ranks"] = ranks.empty() ? 1 : ranks.size();
  if (!ranks.empty()) {
    summary["timers_s"]["exchange"] = tm.exchange;
    summary["contact_halo_builds"] = solver.contact_halo_builds();
    auto& per = summary["mpi_per_rank"] = nlohmann::json::array();
    double busiest = 0;
    for (const auto& r : ranks)
      busiest = std::max(busiest, r.timers.internal_force + r.timers.contact + r.timers.update);
    for (const auto& r : ranks) {
      const double busy = r.timers.internal_force + r.timers.contact + r.timers.update;
      per.push_back({{"elements", r.elements},
                     {"owned_nodes", r.owned_nodes},
                     {"ghost_nodes", r.ghost_nodes},
                     {"ghost_bytes_per_cycle", r.ghost_bytes},
                     {"timers_s",
                      {{"internal_force", r.timers.internal_force},
                       {"contact", r.timers.contact},
                       {"update", r.timers.update},
                       {"exchange", r.timers.exchange}}},
                     {"busy_share", busiest > 0 ? busy / busiest : 1.0}});
    }
  }
}

namespace {

// Mean of a column over a time window (or the ratio of two columns' increments over it).
void add_mean(const SummaryMean& sm, const RunHistory& h, json& summary) {
  const int c = h.index(sm.column), cp = h.index(sm.per_column);
  const auto col = [](const std::vector<double>& r, int k) {
    return r[static_cast<std::size_t>(k)];
  };
  double sum = 0;
  std::size_t n = 0;
  const std::vector<double>*first = nullptr, *last = nullptr;
  for (const auto& r : h.rows())
    if (c >= 0 && r[0] >= sm.from_time && r[0] <= sm.to_time) {
      sum += col(r, c), ++n;
      if (!first) first = &r;
      last = &r;
    }
  double value = n ? sm.scale * sum / static_cast<double>(n) : std::nan("");
  if (!sm.per_column.empty()) {  // ratio of increments over the window
    value = std::nan("");
    if (cp >= 0 && first && last && col(*last, cp) != col(*first, cp))
      value = sm.scale * (col(*last, c) - col(*first, c)) / (col(*last, cp) - col(*first, cp));
  }
  summary[sm.name] = fem::json_number(value);
  if ((c < 0 || (!sm.per_column.empty() && cp < 0)) && !h.columns().empty())
    summary[sm.name + "_error"] = "no history column '" + (c < 0 ? sm.column : sm.per_column) + "'";
}

// History columns interpolated at given values of another column.
void add_samples(const SummarySamples& ss, const RunHistory& h, json& summary) {
  const auto& rows = h.rows();
  const int cx = h.index(ss.x);
  for (double at : ss.at) {
    const std::string tag = sample_suffix(at, ss.x_unit);
    const double xv = at / ss.x_display_scale;
    for (const auto& [label, column] : ss.columns) {
      const int cy = h.index(column);
      double val = std::numeric_limits<double>::quiet_NaN();
      for (std::size_t r = 1; cx >= 0 && cy >= 0 && r < rows.size(); ++r) {
        const double x0 = rows[r - 1][static_cast<std::size_t>(cx)],
                     x1 = rows[r][static_cast<std::size_t>(cx)];
        if ((x0 - xv) * (x1 - xv) <= 0 && x1 != x0) {
          const double w = (xv - x0) / (x1 - x0);
          val = (1 - w) * rows[r - 1][static_cast<std::size_t>(cy)] +
                w * rows[r][static_cast<std::size_t>(cy)];
          break;
        }
      }
      summary[label + tag] = fem::json_number(val);
    }
  }
}

}  // namespace

void add_history_summary(const EngineCase& ec, const RunHistory& history, json& summary) {
  for (const auto& sm : ec.means) add_mean(sm, history, summary);
  for (const auto& ss : ec.samples) add_samples(ss, history, summary);
}

std::vector<std::string> add_targets(const EngineCase& ec, json& summary) {
  std::vector<std::string> lines;
  if (ec.targets.empty()) return lines;
  const auto value_of = [&](const std::string& key) {
    return summary.contains(key) && summary[key].is_number() ? summary[key].get<double>()
                                                             : std::nan("");
  };
  json rows = json::array();
  bool all_met = true;
  for (const auto& t : ec.targets) {
    const double v = value_of(t.quantity);
    const double target = t.target_quantity.empty() ? t.target : value_of(t.target_quantity);
    const double allowed = !std::isnan(t.tolerance) ? t.tolerance
                           : !std::isnan(t.relative_tolerance)
                               ? t.relative_tolerance * std::abs(target)
                               : std::nan("");
    json row{{"quantity", t.quantity},
             {"value", fem::json_number(v)},
             {"target", fem::json_number(target)},
             {"source", t.source}};
    if (!t.target_quantity.empty()) row["target_quantity"] = t.target_quantity;
    if (!std::isnan(t.tolerance)) row["tolerance"] = t.tolerance;
    if (!std::isnan(t.relative_tolerance)) row["relative_tolerance"] = t.relative_tolerance;
    const std::string what =
        t.target_quantity.empty() ? fmt::format("{:.4g}", target) : t.target_quantity;
    if (std::isnan(v) || std::isnan(target)) {
      row["met"] = nullptr;
      all_met = all_met && std::isnan(allowed);
      lines.push_back(fmt::format("target {}: not measured ({} is not a number of this run)",
                                  t.quantity, std::isnan(v) ? t.quantity : t.target_quantity));
    } else if (std::isnan(allowed)) {
      row["met"] = nullptr;  // shown beside its target, not checked
    } else {
      const bool met = std::abs(v - target) <= allowed;
      row["met"] = met;
      all_met = all_met && met;
      if (!met)
        lines.push_back(
            fmt::format("target {}: {:.4g} is {:.3g} from its target {} = {:.4g} "
                        "(allowed {:.3g}; {})",
                        t.quantity, v, std::abs(v - target), what, target, allowed,
                        t.source.empty() ? "[[output.target]]" : t.source));
    }
    rows.push_back(row);
  }
  summary["targets"] = rows;
  summary["targets_met"] = all_met;
  return lines;
}

std::vector<std::pair<std::string, double>> cycle_phases(const fem::ExplicitSolver& s) {
  std::vector<std::pair<std::string, double>> out;
  const fem::PhaseTimers tm = s.loop_timers();
  double elements = 0;
  for (int k = 0; k < 3; ++k) {
    const auto kind = static_cast<fem::ElementKind>(k);
    double secs = 0;
    bool any = false;
    for (std::size_t g = 0; g < s.groups().size(); ++g)
      if (s.groups()[g]->kind() == kind) secs += s.group_seconds(g), any = true;
    if (any) out.emplace_back(fem::element_plural(kind), secs);
    elements += secs;
  }
  out.emplace_back("clear_erosion_step", std::max(tm.internal_force - elements, 0.0));
  double counted = 0;
  for (std::size_t k = 0; k < s.model().tools.size(); ++k) {
    out.emplace_back("tool " + s.model().tools[k].name, s.tool_seconds(k));
    counted += s.tool_seconds(k);
  }
  for (std::size_t k = 0; k < s.model().contacts.size(); ++k) {
    out.emplace_back("contact " + s.model().contacts[k]->name(), s.contact_seconds(k));
    counted += s.contact_seconds(k);
  }
  out.emplace_back("other_contact", std::max(tm.contact - counted, 0.0));
  out.emplace_back("update", tm.update);
  if (s.domain()) out.emplace_back("exchange", tm.exchange);
  return out;
}

}  // namespace ncfsim::workflow
