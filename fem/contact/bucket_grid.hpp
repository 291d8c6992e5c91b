#pragma once
// Broad phase: a uniform grid of axis-aligned boxes (segments grown by the search margin) in
// compressed rows (CSR), rebuilt in place: after the first builds it allocates nothing.
#include <algorithm>
#include <cstdint>
#include <vector>

namespace ncfsim::fem {

class BucketGrid {
 public:
  /// Sorts boxes [lo, hi] (box_lo, box_hi: [n][3], borrowed) into cells. The cell edge along
  /// each axis is the mean box size along it, grown uniformly while there would be more than
  /// max(1024, 2 n) cells.
  void build(std::size_t n, const double* box_lo, const double* box_hi);

  /// Boxes whose cell range holds the point; [begin, end) into items(). False outside the grid.
  bool cell_of(const double* p, std::int32_t& begin, std::int32_t& end) const {
    std::int64_t idx = 0, stride = 1;
    for (int k = 0; k < 3; ++k) {
      const double t = (p[k] - lo_[k]) * inv_cell_[k];
      if (!(t >= 0) || t >= static_cast<double>(dims_[k])) return false;
      idx += stride * static_cast<std::int64_t>(t);
      stride *= dims_[k];
    }
    begin = start_[static_cast<std::size_t>(idx)];
    end = start_[static_cast<std::size_t>(idx) + 1];
    return true;
  }
  const std::int32_t* items() const { return items_.data(); }
  std::size_t n_cells() const { return start_.empty() ? 0 : start_.size() - 1; }

 private:
  double lo_[3] = {0, 0, 0}, inv_cell_[3] = {1, 1, 1};
  std::int64_t dims_[3] = {0, 0, 0};
  std::vector<std::int32_t> start_;   // [n_cells + 1]
  std::vector<std::int32_t> cursor_;  // [n_cells] fill positions
  std::vector<std::int32_t> items_;   // box indices, cell by cell
};

}  // namespace ncfsim::fem
