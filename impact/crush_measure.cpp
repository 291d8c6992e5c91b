#include "impact/crush_measure.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

#include "fem/contact/tied_contact.hpp"
#include "fem/elements/element_group.hpp"
#include "fem/elements/hex8_block.hpp"
#include "impact/cfc_filter.hpp"
#include "impact/tow_damage_material.hpp"

namespace ncfsim::impact {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// A mode counts as failed once its damage is this close to 1 (the law clamps at exactly 1).
constexpr double kFullDamage = 1.0 - 1e-9;

}  // namespace

CrushMeasure::CrushMeasure(const fem::ExplicitSolver& s, int punch, double cfc,
                           CrackBandRaise crack_band)
    : punch_(punch), cfc_(cfc), crack_band_(std::move(crack_band)) {
  const auto& model = s.model();
  punch_name_ = model.tools.at(static_cast<std::size_t>(punch)).name;
  for (const auto& c : model.contacts)
    if (const auto* t = dynamic_cast<const fem::TiedContact*>(c.get()))
      (t->config().slave_nodes.empty() ? ties_ : stitch_ties_).push_back(t);
  const auto& groups = s.groups();
  for (std::size_t k = 0; k < groups.size(); ++k)
    if (const auto* b = fem::block_of<fem::Hex8Block>(*groups[k]))
      if (dynamic_cast<const TowDamageMaterial*>(b->material)) damage_groups_.push_back(k);
}

std::string CrushMeasure::filtered_column() const {
  return fmt::format("{}_force_cfc{:g}_N", punch_name_, cfc_);
}

std::vector<std::string> CrushMeasure::setup_lines() const {
  std::vector<std::string> lines;
  lines.push_back(fmt::format("crush: punch '{}', force filtered at CFC {:g} (column {})",
                              punch_name_, cfc_, filtered_column()));
  for (const auto* t : ties_)
    lines.push_back(fmt::format("crush: resin bond '{}': {} tied nodes over {:.5g} mm^2", t->name(),
                                t->n_ties(), 1e6 * t->tied_area()));
  for (const auto* t : stitch_ties_)
    lines.push_back(fmt::format(
        "crush: cured stitch '{}': {} stitch nodes tied to the nearest tow face within {:.4g} mm "
        "({} beside no face: free)",
        t->name(), t->n_ties(), 1e3 * t->search_distance(), t->untied_nodes()));
  return lines;
}

void CrushMeasure::add_columns(std::vector<std::string>& c) {
  c.push_back("failed_elements");  // at least one mode fully damaged
  c.push_back("tied_area_failed_m2");
}

CrushMeasure::DamageCounts CrushMeasure::count_damage(const fem::ExplicitSolver& s) const {
  DamageCounts dc;
  for (auto k : damage_groups_) {
    const auto& b = *fem::block_of<fem::Hex8Block>(*s.groups()[k]);
    const double* d =
        b.history.data() + static_cast<std::size_t>(TowDamageMaterial::kDamageRow) * b.n;
    dc.elements += b.n;
    for (int m = 0; m < kModes; ++m)
      for (std::size_t e = 0; e < b.n; ++e) {
        const double v = d[static_cast<std::size_t>(m) * b.n + e];
        dc.failed[static_cast<std::size_t>(m)] += v >= kFullDamage;
        dc.initiated[static_cast<std::size_t>(m)] += v > 0;
      }
  }
  return dc;
}

double CrushMeasure::tied_area(bool failed_only) const {
  double a = 0;
  for (const auto* t : ties_) a += failed_only ? t->failed_area() : t->tied_area();
  return a;
}

void CrushMeasure::add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const {
  const auto& tool = s.model().tools[static_cast<std::size_t>(punch_)];
  const fem::V3 ax = fem::tool_axis(tool);
  time_.push_back(s.time());
  stroke_.push_back(dot(tool.displacement, ax));
  force_.push_back(-dot(tool.force, ax));
  std::size_t failed = 0;
  for (auto k : damage_groups_) {
    const auto& b = *fem::block_of<fem::Hex8Block>(*s.groups()[k]);
    const double* d =
        b.history.data() + static_cast<std::size_t>(TowDamageMaterial::kDamageRow) * b.n;
    for (std::size_t e = 0; e < b.n; ++e) {
      double dmax = 0;
      for (int m = 0; m < kModes; ++m)
        dmax = std::max(dmax, d[static_cast<std::size_t>(m) * b.n + e]);
      failed += dmax >= kFullDamage;
    }
  }
  row.push_back(static_cast<double>(failed));
  row.push_back(tied_area(true));
}

std::vector<double> CrushMeasure::filtered_force(std::string* why_raw) const {
  const std::size_t n = force_.size();
  if (n < 8) {
    if (why_raw) *why_raw = "fewer than 8 history rows";
    return force_;
  }
  // The rows come every time.history_interval (the last one may be closer): the filter takes
  // the mean interval of the regular rows.
  const double T = (time_[n - 2] - time_[0]) / static_cast<double>(n - 2);
  try {
    return cfc_filter(force_, T, cfc_);
  } catch (const std::invalid_argument& e) {
    if (why_raw) *why_raw = e.what();
    return force_;
  }
}

