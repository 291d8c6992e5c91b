#pragma once
// What a crush run measures and reports (issue #21): the punch's force against its displacement,
// raw and filtered (SAE J211 / ISO 6487 CFC, a final history column), the peak force and the
// stroke at it, the energy absorbed (the punch's work), the damage of the tows per failure mode
// (result fields damage_<mode>, failed_mode; failed and initiated fractions per mode) and the
// resin bonds' failed area. Reads the solver state, never changes it.
#include <string>
#include <vector>

#include "fem/run_measure.hpp"
#include "impact/crack_band.hpp"

namespace ncfsim::fem {
struct Hex8Block;
class TiedContact;
}  // namespace ncfsim::fem

namespace ncfsim::impact {

class CrushMeasure final : public fem::RunMeasure {
 public:
  /// `punch`: index into the model's tools; `cfc`: the filter's channel frequency class;
  /// `crack_band`: the fracture energies the case's laws raised (reported).
  CrushMeasure(const fem::ExplicitSolver& s, int punch, double cfc, CrackBandRaise crack_band = {});

  std::vector<std::string> setup_lines() const override;
  std::vector<std::string> setup_warnings() const override { return crack_band_.warnings(); }
  void add_columns(std::vector<std::string>& columns) override;
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override;
  bool needs_final_columns() const override { return true; }
  void add_final_columns(std::vector<std::string>& columns,
                         std::vector<std::vector<double>>& rows) const override;
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override;
  void add_frame_fields(const fem::ExplicitSolver& s,
                        std::vector<fem::MeasureCellField>& fields) const override;

  /// Column of the filtered punch force: <punch>_force_cfc<class>_N.
  std::string filtered_column() const;
  /// The force-stroke samples so far (a resumed run's filter sees the whole curve).
  void save_state(fem::CheckpointWriter& w) const override {
    fem::save_array(w, "time", time_);
    fem::save_array(w, "stroke", stroke_);
    fem::save_array(w, "force", force_);
  }
  void load_state(fem::CheckpointReader& r) override {
    r.read_array("time", time_);
    r.read_array("stroke", stroke_, time_.size());
    r.read_array("force", force_, time_.size());
  }

 private:
  struct DamageCounts {
    std::size_t elements = 0;
    std::array<std::size_t, 6> failed{}, initiated{};
  };
  DamageCounts count_damage(const fem::ExplicitSolver& s) const;
  double tied_area(bool failed_only) const;
  /// The filtered force at the recorded samples (raw when they are too few or too sparse).
  std::vector<double> filtered_force(std::string* why_raw = nullptr) const;

  int punch_;
  double cfc_;
  CrackBandRaise crack_band_;
  std::string punch_name_;
  std::vector<const fem::TiedContact*> ties_;         // the resin bonds
  std::vector<const fem::TiedContact*> stitch_ties_;  // the cured stitch's nodes on the tows
  std::vector<std::size_t> damage_groups_;  // indices of the hexahedron groups with a damage law
  // Samples at the history rows: time, punch displacement and force (resistance, N).
  mutable std::vector<double> time_, stroke_, force_;
};

}  // namespace ncfsim::impact
