// Proximity cull of rigid-tool contact: testing only the nodes that were within the margin at
// the last rebuild must give the same forces as testing every contact node, cycle by cycle, to
// the last bit (the cull only skips nodes whose force is zero), while a cloud of nodes swirls
// through a moving sphere and a plate with a hole; and the cull must actually skip nodes.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "fem/rigid_tool.hpp"

using namespace ncfsim::fem;

namespace {

struct Cloud {
  std::vector<double> x0, x, v, m;
};

// n nodes on a 30 x 30 mm grid in z = 0, each moving on its own circle (radius 3 mm) so that
// nodes move in and out of the tools' reach.
Cloud make_cloud(int side) {
  Cloud c;
  for (int j = 0; j < side; ++j)
    for (int i = 0; i < side; ++i) {
      const double px = -0.015 + 0.03 * i / (side - 1), py = -0.015 + 0.03 * j / (side - 1);
      c.x0.insert(c.x0.end(), {px, py, 0.0});
    }
  c.x = c.x0;
  c.v.assign(c.x.size(), 0.0);
  c.m.assign(c.x.size(), 1e-4);
  return c;
}

void move_cloud(Cloud& c, double t) {
  const std::size_t n = c.x.size() / 3;
  for (std::size_t k = 0; k < n; ++k) {
    const double w = 200.0 + 7.0 * static_cast<double>(k % 13), ph = 0.37 * static_cast<double>(k);
    const double r = 0.003;
    c.x[3 * k] = c.x0[3 * k] + r * std::cos(w * t + ph);
    c.x[3 * k + 1] = c.x0[3 * k + 1] + r * std::sin(w * t + ph);
    c.x[3 * k + 2] = c.x0[3 * k + 2] + 0.5 * r * std::sin(1.3 * w * t + ph);
    c.v[3 * k] = -r * w * std::sin(w * t + ph);
    c.v[3 * k + 1] = r * w * std::cos(w * t + ph);
    c.v[3 * k + 2] = 0.65 * r * w * std::cos(1.3 * w * t + ph);
  }
}

RigidTool rising_sphere() {
  RigidTool t;
  t.name = "punch";
  t.surface.shape = ToolShape::Sphere;
  t.surface.point = {0.002, -0.001, -0.012};
  t.surface.radius = 0.01;
  t.motion.kind = ToolMotion::Kind::Velocity;
  t.friction = 0.2;
  return t;
}

RigidTool holed_plate() {
  RigidTool t;
  t.name = "die";
  t.surface.shape = ToolShape::PlaneWithHole;
  t.surface.point = {0, 0, 0.0005};
  t.surface.axis = {0, 0, -1};
  t.surface.radius = 0.008;
  t.friction = 0.3;
  t.thickness = 2e-4;
  return t;
}

}  // namespace

TEST(RigidToolCull, SameForcesAsTestingEveryNode) {
  for (const bool sphere : {true, false}) {
    Cloud c = make_cloud(41);
    const std::size_t n = c.x.size() / 3;
    RigidTool culled = sphere ? rising_sphere() : holed_plate();
    for (std::size_t k = 0; k < n; ++k)
      culled.contact_nodes.push_back(static_cast<std::int32_t>(k));
    culled.search_margin = 1e-3;
    RigidTool full = culled;
    full.search_margin = 1.0;  // every node always near: the uncull reference
    const double dt = 2e-6;
    std::int64_t active_sum = 0;
    std::size_t near_min = n;
    for (int cycle = 0; cycle < 4000; ++cycle) {
      const double t = cycle * dt;
      move_cloud(c, t);
      for (RigidTool* tool : {&culled, &full}) {
        tool->displacement = {0, 0, sphere ? 2.0 * t : 0.0};
        tool->velocity = {0, 0, sphere ? 2.0 : 0.0};
      }
      std::vector<double> f_cull(3 * n, 0.0), f_full(3 * n, 0.0);
      tool_contact_forces(culled, c.x.data(), c.v.data(), c.m.data(), dt, f_cull.data());
      tool_contact_forces(full, c.x.data(), c.v.data(), c.m.data(), dt, f_full.data());
      ASSERT_EQ(f_cull, f_full) << "cycle " << cycle;
      ASSERT_EQ(culled.force.x, full.force.x);
      ASSERT_EQ(culled.force.z, full.force.z);
      ASSERT_EQ(culled.n_active, full.n_active);
      ASSERT_EQ(culled.friction_dissipation, full.friction_dissipation);
      active_sum += culled.n_active;
      near_min = std::min(near_min, culled.proximity.near.size());
    }
    EXPECT_GT(active_sum, 10000) << "the tool must touch the cloud";
    EXPECT_GT(culled.proximity.n_rebuilds, 3) << "the cloud moves past the margin: rebuilds";
    EXPECT_LT(culled.proximity.n_rebuilds, 1000) << "most cycles reuse the near list";
    // The plate reaches most of the cloud; the nodes deep in its hole or below it are skipped.
    EXPECT_LT(near_min, sphere ? n / 2 : 3 * n / 4) << "the cull must skip nodes";
    EXPECT_EQ(full.proximity.n_rebuilds, 1);
  }
}
