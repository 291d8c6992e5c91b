// ExplicitSolver: its state into and out of a checkpoint (docs/output.md, "/solver").
#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <sstream>
#include <utility>

#include "fem/boundary/picture_frame_motion.hpp"
#include "fem/checkpoint.hpp"
#include "fem/errors.hpp"
#include "fem/parallel/domain.hpp"
#include "fem/solver.hpp"

namespace ncfsim::fem {

namespace {
constexpr const char* kEnergyNames[] = {
    "time",          "kinetic",         "rotational_kinetic", "internal", "stabilisation",
    "hourglass",     "contact",         "friction",           "damping",  "external_work",
    "initial_total", "eroded_internal", "eroded_kinetic",     "scale_max"};
double* energy_field(EnergyBalance& e, std::size_t k) {
  double* f[] = {
      &e.time,          &e.kinetic,         &e.rotational_kinetic, &e.internal, &e.stabilisation,
      &e.hourglass,     &e.contact,         &e.friction,           &e.damping,  &e.external_work,
      &e.initial_total, &e.eroded_internal, &e.eroded_kinetic,     &e.scale_max};
  return f[k];
}
constexpr std::size_t kEnergyFields = std::size(kEnergyNames);
}  // namespace

void ExplicitSolver::save_state(CheckpointWriter& w) const {
  if (!freeing_.empty() || !eroded_forces_.empty())
    throw std::logic_error("ExplicitSolver::save_state: not at a cycle boundary");
  const std::size_t n = model_.mesh.n_nodes();
  CheckpointScope<CheckpointWriter> solver(w, "solver");
  w.write_int("n_nodes", static_cast<std::int64_t>(n));
  {
    auto X = x.view();
    auto V = v.view();
    w.write_array("x", std::span<const double>(X.data(), 3 * n));
    w.write_array("v", std::span<const double>(V.data(), 3 * n));
    if (model_.time.mass_scaling_dynamic) {  // the masses added during the run
      auto M = mass.view();
      w.write_array("mass", std::span<const double>(M.data(), 3 * n));
      std::vector<double> added;
      for (const auto& pm : part_mass_) added.push_back(pm.added_mass);
      save_array(w, "part_added_mass", added);
      w.write_int("mass_scaling_events", mass_scaling_events_);
      w.write_int("mass_scaling_pause_until", mass_scaling_pause_until_);
      w.write_int("mass_scaling_capped", mass_scaling_capped_);
    }
  }
  w.write_double("t", t_);
  w.write_double("dt", dt_);
  w.write_double("dt_prev", dt_prev_);
  w.write_double("dt_initial", dt_initial_);
  w.write_int("cycle", cycle_);
  w.write_int("contact_halo_builds", halo_builds_);
  if (!halo_x_.empty()) {  // several ranks: the halo's last build, so a resume rebuilds it
    save_array(w, "halo_x", halo_x_);
    save_array(w, "halo_travel",
               std::vector<double>{halo_travel_, halo_checked_d_, halo_travel_checked_});
  }
  w.write_double("step_dt", step_.dt);
  w.write_int("step_element", step_.element);
  w.write_int("step_kind", static_cast<std::int64_t>(step_.kind));
  {
    EnergyBalance e = energy_;
    std::vector<double> a(kEnergyFields);
    for (std::size_t k = 0; k < kEnergyFields; ++k) a[k] = *energy_field(e, k);
    save_array(w, "energy", a);
    const WorkAccumulator* acc[] = {&w_ext_, &w_damp_, &w_contact_nodes_, &w_tools_,
                                    &tool_work_on_nodes_};
    std::vector<double> work;
    for (const auto* a : acc) work.push_back(a->committed), work.push_back(a->pending);
    save_array(w, "work", work);
    const std::vector<double> timers = {timers_.internal_force, timers_.contact, timers_.update,
                                        timers_.output};
    save_array(w, "timers", timers);
  }
  {
    CheckpointScope<CheckpointWriter> er(w, "erosions");
    std::vector<std::int64_t> cause, cycle, element, kind, part;
    std::vector<double> time, step, centroid;
    for (const auto& ev : erosions_) {
      cause.push_back(static_cast<std::int64_t>(ev.cause));
      time.push_back(ev.time);
      cycle.push_back(ev.cycle);
      element.push_back(ev.element);
      kind.push_back(static_cast<std::int64_t>(ev.kind));
      part.push_back(ev.part);
      step.push_back(ev.step);
      centroid.insert(centroid.end(), {ev.centroid.x, ev.centroid.y, ev.centroid.z});
    }
    save_array(w, "cause", cause);
    save_array(w, "time", time);
    save_array(w, "cycle", cycle);
    save_array(w, "element", element);
    save_array(w, "kind", kind);
    save_array(w, "part", part);
    save_array(w, "step", step);
    save_array(w, "centroid", centroid);
  }
  save_array(w, "node_elements", node_elements_);
  save_array(w, "node_freed", node_freed_);
  {
    CheckpointScope<CheckpointWriter> gs(w, "groups");
    w.write_int("count", static_cast<std::int64_t>(groups_.size()));
    for (std::size_t k = 0; k < groups_.size(); ++k) {
      CheckpointScope<CheckpointWriter> g(w, checkpoint_index(k));
      w.write_int("kind", static_cast<std::int64_t>(groups_[k]->kind()));
      w.write_int("part", groups_[k]->part());
      w.write_int("size", static_cast<std::int64_t>(groups_[k]->size()));
      groups_[k]->save_state(w);
    }
  }
  {
    CheckpointScope<CheckpointWriter> ts(w, "tools");
    for (const auto& tool : model_.tools) {
      CheckpointScope<CheckpointWriter> t(w, tool.name);
      save_tool_state(tool, w);
    }
  }
  {
    CheckpointScope<CheckpointWriter> cs(w, "contacts");
    w.write_int("count", static_cast<std::int64_t>(model_.contacts.size()));
    for (std::size_t k = 0; k < model_.contacts.size(); ++k) {
      CheckpointScope<CheckpointWriter> c(w, checkpoint_index(k));
      w.write_string("name", model_.contacts[k]->name());
      model_.contacts[k]->save_state(w);
    }
  }
}

void ExplicitSolver::load_state(CheckpointReader& r) {
  if (cycle_ != 0 || t_ != 0)
    throw std::logic_error("ExplicitSolver::load_state: the solver has already stepped");
  const std::size_t n = model_.mesh.n_nodes();
  // The contact halo was built at the start positions: built again at the saved ones.
  halo_due_ = domain_ && !model_.contacts.empty() && model_.parallel.contact_halo_refresh > 0;
  CheckpointScope<CheckpointReader> solver(r, "solver");
  r.check_int("n_nodes", static_cast<std::int64_t>(n));
  {
    std::vector<double> a;
    auto X = x.view();
    r.read_array("x", a, 3 * n);
    std::copy(a.begin(), a.end(), X.data());
    auto V = v.view();
    r.read_array("v", a, 3 * n);
    std::copy(a.begin(), a.end(), V.data());
    if (r.has("mass")) {  // dynamic mass scaling: the masses as they stood (freed nodes below)
      auto M = mass.view();
      r.read_array("mass", a, 3 * n);
      std::copy(a.begin(), a.end(), M.data());
      for (std::size_t d = 0; d < 3 * n; ++d) inv_mass_[d] = 1.0 / M[d];
      r.read_array("part_added_mass", a, part_mass_.size());
      for (std::size_t p = 0; p < part_mass_.size(); ++p) part_mass_[p].added_mass = a[p];
      mass_scaling_events_ = r.read_int("mass_scaling_events");
      if (r.has("mass_scaling_pause_until")) {
        mass_scaling_pause_until_ = r.read_int("mass_scaling_pause_until");
        mass_scaling_capped_ = r.read_int("mass_scaling_capped");
      }
    }
  }
  if (r.read_double("dt_initial") != dt_initial_)
    r.mismatch("dt_initial",
               "another initial stable step than this model's (another mesh or "
               "material?)");
  t_ = r.read_double("t");
  dt_ = r.read_double("dt");
  dt_prev_ = r.read_double("dt_prev");
  cycle_ = r.read_int("cycle");
  halo_builds_ = r.has("contact_halo_builds") ? r.read_int("contact_halo_builds") : 0;
  halo_x_.clear();  // none saved: built at the saved positions
  if (halo_due_ && r.has("halo_x")) {
    std::vector<double> tr;
    r.read_array("halo_x", halo_x_, 3 * n);
    r.read_array("halo_travel", tr, 3);
    halo_travel_ = tr[0], halo_checked_d_ = tr[1], halo_travel_checked_ = tr[2];
  }
  step_.dt = r.read_double("step_dt");
  step_.element = r.read_int("step_element");
  step_.kind = static_cast<ElementKind>(r.read_int("step_kind"));
  {
    std::vector<double> a;
    r.read_array("energy", a, kEnergyFields);
    for (std::size_t k = 0; k < kEnergyFields; ++k) *energy_field(energy_, k) = a[k];
    WorkAccumulator* acc[] = {&w_ext_, &w_damp_, &w_contact_nodes_, &w_tools_,
                              &tool_work_on_nodes_};
    r.read_array("work", a, 2 * std::size(acc));
    for (std::size_t k = 0; k < std::size(acc); ++k)
      acc[k]->committed = a[2 * k], acc[k]->pending = a[2 * k + 1];
    r.read_array("timers", a, 4);
    timers_ = {a[0], a[1], a[2], a[3]};
    timers_loaded_ = timers_;
  }
  {
    CheckpointScope<CheckpointReader> er(r, "erosions");
    std::vector<std::int64_t> cause, cycle, element, kind, part;
    std::vector<double> time, step, centroid;
    r.read_array("cause", cause);
    const std::size_t m = cause.size();
    r.read_array("time", time, m);
    r.read_array("cycle", cycle, m);
    r.read_array("element", element, m);
    r.read_array("kind", kind, m);
    r.read_array("part", part, m);
    r.read_array("step", step, m);
    r.read_array("centroid", centroid, 3 * m);
    erosions_.clear();
    for (std::size_t k = 0; k < m; ++k)
      erosions_.push_back({static_cast<ErosionEvent::Cause>(cause[k]), time[k], cycle[k],
                           element[k], static_cast<ElementKind>(kind[k]), static_cast<int>(part[k]),
                           step[k], V3{centroid[3 * k], centroid[3 * k + 1], centroid[3 * k + 2]}});
  }
  load_array(r, "node_elements", node_elements_);
  load_array(r, "node_freed", node_freed_);
  n_freed_nodes_ = 0;
  for (std::size_t i = 0; i < node_freed_.size(); ++i)
    if (node_freed_[i]) {
      ++n_freed_nodes_;
      for (std::size_t d = 3 * i; d < 3 * i + 3; ++d) inv_mass_[d] = 0;
    }
  {
    CheckpointScope<CheckpointReader> gs(r, "groups");
    r.check_int("count", static_cast<std::int64_t>(groups_.size()));
    for (std::size_t k = 0; k < groups_.size(); ++k) {
      CheckpointScope<CheckpointReader> g(r, checkpoint_index(k));
      r.check_int("kind", static_cast<std::int64_t>(groups_[k]->kind()));
      r.check_int("part", groups_[k]->part());
      r.check_int("size", static_cast<std::int64_t>(groups_[k]->size()));
      groups_[k]->load_state(r);
    }
  }
  {
    CheckpointScope<CheckpointReader> ts(r, "tools");
    for (auto& tool : model_.tools) {
      CheckpointScope<CheckpointReader> t(r, tool.name);
      load_tool_state(tool, r);
    }
  }
  {
    CheckpointScope<CheckpointReader> cs(r, "contacts");
    r.check_int("count", static_cast<std::int64_t>(model_.contacts.size()));
    for (std::size_t k = 0; k < model_.contacts.size(); ++k) {
      CheckpointScope<CheckpointReader> c(r, checkpoint_index(k));
      if (r.read_string("name") != model_.contacts[k]->name())
        r.mismatch("name", "contact '" + r.read_string("name") + "', this model has '" +
                               model_.contacts[k]->name() + "' here");
      model_.contacts[k]->load_state(r);
    }
  }
}

}  // namespace ncfsim::fem
