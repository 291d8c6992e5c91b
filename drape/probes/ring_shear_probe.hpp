#pragma once
// The ring shear measure on the meso model (drape/probe_specs.hpp RingShearProbe): at every frame
// and at the end, the inter-ply shear angle of each tow element of the two plies (against the
// nearest element of the other ply, current positions), averaged to the nodes, read around the
// ring on the plies' outer faces. summary.json max_shear_deg_q1..q4; ring_shear.csv at the end.
#include <array>
#include <utility>
#include <vector>

#include "drape/probe_specs.hpp"
#include "drape/probes/ply_elements.hpp"
#include "fem/run_measure.hpp"

namespace ncfsim::drape {

class RingShearMeasure final : public fem::RunMeasure {
 public:
  RingShearMeasure(const RingShearProbe& spec, const fem::ExplicitSolver& s);
  std::vector<std::string> setup_lines() const override;
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override;
  std::vector<std::string> write_files(const fem::ExplicitSolver& s,
                                       const std::filesystem::path& dir) const override;

  /// The ring at the solver's current state.
  std::vector<RingSample> ring(const fem::ExplicitSolver& s) const;

 private:
  RingShearProbe spec_;
  PlyElements plies_;
  std::vector<std::array<std::int32_t, 3>> faces_;  // outer-face triangles (mesh nodes)
  double reach_ = 0;                                // m, nearest-element search
};

/// The ring on a macro (shell) drape: the magnitude of each shell's shear_angle_deg
/// (fem/elements/shell4_block) averaged to the nodes, read around the ring on the shells split into triangles.
/// summary.json macro_max_shear_deg_q1..q4 (and kinematic_...); ring_shear.csv column
/// macro_shear_deg.
class ShellRingShearMeasure final : public fem::RunMeasure {
 public:
  ShellRingShearMeasure(const RingShearProbe& spec, const fem::ExplicitSolver& s);
  std::vector<std::string> setup_lines() const override;
  void add_summary(const fem::ExplicitSolver& s, nlohmann::json& summary) const override;
  std::vector<std::string> write_files(const fem::ExplicitSolver& s,
                                       const std::filesystem::path& dir) const override;
  std::vector<RingSample> ring(const fem::ExplicitSolver& s) const;

 private:
  RingShearProbe spec_;
  std::vector<std::array<std::int32_t, 3>> faces_;
  std::size_t n_shells_ = 0;
};

}  // namespace ncfsim::drape
