#include "drape/probes/fabric_report.hpp"

#include <fmt/format.h>

#include <cassert>

namespace ncfsim::drape {

FabricReport::FabricReport(std::vector<FabricSummary> fabrics, const fem::Model& model)
    : fabrics_(std::move(fabrics)), released_logged_(fabrics_.size(), 0) {
  for (const auto& f : fabrics_) {
    const StitchToTowConnection* joints = nullptr;
    if (f.connection_contact >= 0) {
      // The case reader keeps the index of the contact it made for this fabric's joints.
      const fem::ContactAlgorithm* c = model.contacts.at(static_cast<std::size_t>(f.connection_contact)).get();
      assert(dynamic_cast<const StitchToTowConnection*>(c) != nullptr);
      joints = static_cast<const StitchToTowConnection*>(c);
    }
    joints_.push_back(joints);
  }
}

std::vector<std::string> FabricReport::setup_lines() const {
  std::vector<std::string> lines;
  for (const auto& f : fabrics_)
    lines.push_back(fmt::format("fabric {}: {} tows ({} dropped at the corners), tow thickness {:.4g} mm, {} stitch "
                                "penetrations, {} stitch-to-tow connections",
                                f.name, f.tows, f.dropped_tows, 1e3 * f.tow_thickness, f.penetrations, f.connections));
  return lines;
}

std::vector<std::string> FabricReport::after_erosion(const fem::ExplicitSolver& s) {
  std::vector<std::string> lines;
  for (std::size_t k = 0; k < fabrics_.size(); ++k) {
    const std::size_t n = released(k);
    if (n == released_logged_[k]) continue;
    lines.push_back(fmt::format("fabric {}: {} stitch-to-tow connections released at t = {:.6g} s (their tow "
                                "hexahedron eroded), {} of {} in all",
                                fabrics_[k].name, n - released_logged_[k], s.time(), n, fabrics_[k].connections));
    released_logged_[k] = n;
  }
  return lines;
}

void FabricReport::add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const {
  (void)s;
  if (fabrics_.empty()) return;
  auto& out = summary["fabrics"];
  for (std::size_t k = 0; k < fabrics_.size(); ++k) {
    const auto& f = fabrics_[k];
    out[f.name] = {{"tows", f.tows},
                   {"dropped_tows", f.dropped_tows},
                   {"tow_thickness_m", f.tow_thickness},
                   {"stitch_penetrations", f.penetrations},
                   {"stitch_connections", f.connections},
                   {"stitch_connections_released", released(k)}};
  }
}

}  // namespace ncfsim::drape
