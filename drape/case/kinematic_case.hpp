#pragma once
// A kinematic (pin-jointed net) drape case, `[case] kind = "kinematic_drape"` (keys in
// docs/case-file.md, "Kinematic drape"): the tool surfaces ([[surface]], the geometry keys of a
// [[tool]], at their final position), the net ([net]: pole, fibre angles, spacing, reach) and the
// ring measure ([ring]).
#include <filesystem>
#include <string>
#include <vector>

#include "drape/kinematic_drape.hpp"
#include "drape/ring_measure.hpp"

namespace ncfsim::drape {

struct KinematicDrapeCase {
  std::filesystem::path file;
  std::string name, description;
  std::vector<std::string> overrides;
  DrapeSurface surface;
  KinematicDrapeSpec net;
  std::array<double, 2> fibre_angles_deg{45.0,
                                         -45.0};  // to the ring's zero direction, about its axis
  RingSpec ring;
};

/// Reads and checks the case (InputError naming file, key and the allowed range).
KinematicDrapeCase load_kinematic_drape_case(const std::filesystem::path& file,
                                             const std::vector<std::string>& overrides);

}  // namespace ncfsim::drape
