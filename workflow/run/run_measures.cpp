#include "workflow/run/run_measures.hpp"

#include <fmt/format.h>

#include "drape/probes/bending_length_probe.hpp"
#include "drape/probes/bias_extension_curve.hpp"
#include "drape/probes/fabric_fields.hpp"
#include "drape/probes/fabric_report.hpp"
#include "drape/probes/picture_frame_force.hpp"
#include "drape/probes/ring_shear_probe.hpp"
#include "drape/probes/shear_angle_probe.hpp"
#include "fem/elements/hex8_block.hpp"
#include "impact/crush_measure.hpp"

namespace ncfsim::workflow {

using fem::V3;

std::string sample_suffix(double at, const std::string& unit) {
  return fmt::format("_at_{:g}{}", at, unit);
}

namespace {

void add_xyz(std::vector<std::string>& columns, const std::string& prefix,
             const std::string& unit) {
  for (const char* c : {"x", "y", "z"}) columns.push_back(prefix + "_" + c + "_" + unit);
}

// time, cycle, step and the energy balance (+ erosion counts when erosion is on).
class EnergyColumns final : public fem::RunMeasure {
 public:
  explicit EnergyColumns(bool erosion) : erosion_(erosion) {}
  void add_columns(std::vector<std::string>& c) override {
    for (const char* n :
         {"time", "cycle", "time_step_s", "kinetic_energy_J", "internal_energy_J",
          "stabilisation_energy_J", "hourglass_energy_J", "contact_energy_J", "friction_energy_J",
          "damping_energy_J", "external_work_J", "total_energy_J", "energy_balance_error"})
      c.push_back(n);
    if (erosion_) {
      c.push_back("eroded_elements");
      c.push_back("eroded_internal_energy_J");
      c.push_back("eroded_kinetic_energy_J");
      c.push_back("freed_nodes");
    }
  }
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override {
    const auto& en = s.energy();
    for (double v : {s.time(), static_cast<double>(s.cycle()), s.time_step(), en.kinetic,
                     en.internal, en.stabilisation, en.hourglass, en.contact, en.friction,
                     en.damping, en.external_work, en.total(), en.error()})
      row.push_back(v);
    if (erosion_) {
      row.push_back(static_cast<double>(s.erosions().size()));
      row.push_back(en.eroded_internal);
      row.push_back(en.eroded_kinetic);
      row.push_back(static_cast<double>(s.n_freed_nodes()));
    }
  }

 private:
  bool erosion_;
};

// Rigid tools: force (resistance of the part, positive against the motion) and displacement
// along the motion axis, and their components.
class ToolMeasure final : public fem::RunMeasure {
 public:
  explicit ToolMeasure(const fem::RigidTool& t) : tool_(t) {}
  void add_columns(std::vector<std::string>& c) override {
    c.push_back(tool_.name + "_force_N");
    c.push_back(tool_.name + "_displacement_m");
    add_xyz(c, tool_.name + "_force", "N");
    add_xyz(c, tool_.name + "_displacement", "m");
  }
  void add_values(const fem::ExplicitSolver&, std::vector<double>& row) const override {
    const V3 ax = tool_axis(tool_);
    row.push_back(-dot(tool_.force, ax));  // resistance of the part, positive against the motion
    row.push_back(dot(tool_.displacement, ax));
    for (double v : tool_.force.arr()) row.push_back(v);
    for (double v : tool_.displacement.arr()) row.push_back(v);
  }
  void add_summary(const fem::ExplicitSolver&, nlohmann::json& summary) const override {
    summary[tool_.name + "_force_N"] = -dot(tool_.force, tool_axis(tool_));
    summary[tool_.name + "_displacement_m"] = dot(tool_.displacement, tool_axis(tool_));
    summary[tool_.name + "_max_penetration_m"] = tool_.max_penetration;  // over the run
  }

 private:
  const fem::RigidTool& tool_;  // borrowed from the model
};

// Reaction of a fixed or velocity set.
class ReactionMeasure final : public fem::RunMeasure {
 public:
  explicit ReactionMeasure(const ReactionProbe& r) : r_(r) {}
  void add_columns(std::vector<std::string>& c) override { add_xyz(c, r_.name + "_reaction", "N"); }
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override {
    for (double v : s.reaction_force(r_.nodes).arr()) row.push_back(v);
  }

 private:
  ReactionProbe r_;
};

// Mean displacement of a node set.
class DisplacementMeasure final : public fem::RunMeasure {
 public:
  explicit DisplacementMeasure(const DisplacementProbe& p) : p_(p) {}
  void add_columns(std::vector<std::string>& c) override {
    add_xyz(c, p_.name + "_displacement", "m");
  }
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override {
    for (double v : fem::mean_displacement(s, p_.nodes).arr()) row.push_back(v);
  }
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override {
    const V3 d = fem::mean_displacement(s, p_.nodes);
    summary[p_.name + "_displacement_m"] = {d.x, d.y, d.z};
  }

