#pragma once
// The paper's Fig. 18 measure: the fabric shear angle around a formed part on the circle at a
// given height above a reference plane (the blankholder's), against the azimuth measured from the
// wale direction, every degree; and its maxima per quadrant (the four 90 deg sectors centred on
// the azimuths 0, 90, 180 and 270 deg, q1 centred on the wale direction, counter-clockwise seen
// from the side the axis points to). Shear bias shows as quadrants that differ.
//
// The measure is taken on a triangulated surface with a shear angle per node (a kinematic net, a
// ply's outer faces, a shell mesh): for each azimuth the ray from the axis at that height, in the
// plane normal to the axis, is intersected with the triangles; the first hit from the axis counts
// and its value is interpolated from the triangle's nodes.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "fem/vec3.hpp"

namespace ncfsim::drape {

struct RingSpec {
  fem::V3 centre;                   // a point of the part's axis in the reference plane
  fem::V3 axis{0, 0, 1};            // unit, from the reference plane towards the part's top
  fem::V3 zero_direction{1, 0, 0};  // azimuth 0 (the wale direction), projected normal to axis
  double height = 0.04;             // m above the reference plane
  double step_deg = 1.0;            // azimuth step, (0, 90]
  /// Throws std::invalid_argument naming the field and its allowed range.
  void validate() const;
};

struct RingSample {
  double azimuth_deg = 0;
  bool hit = false;      // the ray met the surface
  double shear_deg = 0;  // interpolated shear angle (0 without a hit)
  fem::V3 point;         // where the ray met the surface
};

std::vector<RingSample> ring_shear(const std::vector<fem::V3>& nodes,
                                   const std::vector<std::array<std::int32_t, 3>>& triangles,
                                   const std::vector<double>& node_shear_deg, const RingSpec& ring);

/// The ring as CSV text: azimuth_deg,<shear_column>,hit,x_m,y_m,z_m (NaN shear where the ray
/// misses): ring_shear.csv of the meso runs and of the kinematic drape.
std::string ring_csv(const std::vector<RingSample>& ring, const std::string& shear_column);

struct QuadrantMaxima {
  std::array<double, 4> max_shear_deg{0, 0, 0, 0};  // q1..q4
  std::array<int, 4> samples{0, 0, 0, 0};           // azimuths with a hit in each quadrant
};

/// A sample on a quadrant boundary (45, 135, ... deg) counts in both quadrants.
QuadrantMaxima quadrant_maxima(const std::vector<RingSample>& ring);

}  // namespace ncfsim::drape
