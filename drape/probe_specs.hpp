#pragma once
// What a case asks the fabric model to measure (its probes) and what a generated blanket reports:
// plain data read by the case reader and used by the run's measures.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "drape/ring_measure.hpp"

namespace ncfsim::drape {

/// In-plane shear angle between the fibres of two plies over the elements whose reference centroid
/// lies in a box (a material region): 90 deg minus the angle between the mean fibre directions.
/// history.csv: <name>_shear_angle_deg.
struct ShearProbe {
  std::string name;
  int part_a = -1, part_b = -1;
  std::array<double, 3> box_min{}, box_max{};
};

/// ASTM D1388 cantilever bending of a strip clamped at `root` and overhanging to `tip` under
/// gravity: tip angle theta below the horizontal, bending length c = O (cos(theta/2) / (8 tan
/// theta))^(1/3), flexural rigidity G = w c^3 (w = weight per area), and the beam-theory c of the
/// part's material, (E1 t^3 / 12 / w)^(1/3). history.csv: <name>_tip_angle_deg.
struct BendingLengthProbe {
  std::string name;
  int part = -1;
  std::vector<std::int32_t> root, tip;
};

/// The paper's Fig. 18 measure on a formed fabric: the inter-ply shear angle around the ring at
/// a height above the blankholder plane (drape/ring_measure.hpp), from the elements of two plies.
/// summary.json max_shear_deg_q1..q4, ring_shear.csv.
struct RingShearProbe {
  int part_a = -1, part_b = -1;
  // A macro (shell) drape: the one shell part whose shear_angle_deg is read instead of the two
  // plies' inter-ply angle (-1: meso); keys macro_max_shear_deg_q1..q4, column macro_shear_deg.
  int shell_part = -1;
  RingSpec ring;
  // The kinematic (pin-jointed net) drape of a kinematic_drape case on the same ring, computed
  // once when the case is read (empty: none): the ring CSV's kinematic_shear_deg column and the
  // summary's kinematic_max_shear_deg_q1..q4, beside the meso ones.
  std::string kinematic_case;
  std::vector<RingSample> kinematic;
};

/// What a [[mesh.fabric]] generated (echoed in the log and summary.json).
struct FabricSummary {
  std::string name;
  std::size_t tows = 0, dropped_tows = 0, penetrations = 0, connections = 0;
  double tow_thickness = 0;
  // Index of its stitch-to-tow connection in model.contacts (-1: none).
  int connection_contact = -1;
  std::vector<int> ply_parts;  // part index per ply (hexahedra)
};

}  // namespace ncfsim::drape
