// Kinematic (pin-jointed net) drape against answers known without it: the net keeps its chord
// lengths and lies on the surface; zero shear along the generators; a cylinder draped with fibres
// along its axis and its hoop has zero shear everywhere; the four quadrants of a +-45 net on a
// sphere are equal; the ring measure converges as the net spacing halves.
#include <gtest/gtest.h>

#include <cmath>

#include "drape/kinematic_drape.hpp"
#include "drape/ring_measure.hpp"
#include "tests/test_support.hpp"

namespace ncfsim {
namespace {

using drape::DrapeSurface;
using drape::KinematicDrapeSpec;
using fem::V3;

constexpr double kR = 0.078;  // the paper's 156 mm punch

// A hemispherical punch of radius R standing with its equator on the plane z = 0.
DrapeSurface hemisphere_on_plane() {
  DrapeSurface s;
  fem::RigidSurface ball;
  ball.shape = fem::ToolShape::Sphere;
  ball.radius = kR;
  s.bodies.push_back(ball);
  fem::RigidSurface plane;
  plane.shape = fem::ToolShape::Plane;
  plane.axis = {0, 0, 1};
  s.bodies.push_back(plane);
  return s;
}

// A solid cylinder of radius r about `axis` through the origin.
DrapeSurface cylinder(V3 axis, double r) {
  DrapeSurface s;
  fem::RigidSurface cyl;
  cyl.shape = fem::ToolShape::Cylinder;
  cyl.axis = axis;
  cyl.radius = r;
  s.bodies.push_back(cyl);
  return s;
}

KinematicDrapeSpec pm45(double spacing, double reach) {
  KinematicDrapeSpec k;
  k.pole = {0, 0, kR + 0.01};
  const double c = std::sqrt(0.5);
  k.fibre1 = {c, c, 0};
  k.fibre2 = {c, -c, 0};
  k.spacing = spacing;
  k.half_nodes = static_cast<int>(std::ceil(reach / spacing));
  return k;
}

drape::QuadrantMaxima ring_maxima(const drape::KinematicNet& net, double height) {
  drape::RingSpec ring;
  ring.height = height;
  const auto samples = drape::ring_shear(net.x, net.triangles(), net.shear_deg, ring);
  for (const auto& s : samples) EXPECT_TRUE(s.hit) << "azimuth " << s.azimuth_deg;
  return drape::quadrant_maxima(samples);
}

TEST(KinematicDrape, NetOnAHemisphereKeepsItsChordsAndLiesOnTheSurface) {
  const auto surf = hemisphere_on_plane();
  const auto net = drape::kinematic_drape(surf, pm45(4e-3, 0.16));
  std::size_t edges = 0;
  for (int j = -net.n; j <= net.n; ++j)
    for (int i = -net.n; i <= net.n; ++i) {
      if (!net.has(i, j)) continue;
      double gap = 0;
      V3 nrm;
      ASSERT_TRUE(surf.gap_at(net.x[net.index(i, j)], gap, nrm));
      EXPECT_NEAR(gap, 0.0, 1e-12) << i << "," << j;
      for (auto [di, dj] : {std::pair{1, 0}, std::pair{0, 1}}) {
        if (!net.has(i + di, j + dj)) continue;
        ++edges;
        EXPECT_NEAR(norm(net.x[net.index(i + di, j + dj)] - net.x[net.index(i, j)]), 4e-3, 1e-11);
      }
    }
  EXPECT_GT(edges, 3000u);
}

TEST(KinematicDrape, NoShearAlongTheGeneratorsOfASphere) {
  const auto net = drape::kinematic_drape(hemisphere_on_plane(), pm45(2e-3, 0.1));
  for (int k = -net.n + 1; k < net.n; ++k) {
    ASSERT_TRUE(net.has(k, 0));
    EXPECT_NEAR(net.shear_deg[net.index(k, 0)], 0.0, 1e-6) << k;
    EXPECT_NEAR(net.shear_deg[net.index(0, k)], 0.0, 1e-6) << k;
  }
  // Off the generators a sphere does shear the net: most between them, near the equator.
  EXPECT_GT(net.shear_deg[net.index(30, 30)], 10.0);
}

TEST(KinematicDrape, CylinderWithAxialAndHoopFibresDoesNotShear) {
  const DrapeSurface surf = cylinder({1, 0, 0}, 0.05);
  KinematicDrapeSpec k;
  k.pole = {0, 0, 0.06};
  k.fibre1 = {1, 0, 0};  // along the axis
  k.fibre2 = {0, 1, 0};  // hoop
  k.spacing = 3e-3;
  k.half_nodes = 40;
  const auto net = drape::kinematic_drape(surf, k);
  EXPECT_EQ(net.n_locked, 0u);
  for (double s : net.shear_deg) EXPECT_NEAR(s, 0.0, 1e-6);
  // The hoop generator is a circle of the cylinder's radius.
  for (int j = -net.n; j <= net.n; ++j) {
    const V3 p = net.x[net.index(5, j)];
    EXPECT_NEAR(std::hypot(p.y, p.z), 0.05, 1e-12);
  }
}

TEST(KinematicDrape, FourQuadrantsOfAPlusMinus45NetOnASphereAreEqual) {
  const auto net = drape::kinematic_drape(hemisphere_on_plane(), pm45(2e-3, 0.16));
  const auto q = ring_maxima(net, 0.04);
  for (int k = 0; k < 4; ++k) {
    EXPECT_GT(q.samples[static_cast<std::size_t>(k)], 80);
    EXPECT_NEAR(q.max_shear_deg[static_cast<std::size_t>(k)], q.max_shear_deg[0], 0.05)
        << "q" << k + 1;
  }
  // +-45 fibres: the quadrant centres (0, 90, ... deg) lie midway between the generators, where
  // a sphere shears the net most.
  EXPECT_GT(q.max_shear_deg[0], 15.0);
  EXPECT_LT(q.max_shear_deg[0], 60.0);
}

TEST(KinematicDrape, RingShearConvergesAsTheSpacingHalves) {
  const auto surf = hemisphere_on_plane();
  double q[3];
  const double spacing[3] = {4e-3, 2e-3, 1e-3};
  for (int m = 0; m < 3; ++m)
    q[m] = ring_maxima(drape::kinematic_drape(surf, pm45(spacing[m], 0.15)), 0.04).max_shear_deg[0];
  const double d1 = std::abs(q[1] - q[0]), d2 = std::abs(q[2] - q[1]);
  EXPECT_LT(d2, 0.6 * d1 + 1e-3) << q[0] << " " << q[1] << " " << q[2];
  EXPECT_LT(d2, 0.5) << q[1] << " " << q[2];
}

TEST(KinematicDrape, ShearDependsOnTheAngularPositionNotTheRadius) {
  // Half the punch radius with half the spacing is the same net scaled: the ring at the same
  // height-to-radius ratio reads the same shear.
  auto at_radius = [](double R, double spacing) {
    DrapeSurface s;
    fem::RigidSurface ball;
    ball.shape = fem::ToolShape::Sphere;
    ball.radius = R;
    s.bodies.push_back(ball);
    auto k = pm45(spacing, 2.0 * R);
    k.pole = {0, 0, 2 * R};
    return ring_maxima(drape::kinematic_drape(s, k), 0.04 / 0.078 * R).max_shear_deg[0];
  };
  EXPECT_NEAR(at_radius(0.039, 1e-3), at_radius(0.078, 2e-3), 1e-6);
  EXPECT_NEAR(at_radius(0.039, 2e-3), at_radius(0.078, 2e-3),
              0.05);  // the cell size barely matters
}

TEST(RingMeasure, InterpolatesAFieldAroundACylinderAndTakesQuadrantMaxima) {
  // A vertical cylinder of radius 50 mm as a net of axial and hoop fibres; node value
  // 20 + 10 x / R: the ring reads 20 + 10 cos(azimuth) (to the chord error of the net).
  const DrapeSurface surf = cylinder({0, 0, 1}, 0.05);
  KinematicDrapeSpec k;
  k.pole = {0.06, 0, 0.03};
  k.fibre1 = {0, 0, 1};
  k.fibre2 = {0, 1, 0};
  k.spacing = 1e-3;
  k.half_nodes = 160;  // the hoop generator goes round (2 pi R = 314 mm)
  auto net = drape::kinematic_drape(surf, k);
  std::vector<double> value(net.x.size());
  for (std::size_t i = 0; i < value.size(); ++i) value[i] = 20 + 10 * net.x[i].x / 0.05;
  drape::RingSpec ring;
  ring.height = 0.03;
  const auto samples = drape::ring_shear(net.x, net.triangles(), value, ring);
  ASSERT_EQ(samples.size(), 360u);
  for (const auto& s : samples) {
    ASSERT_TRUE(s.hit) << s.azimuth_deg;
    EXPECT_NEAR(s.shear_deg, 20 + 10 * std::cos(s.azimuth_deg * M_PI / 180), 2e-3) << s.azimuth_deg;
    EXPECT_NEAR(std::hypot(s.point.x, s.point.y), 0.05, 1e-5);
    EXPECT_NEAR(s.point.z, 0.03, 1e-12);
  }
  const auto q = drape::quadrant_maxima(samples);
  EXPECT_NEAR(q.max_shear_deg[0], 30.0, 2e-3);
  EXPECT_NEAR(q.max_shear_deg[1], 20 + 10 * std::cos(M_PI / 4), 2e-3);
  EXPECT_NEAR(q.max_shear_deg[2], 20 + 10 * std::cos(3 * M_PI / 4), 2e-3);
  EXPECT_NEAR(q.max_shear_deg[3], 20 + 10 * std::cos(M_PI / 4), 2e-3);
  EXPECT_EQ(q.samples[0], 91);  // -45..45 deg, both boundaries
}

TEST(KinematicDrape, BadSpecNamesTheField) {
  auto k = pm45(0.0, 0.1);
  k.half_nodes = 10;
  EXPECT_THROW(
      {
        try {
          drape::kinematic_drape(hemisphere_on_plane(), k);
        } catch (const std::invalid_argument& e) {
          EXPECT_NE(std::string(e.what()).find("spacing"), std::string::npos);
          throw;
        }
      },
      std::invalid_argument);
}

}  // namespace
}  // namespace ncfsim
