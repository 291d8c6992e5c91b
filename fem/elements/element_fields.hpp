#pragma once
// Element results for output (not used in the cycle): Cauchy stress in global axes, von Mises
// stress and the convected fibre direction of hexahedra; axial force and strain of bars.
#include <vector>

#include "fem/elements/bar_block.hpp"
#include "fem/elements/hex8_block.hpp"

namespace ncfsim::fem {

/// Per hexahedron of the block, from the stored 2nd Piola-Kirchhoff stress and current positions x:
/// cauchy [n][6] (xx yy zz xy yz xz, entity-major as output writers want), von_mises [n],
/// fibre [n][3] (unit vector of material axis 1 pushed forward by F).
void hex8_output_fields(const Hex8Block& b, const double* x, double* cauchy, double* von_mises, double* fibre);

/// Unit vector of material axis 1 of element e pushed forward by F (the current fibre direction).
void hex8_fibre_direction(const Hex8Block& b, const double* x, std::size_t e, double out[3]);

/// Von Mises equivalent of a symmetric stress (xx yy zz xy yz xz).
double von_mises(const double s[6]);

}  // namespace ncfsim::fem