 private:
  DisplacementProbe p_;
};

// One hexahedron's material-frame stress and strain.
class ElementMeasure final : public fem::RunMeasure {
 public:
  ElementMeasure(const ElementProbe& p, const fem::ExplicitSolver& s) : p_(p) {
    for (const auto& b : s.blocks<fem::Hex8Block>())
      for (std::size_t e = 0; e < b.n; ++e)
        if (b.user_id[e] == p.element) block_ = &b, index_ = e;
  }
  void add_columns(std::vector<std::string>& c) override {
    for (const char* ij : {"11", "22", "33", "12", "23", "13"})
      c.push_back(p_.name + "_stress_" + ij + "_Pa");
    for (const char* ij : {"11", "22", "33", "12", "23", "13"})
      c.push_back(p_.name + "_strain_" + ij);
  }
  void add_values(const fem::ExplicitSolver&, std::vector<double>& row) const override {
    for (int c = 0; c < 6; ++c)
      row.push_back(block_ ? block_->stress[static_cast<std::size_t>(c) * block_->n + index_]
                           : 0.0);
    for (int c = 0; c < 6; ++c)
      row.push_back(block_ ? block_->strain[static_cast<std::size_t>(c) * block_->n + index_]
                           : 0.0);
  }

 private:
  ElementProbe p_;
  const fem::Hex8Block* block_ = nullptr;
  std::size_t index_ = 0;
};

// Force resultants of the deformable contacts, named by the contacts once they have run a cycle.
class ContactResultants final : public fem::RunMeasure {
 public:
  void add_late_columns(const fem::ExplicitSolver& s, std::vector<std::string>& c) const override {
    for (std::size_t k = 0; k < s.model().contacts.size(); ++k)
      for (const auto& r : s.contact_resultants(k)) add_xyz(c, r.name + "_force", "N");
  }
  void add_values(const fem::ExplicitSolver& s, std::vector<double>& row) const override {
    for (std::size_t k = 0; k < s.model().contacts.size(); ++k)
      for (const auto& r : s.contact_resultants(k))
        for (double v : r.force.arr()) row.push_back(v);
  }
  // Deepest penetration past the contact thickness over the run: a body passing through another
  // shows as a depth near its thickness.
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override {
    for (std::size_t k = 0; k < s.model().contacts.size(); ++k)
      summary[s.model().contacts[k]->name() + "_max_penetration_m"] = s.contact_max_penetration(k);
  }
};

// The bias-extension curve (Eq. 2) of the case's summary samples that ask for it: the history
// column follows the last of them.
std::unique_ptr<fem::RunMeasure> make_bias_extension_curve(const EngineCase& ec) {
  const SummarySamples* analytic = nullptr;
  std::vector<drape::BiasExtensionCurve::Point> points;
  for (const auto& ss : ec.samples) {
    if (!ss.bias_extension_analytic) continue;
    analytic = &ss;
    drape::BiasExtensionCoupon coupon;
    coupon.length = ss.coupon_length, coupon.width = ss.coupon_width;
    for (double at : ss.at)
      points.push_back({sample_suffix(at, ss.x_unit), at / ss.x_display_scale, coupon});
  }
  if (!analytic) return nullptr;
  drape::BiasExtensionCoupon coupon;
  coupon.length = analytic->coupon_length, coupon.width = analytic->coupon_width;
  return std::make_unique<drape::BiasExtensionCurve>(analytic->x, coupon, std::move(points),
                                                     ec.file.string());
}

}  // namespace

MeasureList make_run_measures(const EngineCase& ec, const fem::ExplicitSolver& s) {
  const fem::Model& model = s.model();
  MeasureList m;
  m.push_back(std::make_unique<EnergyColumns>(s.erosion_enabled()));
  for (const auto& t : model.tools) m.push_back(std::make_unique<ToolMeasure>(t));
  for (const auto& r : ec.reactions) m.push_back(std::make_unique<ReactionMeasure>(r));
  for (std::size_t k = 0; k < model.picture_frames.size(); ++k)
    m.push_back(std::make_unique<drape::PictureFrameForce>(k, model.picture_frames[k],
                                                           ec.frame_fabric_length[k]));
  for (const auto& p : ec.probes) m.push_back(std::make_unique<DisplacementMeasure>(p));
  for (const auto& p : ec.element_probes) m.push_back(std::make_unique<ElementMeasure>(p, s));
  for (const auto& sp : ec.shear_probes)
    m.push_back(std::make_unique<drape::ShearAngleProbe>(sp, s, ec.file.string()));
  for (const auto& bp : ec.bending)
    m.push_back(std::make_unique<drape::BendingLengthMeasure>(bp, s));
  for (const auto& rp : ec.ring_probes)
    if (rp.shell_part >= 0)
      m.push_back(std::make_unique<drape::ShellRingShearMeasure>(rp, s));
    else
      m.push_back(std::make_unique<drape::RingShearMeasure>(rp, s));
  if (auto curve = make_bias_extension_curve(ec)) m.push_back(std::move(curve));
  if (ec.crush.enabled)
    m.push_back(std::make_unique<impact::CrushMeasure>(s, ec.crush.punch, ec.crush.cfc,
                                                       ec.crush.crack_band));
  m.push_back(std::make_unique<ContactResultants>());
  if (!ec.fabric_summaries.empty())
    m.push_back(std::make_unique<drape::FabricReport>(ec.fabric_summaries, model));
  // After the report, which writes each fabric's summary entry anew.
  for (const auto& f : ec.fabric_summaries)
    if (f.ply_parts.size() == 2)
      m.push_back(std::make_unique<drape::FabricFields>(f.name, f.ply_parts[0], f.ply_parts[1], s));
  return m;
}

}  // namespace ncfsim::workflow
