#pragma once
// Two-node bars with a tabulated force-strain law (axial force in N against engineering
// strain), optionally tension-only: the stitch yarn of the fabric model.
#include <cstdint>
#include <string>
#include <vector>

#include "fem/elements/block_of.hpp"
#include "fem/elements/element_step.hpp"

namespace ncfsim::fem {

/// Piecewise-linear axial force F(strain); extrapolated with the end slopes.
class BarForceLaw {
 public:
  BarForceLaw() = default;
  /// Throws std::invalid_argument unless strains strictly increase and F(0) = 0.
  BarForceLaw(std::string name, std::vector<double> strain, std::vector<double> force,
              bool tension_only, double linear_density);
  static BarForceLaw linear(std::string name, double axial_stiffness_EA, bool tension_only,
                            double linear_density);
  double force(double strain) const {
    if (tension_only_ && strain <= 0) return 0.0;
    const std::size_t n = strain_.size();
    std::size_t i = 0;
    while (i + 2 < n && strain > strain_[i + 1]) ++i;  // tables are short: a scan beats bisection
    return force_[i] + slope_[i] * (strain - strain_[i]);
  }
  // The table as evaluated (origin prepended where needed), for the batched kernel: segment i
  // starts at strains()[i] with forces()[i] and slopes()[i].
  const std::vector<double>& strains() const { return strain_; }
  const std::vector<double>& forces() const { return force_; }
  const std::vector<double>& slopes() const { return slope_; }
  double max_slope() const { return max_slope_; }
  double linear_density() const { return rho_l_; }
  bool tension_only() const { return tension_only_; }
  const std::string& name() const { return name_; }

 private:
  std::string name_;
  std::vector<double> strain_, force_, slope_;
  bool tension_only_ = false;
  double max_slope_ = 0, rho_l_ = 0;
};

struct BarBlock {
  int part = 0;
  const BarForceLaw* law = nullptr;  // borrowed
  std::size_t n = 0;
  std::vector<std::int32_t> conn;     // [2][n]
  std::vector<std::int64_t> user_id;  // [n]
  std::vector<double> length0;        // [n]
  std::vector<double> strain;         // [n] engineering strain at the last update
  std::vector<double> force;          // [n] axial force at the last update
  std::vector<double> dt_crit;        // [n] (fixed: depends on mass and slope only)
  // Bars the per-cycle kernel integrates (a rank's run, fem/parallel/domain.hpp).
  std::size_t range_begin = 0, range_end = static_cast<std::size_t>(-1);
  std::vector<double> mass_scale;     // [n] >1 where mass scaling raised the bar's step
};

void bar_initialise(BarBlock& b, const double* x_ref);
void bar_lumped_mass(const BarBlock& b, double* mass);
void bar_internal_forces(BarBlock& b, const double* x, double* f, ElementEnergyIncrement& energy,
                         StableStep& step);

// The block behind an element group (fem/elements/block_of.hpp), null for another kind.
template <>
BarBlock* block_of<BarBlock>(ElementGroup& g);
template <>
const BarBlock* block_of<BarBlock>(const ElementGroup& g);

}  // namespace ncfsim::fem
