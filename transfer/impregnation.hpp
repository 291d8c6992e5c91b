#pragma once
// The mapping at the heart of the transfer stage, on plain arrays (a drape result's frame): every
// draped tow hexahedron becomes an impregnated-tow element with
//  * an orthonormal material frame: axis 1 along the convected fibre direction, axis 3 through
//    the tow's thickness (bottom face to top face of the hexahedron, made normal to axis 1),
//    axis 2 = 3 x 1 (right-handed);
//  * its fibre volume fraction raised by its compaction during the drape: Vf = Vf0 lambda_1 / J
//    (constant fibre content, J the volume ratio of the hexahedron, lambda_1 the fibre stretch),
//    capped at the locking value and floored at the undeformed one (a tow the drape spread, with
//    J / lambda_1 > 1, is pressed back to at least its nominal Vf by the infusion's vacuum bag);
//  * a material class: elements are grouped by Vf into bins of `vf_bin` width, one impregnated
//    material per bin, so that the crush runs over batches of one material (bins of 0.005 keep
//    the moduli within ~1 % of the element's own).
#include <array>
#include <cstdint>
#include <vector>

#include "fem/vec3.hpp"

namespace ncfsim::transfer {

struct DrapedTows {
  std::vector<fem::V3> reference, current;       // node positions [n_nodes]
  std::vector<std::array<std::int32_t, 8>> hex;  // VTK order: bottom face, then top face
  std::vector<fem::V3> fibre;                    // per hexahedron, convected fibre direction
  std::vector<double> fibre_stretch;             // per hexahedron (empty: 1, inextensible)
};

struct MappingSpec {
  double vf_undeformed = 0.6;  // the dry tow's fibre volume fraction
  double vf_locking =
      0.857;              // the tow's fibre volume fraction at locking (vf0 / locking width ratio)
  double vf_bin = 0.005;  // width of the Vf classes
  /// Throws std::invalid_argument naming the field and its range.
  void validate() const;
};

struct ImpregnatedMapping {
  std::vector<std::array<double, 9>> frame;  // per element: row-major, axes as columns (global)
  std::vector<double> volume_ratio;          // J per element
  std::vector<double> vf;                    // per element, after compaction (capped)
  std::vector<std::int32_t> vf_class;        // per element: index into class_vf
  std::vector<double> class_vf;              // Vf of each class (its bin centre)
  std::size_t n_capped = 0;                  // elements whose Vf was capped at the locking value
  std::size_t n_floored = 0;                 // elements whose Vf was raised to the undeformed value
};

/// Exact volume of a trilinear hexahedron (2 x 2 x 2 Gauss points integrate its Jacobian exactly).
double hex_volume(const std::array<fem::V3, 8>& x);

/// Smallest scaled corner Jacobian of a hexahedron (VTK order): at each corner the triple product
/// of the three edges leaving it over the product of their lengths; 1 for a box, <= 0 where the
/// element folds over at a corner (which its volume does not show).
double min_scaled_corner_jacobian(const std::array<fem::V3, 8>& x);

/// Throws std::invalid_argument for a bad spec and std::runtime_error naming the element for a
/// hexahedron with a non-positive volume or a fibre direction along its thickness.
ImpregnatedMapping map_impregnated(const DrapedTows& tows, const MappingSpec& spec);

}  // namespace ncfsim::transfer