void CrushMeasure::add_final_columns(std::vector<std::string>& columns,
                                     std::vector<std::vector<double>>& rows) const {
  columns.push_back(filtered_column());
  const auto f = filtered_force();
  for (std::size_t i = 0; i < rows.size(); ++i) {
    rows[i].resize(columns.size() - 1, kNaN);
    rows[i].push_back(i < f.size() && f.size() == force_.size() ? f[i] : kNaN);
  }
}

void CrushMeasure::add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const {
  std::string why_raw;
  const auto f = filtered_force(&why_raw);
  double peak = kNaN, peak_raw = kNaN, at_peak = kNaN, work = 0;
  for (std::size_t i = 0; i < f.size(); ++i)
    if (!(f[i] <= peak)) peak = f[i], at_peak = stroke_[i];
  for (std::size_t i = 0; i < force_.size(); ++i) {
    if (!(force_[i] <= peak_raw)) peak_raw = force_[i];
    if (i > 0) work += 0.5 * (force_[i] + force_[i - 1]) * (stroke_[i] - stroke_[i - 1]);
  }
  summary["cfc_class"] = cfc_;
  summary["crack_band_raised"] = crack_band_.to_json();
  summary["peak_force_N"] = fem::json_number(peak);
  summary["peak_force_filtered"] = why_raw.empty();
  if (!why_raw.empty())
    summary["peak_force_unfiltered_because"] = why_raw;
  else
    summary.erase("peak_force_unfiltered_because");  // written at an early frame
  summary["peak_force_raw_N"] = fem::json_number(peak_raw);
  summary["stroke_at_peak_m"] = fem::json_number(at_peak);
  summary["stroke_m"] = stroke_.empty() ? nlohmann::json(nullptr) : nlohmann::json(stroke_.back());
  summary["energy_absorbed_J"] = fem::json_number(force_.size() > 1 ? work : kNaN);

  const DamageCounts dc = count_damage(s);
  const double n = static_cast<double>(std::max<std::size_t>(dc.elements, 1));
  std::size_t dominant = 0;
  for (int m = 0; m < kModes; ++m) {
    const auto k = static_cast<std::size_t>(m);
    summary[std::string("failed_fraction_") + kModeNames[k]] =
        static_cast<double>(dc.failed[k]) / n;
    summary[std::string("initiated_fraction_") + kModeNames[k]] =
        static_cast<double>(dc.initiated[k]) / n;
    if (dc.failed[k] > dc.failed[dominant]) dominant = k;
  }
  summary["dominant_failure_mode"] =
      dc.failed[dominant] > 0 ? nlohmann::json(kModeNames[dominant]) : nlohmann::json(nullptr);
  summary["damage_elements"] = dc.elements;
  const double area = tied_area(false), failed = tied_area(true);
  summary["tied_area_m2"] = area;
  summary["tied_area_failed_m2"] = failed;
  summary["tied_area_failed_fraction"] = area > 0 ? failed / area : 0.0;
  for (const auto* t : ties_) {
    summary[t->name() + "_tied_area_m2"] = t->tied_area();
    summary[t->name() + "_failed_area_m2"] = t->failed_area();
  }
}

void CrushMeasure::add_frame_fields(const fem::ExplicitSolver& s,
                                    std::vector<fem::MeasureCellField>& fields) const {
  std::size_t n_cells = 0;  // every kind's cells, in group (= kind) order
  for (const auto& g : s.groups()) n_cells += g->size();
  std::vector<fem::MeasureCellField> out;
  for (int m = 0; m < kModes; ++m)
    out.push_back({std::string("damage_") + kModeNames[static_cast<std::size_t>(m)], 1,
                   std::vector<double>(n_cells, kNaN)});
  // 0: no mode fully damaged; 1 + m: mode m (FailureMode order) is the most damaged of those that
  // are.
  out.push_back({"failed_mode", 1, std::vector<double>(n_cells, kNaN)});
  std::size_t offset = 0;
  for (const auto& g : s.groups()) {
    if (g->kind() != fem::ElementKind::Hex8) continue;
    const auto& b = *fem::block_of<fem::Hex8Block>(*g);
    if (dynamic_cast<const TowDamageMaterial*>(b.material)) {
      const double* d =
          b.history.data() + static_cast<std::size_t>(TowDamageMaterial::kDamageRow) * b.n;
      for (std::size_t e = 0; e < b.n; ++e) {
        int worst = -1;
        double dmax = 0;
        for (int m = 0; m < kModes; ++m) {
          const double v = d[static_cast<std::size_t>(m) * b.n + e];
          out[static_cast<std::size_t>(m)].values[offset + e] = v;
          if (v > dmax) dmax = v, worst = m;
        }
        out[kModes].values[offset + e] = dmax >= kFullDamage ? 1.0 + worst : 0.0;
      }
    }
    offset += b.n;
  }
  for (auto& f : out) fields.push_back(std::move(f));
}

}  // namespace ncfsim::impact
