// Fabric measures on plain arrays: the inter-ply shear angle of two flat plies (0 for +-45 fibres,
// the imposed angle for rotated ones), the outer faces of hexahedra, element-to-node means.
#include <gtest/gtest.h>

#include <cmath>

#include "drape/fabric_measures.hpp"

namespace ncfsim {
namespace {

using fem::V3;

// Two plies of n x n element centroids, 2 mm apart in-plane, 0.25 mm apart through the thickness,
// with fibre directions at angle_a and angle_b (deg) to x.
struct TwoPlies {
  std::vector<V3> centroid, fibre;
  std::vector<std::int32_t> a, b;
};
TwoPlies two_plies(int n, double angle_a, double angle_b) {
  TwoPlies p;
  for (int ply = 0; ply < 2; ++ply)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const auto e = static_cast<std::int32_t>(p.centroid.size());
        // ply b shifted half a cell: its nearest element is never straight above
        p.centroid.push_back({2e-3 * i + ply * 0.7e-3, 2e-3 * j + ply * 0.4e-3, ply * 0.25e-3});
        const double t = (ply == 0 ? angle_a : angle_b) * M_PI / 180;
        p.fibre.push_back({std::cos(t), std::sin(t), 0});
        (ply == 0 ? p.a : p.b).push_back(e);
      }
  return p;
}

TEST(FabricMeasures, FlatPlusMinus45PliesHaveNoShear) {
  auto p = two_plies(10, 45, -45);
  std::vector<double> s(p.centroid.size(), -1);
  drape::interply_shear_deg(p.centroid, p.fibre, p.a, p.b, 3e-3, s);
  drape::interply_shear_deg(p.centroid, p.fibre, p.b, p.a, 3e-3, s);
  for (double v : s) EXPECT_NEAR(v, 0.0, 1e-9);
}

TEST(FabricMeasures, PliesRotatedTowardsEachOtherShearByTheRotation) {
  // +35 / -45: the fibres stand at 80 deg, a 10 deg shear; the sign of a fibre direction does
  // not matter (fibres are lines).
  auto p = two_plies(6, 35, 135);
  std::vector<double> s(p.centroid.size(), -1);
  drape::interply_shear_deg(p.centroid, p.fibre, p.a, p.b, 3e-3, s);
  for (auto e : p.a) EXPECT_NEAR(s[static_cast<std::size_t>(e)], 10.0, 1e-9);
  // Beyond the reach there is no partner: NaN, not a made-up value.
  drape::interply_shear_deg(p.centroid, p.fibre, p.a, p.b, 1e-4, s);
  for (auto e : p.a) EXPECT_TRUE(std::isnan(s[static_cast<std::size_t>(e)]));
}

TEST(FabricMeasures, OuterFacesOfTwoHexahedraLeaveTheSharedFaceOut) {
  // Two unit cubes side by side along x: nodes i + 3 j + 6 k.
  auto id = [](int i, int j, int k) { return static_cast<std::int32_t>(i + 3 * j + 6 * k); };
  std::vector<std::array<std::int32_t, 8>> conn;
  for (int i = 0; i < 2; ++i)
    conn.push_back({id(i, 0, 0), id(i + 1, 0, 0), id(i + 1, 1, 0), id(i, 1, 0), id(i, 0, 1),
                    id(i + 1, 0, 1), id(i + 1, 1, 1), id(i, 1, 1)});
  const auto tri = drape::outer_face_triangles(conn, {0, 1});
  EXPECT_EQ(tri.size(), 20u);  // 10 outer quads
  for (const auto& t : tri) {
    // no triangle lies in the shared plane x = 1 (nodes with i = 1 only)
    const bool all_mid = t[0] % 3 == 1 && t[1] % 3 == 1 && t[2] % 3 == 1;
    EXPECT_FALSE(all_mid);
  }
  const auto mean = drape::element_to_node_mean(conn, {0, 1}, {10.0, 20.0}, 12);
  EXPECT_DOUBLE_EQ(mean[static_cast<std::size_t>(id(0, 0, 0))], 10.0);
  EXPECT_DOUBLE_EQ(mean[static_cast<std::size_t>(id(1, 0, 0))], 15.0);
  EXPECT_DOUBLE_EQ(mean[static_cast<std::size_t>(id(2, 1, 1))], 20.0);
}

}  // namespace
}  // namespace ncfsim
