#include "fem/contact/bucket_grid.hpp"

#include <cmath>
#include <limits>

namespace ncfsim::fem {

void BucketGrid::build(std::size_t n, const double* box_lo, const double* box_hi) {
  if (n == 0) {
    dims_[0] = dims_[1] = dims_[2] = 0;
    start_.assign(1, 0);
    items_.clear();
    return;
  }
  double lo[3], hi[3], mean[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k) lo[k] = std::numeric_limits<double>::max(), hi[k] = -lo[k];
  for (std::size_t b = 0; b < n; ++b)
    for (int k = 0; k < 3; ++k) {
      lo[k] = std::min(lo[k], box_lo[3 * b + k]);
      hi[k] = std::max(hi[k], box_hi[3 * b + k]);
      mean[k] += box_hi[3 * b + k] - box_lo[3 * b + k];
    }
  double cell[3];
  double span_max = 0;
  for (int k = 0; k < 3; ++k) span_max = std::max(span_max, hi[k] - lo[k]);
  const double floor_size = std::max(span_max * 1e-9, 1e-300);
  for (int k = 0; k < 3; ++k) cell[k] = std::max(mean[k] / static_cast<double>(n), floor_size);
  const double max_cells = std::max(1024.0, 2.0 * static_cast<double>(n));
  auto count = [&](int k) {
    return std::max(1.0, std::ceil((hi[k] - lo[k]) / cell[k] * (1 + 1e-12)));
  };
  for (;;) {
    const double total = count(0) * count(1) * count(2);
    if (total <= max_cells) break;
    const double grow = std::cbrt(total / max_cells) * 1.01;
    for (double& c : cell) c *= grow;
  }
  for (int k = 0; k < 3; ++k) {
    lo_[k] = lo[k];
    dims_[k] = static_cast<std::int64_t>(count(k));
    inv_cell_[k] = 1.0 / cell[k];
  }
  const auto n_cells = static_cast<std::size_t>(dims_[0] * dims_[1] * dims_[2]);
  auto range = [&](const double* blo, const double* bhi, std::int64_t(&a)[3], std::int64_t(&b)[3]) {
    for (int k = 0; k < 3; ++k) {
      a[k] = std::clamp<std::int64_t>(static_cast<std::int64_t>((blo[k] - lo_[k]) * inv_cell_[k]),
                                      0, dims_[k] - 1);
      b[k] = std::clamp<std::int64_t>(static_cast<std::int64_t>((bhi[k] - lo_[k]) * inv_cell_[k]),
                                      0, dims_[k] - 1);
    }
  };
  start_.assign(n_cells + 1, 0);
  std::int64_t a[3], b[3];
  for (std::size_t q = 0; q < n; ++q) {
    range(box_lo + 3 * q, box_hi + 3 * q, a, b);
    for (std::int64_t k = a[2]; k <= b[2]; ++k)
      for (std::int64_t j = a[1]; j <= b[1]; ++j)
        for (std::int64_t i = a[0]; i <= b[0]; ++i)
          ++start_[static_cast<std::size_t>(i + dims_[0] * (j + dims_[1] * k)) + 1];
  }
  for (std::size_t c = 0; c < n_cells; ++c) start_[c + 1] += start_[c];
  cursor_.assign(start_.begin(), start_.end() - 1);
  items_.resize(static_cast<std::size_t>(start_[n_cells]));
  for (std::size_t q = 0; q < n; ++q) {
    range(box_lo + 3 * q, box_hi + 3 * q, a, b);
    for (std::int64_t k = a[2]; k <= b[2]; ++k)
      for (std::int64_t j = a[1]; j <= b[1]; ++j)
        for (std::int64_t i = a[0]; i <= b[0]; ++i)
          items_[static_cast<std::size_t>(
              cursor_[static_cast<std::size_t>(i + dims_[0] * (j + dims_[1] * k))]++)] =
              static_cast<std::int32_t>(q);
  }
}

}  // namespace ncfsim::fem
