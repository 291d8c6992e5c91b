#pragma once
// The tow hexahedra of a fabric's two plies, as the fabric measures read them (the ring shear
// measure, the fabric fields): where each lies in the solver's blocks and in the results files,
// its nodes, and at a given state the current centroids and convected fibre directions of those
// not eroded.
#include <array>
#include <cstdint>
#include <utility>
#include <vector>

#include "fem/solver.hpp"
#include "fem/vec3.hpp"

namespace ncfsim::drape {

struct PlyElements {
  PlyElements(const fem::ExplicitSolver& s, int ply_a, int ply_b);

  std::vector<std::pair<std::size_t, std::size_t>> elements;  // (hex block, element), ply a then b
  std::vector<std::size_t> cell;                              // results-file cell index of each
  std::vector<std::array<std::int32_t, 8>> conn;              // mesh nodes of each
  std::size_t n_a = 0;                                        // elements of ply a (first)
  double longest = 0;  // m, the largest reference bounding-box diagonal of an element

  struct State {
    std::vector<fem::V3> centroid, fibre;  // per element (zero where eroded)
    std::vector<std::int32_t> a, b;        // the elements of each ply not eroded
  };
  State current(const fem::ExplicitSolver& s) const;
};

}  // namespace ncfsim::drape
