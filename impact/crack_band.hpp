#pragma once
// What the crack band did to a crush's fracture energies (issue #42): the tow elements longer
// across a crack than 2 G E / X^2 (snap-back) whose law raises their energy in that mode
// (`crack_band = "raise"`, impact/tow_damage_material.hpp) to the smallest free of snap-back,
// counted per mode in the reference shape by the case reader (impact/case: check_crack_band) and
// reported by the crush's measure (log and warnings.txt, summary.json `crack_band_raised`).
#include <array>
#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "impact/tow_damage_material.hpp"

namespace ncfsim::impact {

struct CrackBandRaise {
  std::size_t elements_checked = 0;            // tow_damage elements
  std::array<std::size_t, kModes> elements{};  // raised, per mode
  std::array<double, kModes> max_factor{}, sum_factor{};
  std::array<std::int64_t, kModes> worst_element{};  // user id of the one raised most

  /// Counts an element of mode m whose energy the law multiplies by `factor` (> 1).
  void add(int mode, double factor, std::int64_t element);
  /// A warning line per raised mode, for the log (warnings.txt) and the report.
  std::vector<std::string> warnings() const;
  /// summary.json `crack_band_raised`: per raised mode {elements, mean_factor, max_factor};
  /// an empty object when none was raised.
  nlohmann::json to_json() const;
};

}  // namespace ncfsim::impact
