#pragma once
// Sign vectors of the trilinear basis of the 8-node hexahedron (VTK node order), rows for
// 1, xi, eta, zeta, eta*zeta, zeta*xi, xi*eta, xi*eta*zeta. a_k = (1/8) sum_I kHex8Sign[k][I] x_I
// are the basis vectors; a_1..a_3 the columns of the centre Jacobian.
namespace ncfsim::fem {

inline constexpr double kHex8Sign[8][8] = {
    {1, 1, 1, 1, 1, 1, 1, 1},      {-1, 1, 1, -1, -1, 1, 1, -1},  {-1, -1, 1, 1, -1, -1, 1, 1},
    {-1, -1, -1, -1, 1, 1, 1, 1},  {1, 1, -1, -1, -1, -1, 1, 1},  {1, -1, -1, 1, -1, 1, 1, -1},
    {1, -1, 1, -1, 1, -1, 1, -1},  {-1, 1, -1, 1, 1, -1, 1, -1}};

}  // namespace ncfsim::fem
