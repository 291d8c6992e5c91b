#pragma once
// What the fabric generator made of each [[mesh.fabric]] (drape/probe_specs.hpp FabricSummary),
// in the log and summary.json "fabrics", and the stitch-to-tow joints released when the tow
// hexahedron that gives their axis erodes (logged as they go, counted in summary.json).
#include <cstddef>
#include <string>
#include <vector>

#include "drape/probe_specs.hpp"
#include "drape/stitch_connection.hpp"
#include "fem/run_measure.hpp"

namespace ncfsim::drape {

class FabricReport final : public fem::RunMeasure {
 public:
  /// `fabrics` as the case reader made them; each names its joints by their index in
  /// model.contacts (FabricSummary::connection_contact, -1: none).
  FabricReport(std::vector<FabricSummary> fabrics, const fem::Model& model);
  std::vector<std::string> setup_lines() const override;
  std::vector<std::string> after_erosion(const fem::ExplicitSolver& s) override;
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override;
  /// The released joints already warned about (a resumed run does not warn again).
  void save_state(fem::CheckpointWriter& w) const override {
    std::vector<std::int64_t> v(released_logged_.begin(), released_logged_.end());
    fem::save_array(w, "released_logged", v);
  }
  void load_state(fem::CheckpointReader& r) override {
    std::vector<std::int64_t> v;
    r.read_array("released_logged", v);
    released_logged_.assign(v.begin(), v.end());
  }

 private:
  std::size_t released(std::size_t k) const { return joints_[k] ? joints_[k]->released() : 0; }
  std::vector<FabricSummary> fabrics_;
  std::vector<const StitchToTowConnection*> joints_;  // per fabric, borrowed (null: none)
  std::vector<std::size_t> released_logged_;
};

}  // namespace ncfsim::drape
