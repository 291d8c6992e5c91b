// The broad phase's grid (fem/contact/bucket_grid), exact, no tolerance: for any point in the
// grid, the boxes of its cell that contain it are exactly the boxes that contain it (brute
// force over all boxes), each once, in increasing order: the order the contact's candidates and
// tie searches rely on. Shown on boxes spread over a dome (a curved surface filling few cells of
// its bounding box, so the grid's cap on its cell count makes the cells grow), with a few boxes
// far larger than the mean, and on flat boxes (zero extent).
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <random>
#include <vector>

#include "fem/contact/bucket_grid.hpp"

using namespace ncfsim;

namespace {

struct Boxes {
  std::vector<double> lo, hi;
  std::size_t size() const { return lo.size() / 3; }
  void add(const double c[3], const double half[3]) {
    for (int k = 0; k < 3; ++k) lo.push_back(c[k] - half[k]), hi.push_back(c[k] + half[k]);
  }
  bool contains(std::size_t q, const double* p) const {
    for (int k = 0; k < 3; ++k)
      if (p[k] < lo[3 * q + k] || p[k] > hi[3 * q + k]) return false;
    return true;
  }
};

// Boxes of ~2 mm on a 78 mm hemisphere (a formed dome), jittered.
Boxes dome(std::size_t n, std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Boxes b;
  const double r = 0.078;
  for (std::size_t q = 0; q < n; ++q) {
    const double phi = 2 * M_PI * u(rng), z = r * u(rng), rho = std::sqrt(r * r - z * z);
    const double c[3] = {rho * std::cos(phi), rho * std::sin(phi), z};
    const double half[3] = {1e-3 * (0.5 + u(rng)), 1e-3 * (0.5 + u(rng)), 4e-4 * (0.5 + u(rng))};
    b.add(c, half);
  }
  return b;
}

// Every point's bucket, filtered by containment, against brute force; each bucket strictly
// increasing (so no box twice).
void expect_exact(const Boxes& b, const std::vector<std::array<double, 3>>& points) {
  fem::BucketGrid grid;
  grid.build(b.size(), b.lo.data(), b.hi.data());
  std::size_t found = 0;
  for (const auto& p : points) {
    std::vector<std::int32_t> brute, listed;
    for (std::size_t q = 0; q < b.size(); ++q)
      if (b.contains(q, p.data())) brute.push_back(static_cast<std::int32_t>(q));
    std::int32_t begin = 0, end = 0;
    if (!grid.cell_of(p.data(), begin, end)) {
      EXPECT_TRUE(brute.empty()) << "a point inside a box is outside the grid";
      continue;
    }
    for (std::int32_t it = begin; it < end; ++it) {
      if (it > begin) {
        ASSERT_LT(grid.items()[it - 1], grid.items()[it]) << "cell not increasing";
      }
      const auto q = static_cast<std::size_t>(grid.items()[it]);
      if (b.contains(q, p.data())) listed.push_back(grid.items()[it]);
    }
    ASSERT_EQ(listed, brute);
    found += brute.size();
  }
  EXPECT_GT(found, points.size() / 2) << "the test points should mostly lie in boxes";
}

std::vector<std::array<double, 3>> points_in_boxes(const Boxes& b, std::size_t n,
                                                   std::mt19937& rng) {
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<std::array<double, 3>> pts;
  for (std::size_t i = 0; i < n; ++i) {
    const std::size_t q =
        static_cast<std::size_t>(u(rng) * static_cast<double>(b.size())) % b.size();
    std::array<double, 3> p;
    for (int k = 0; k < 3; ++k)
      p[k] = b.lo[3 * q + k] + u(rng) * (b.hi[3 * q + k] - b.lo[3 * q + k]);
    pts.push_back(p);
  }
  return pts;
}

}  // namespace

TEST(BucketGrid, BoxesOnADomeAreFoundExactlyAndInOrder) {
  std::mt19937 rng(7);
  const Boxes b = dome(20000, rng);
  expect_exact(b, points_in_boxes(b, 20000, rng));
}

TEST(BucketGrid, AFewHugeBoxesAmongSmallOnes) {
  std::mt19937 rng(11);
  Boxes b = dome(5000, rng);
  for (int i = 0; i < 5; ++i) {  // 40 times the mean size
    const double c[3] = {0.01 * i, 0.0, 0.04}, half[3] = {0.04, 0.04, 0.02};
    b.add(c, half);
  }
  expect_exact(b, points_in_boxes(b, 10000, rng));
}

TEST(BucketGrid, FlatBoxesAndPointsOutside) {
  Boxes b;
  for (int i = 0; i < 30; ++i)
    for (int j = 0; j < 30; ++j) {
      const double c[3] = {1e-3 * i, 1e-3 * j, 0.0}, half[3] = {6e-4, 6e-4, 0.0};  // z extent 0
      b.add(c, half);
    }
  std::mt19937 rng(3);
  expect_exact(b, points_in_boxes(b, 5000, rng));
  fem::BucketGrid grid;
  grid.build(b.size(), b.lo.data(), b.hi.data());
  std::int32_t begin = 0, end = 0;
  const double above[3] = {0.01, 0.01, 1e-3}, left[3] = {-0.01, 0.01, 0.0};
  EXPECT_FALSE(grid.cell_of(above, begin, end));
  EXPECT_FALSE(grid.cell_of(left, begin, end));
  fem::BucketGrid empty;
  empty.build(0, nullptr, nullptr);
  EXPECT_FALSE(empty.cell_of(above, begin, end));
}
