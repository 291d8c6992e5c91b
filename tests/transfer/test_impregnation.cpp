// Transfer mapping on plain arrays: a flat, undeformed +-45 blanket maps to fibre axes at exactly
// +-45 deg with orthonormal frames; a uniformly sheared one to the sheared directions; a tow
// compressed to 90 % of its cross-section has its Vf raised by 1/0.9; the trilinear volume is
// exact.
#include <gtest/gtest.h>

#include <cmath>

#include "tests/test_support.hpp"
#include "transfer/impregnation.hpp"

namespace ncfsim {
namespace {

using fem::V3;

// One hexahedron per fibre angle, unit-ish boxes side by side, VTK order.
transfer::DrapedTows boxes(const std::vector<double>& angles_deg, double height = 0.23e-3) {
  transfer::DrapedTows t;
  for (std::size_t e = 0; e < angles_deg.size(); ++e) {
    const double x0 = 2e-3 * static_cast<double>(e);
    const auto base = static_cast<std::int32_t>(t.reference.size());
    for (double z : {0.0, height})
      for (auto [x, y] : {std::pair{0.0, 0.0}, {1e-3, 0.0}, {1e-3, 1e-3}, {0.0, 1e-3}})
        t.reference.push_back({x0 + x, y, z});
    t.hex.push_back({base, base + 1, base + 2, base + 3, base + 4, base + 5, base + 6, base + 7});
    const double a = angles_deg[e] * M_PI / 180;
    t.fibre.push_back({std::cos(a), std::sin(a), 0});
  }
  t.current = t.reference;
  return t;
}

void expect_orthonormal(const std::array<double, 9>& R) {
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      double d = 0;
      for (int k = 0; k < 3; ++k)
        d += R[static_cast<std::size_t>(3 * k + i)] * R[static_cast<std::size_t>(3 * k + j)];
      EXPECT_NEAR(d, i == j ? 1.0 : 0.0, 1e-14);
    }
  // right-handed
  const V3 a1{R[0], R[3], R[6]}, a2{R[1], R[4], R[7]}, a3{R[2], R[5], R[8]};
  EXPECT_NEAR(dot(cross(a1, a2), a3), 1.0, 1e-14);
}

TEST(Impregnation, FlatPlusMinus45BlanketMapsToExactly45Degrees) {
  const auto t = boxes({45.0, -45.0});
  const auto m = transfer::map_impregnated(t, {});
  for (std::size_t e = 0; e < 2; ++e) {
    expect_orthonormal(m.frame[e]);
    const double angle = std::atan2(m.frame[e][3], m.frame[e][0]) * 180 / M_PI;
    EXPECT_DOUBLE_EQ(angle, e == 0 ? 45.0 : -45.0);
    EXPECT_NEAR(m.frame[e][8], 1.0, 1e-15);  // axis 3 through the thickness (z)
    EXPECT_NEAR(m.volume_ratio[e], 1.0, 1e-12);
    EXPECT_NEAR(m.vf[e], 0.6, 1e-12);
  }
  EXPECT_EQ(m.class_vf.size(), 1u);
}

TEST(Impregnation, UniformlyShearedBlanketMapsToTheShearedDirections) {
  // Simple shear x += g y: a fibre a0 convects to F a0 = (a0x + g a0y, a0y, 0).
  auto t = boxes({45.0, -45.0});
  const double g = 0.3;
  for (auto& p : t.current) p.x += g * p.y;
  for (auto& f : t.fibre) f = {f.x + g * f.y, f.y, 0};
  const auto m = transfer::map_impregnated(t, {});
  for (std::size_t e = 0; e < 2; ++e) {
    expect_orthonormal(m.frame[e]);
    const V3 want = normalized(t.fibre[e]);
    EXPECT_NEAR(m.frame[e][0], want.x, 1e-14);
    EXPECT_NEAR(m.frame[e][3], want.y, 1e-14);
    EXPECT_NEAR(m.volume_ratio[e], 1.0, 1e-12);  // simple shear keeps the volume
  }
}

TEST(Impregnation, CompactedTowGainsFibreVolumeFractionAndIsCappedAtLocking) {
  auto t = boxes({0.0, 0.0});
  // element 0: cross-section to 90 % (across the fibre, y); element 1: to 60 % (past locking)
  for (std::size_t i = 0; i < 8; ++i) t.current[i].y *= 0.9;
  for (std::size_t i = 8; i < 16; ++i) t.current[i].y *= 0.6;
  transfer::MappingSpec spec;
  const auto m = transfer::map_impregnated(t, spec);
  EXPECT_NEAR(m.volume_ratio[0], 0.9, 1e-12);
  EXPECT_NEAR(m.vf[0], 0.6 / 0.9, 1e-12);
  EXPECT_NEAR(m.class_vf[static_cast<std::size_t>(m.vf_class[0])], 0.6 / 0.9, spec.vf_bin / 2);
  EXPECT_DOUBLE_EQ(m.vf[1], spec.vf_locking);
  EXPECT_EQ(m.n_capped, 1u);
  EXPECT_EQ(m.n_floored, 0u);
}

// A tow the drape spread (cross-section to 125 %) keeps its nominal Vf: the infusion's vacuum bag
// presses it back; counted.
TEST(Impregnation, SpreadTowKeepsItsNominalFibreVolumeFraction) {
  auto t = boxes({0.0, 0.0});
  for (std::size_t i = 0; i < 8; ++i) t.current[i].y *= 1.25;
  transfer::MappingSpec spec;
  const auto m = transfer::map_impregnated(t, spec);
  EXPECT_NEAR(m.volume_ratio[0], 1.25, 1e-12);
  EXPECT_DOUBLE_EQ(m.vf[0], spec.vf_undeformed);
  EXPECT_EQ(m.n_floored, 1u);
}

TEST(Impregnation, TrilinearVolumeIsExact) {
  std::array<V3, 8> x{V3{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0},
                      {0, 0, 1},   {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
  EXPECT_NEAR(transfer::hex_volume(x), 1.0, 1e-14);
  x[6].z += 0.4;  // a warped top face: mean height 1 + 0.4 / 4
  EXPECT_NEAR(transfer::hex_volume(x), 1.1, 1e-14);
}

TEST(Impregnation, InvertedElementIsReportedByNumber) {
  auto t = boxes({0.0, 0.0});
  for (std::size_t i = 12; i < 16; ++i) t.current[i].z = -1e-3;  // element 2's top below its bottom
  try {
    transfer::map_impregnated(t, {});
    FAIL() << "an inverted hexahedron was mapped";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("hexahedron 2"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace ncfsim
