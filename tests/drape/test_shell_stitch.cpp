// The stitch of a macro fabric as bars sewn onto shells (drape/shell_stitch.hpp) and the slider
// that sews it (drape/shell_stitch_connection.hpp):
// - the lines cover the part: their count times their spacing is its width, each stitch node lies
//   on its host shell (bilinear weights summing to 1 reproduce its position), lines at 45 deg
//   over a square end on its outline, their length times their spacing is its area;
// - a curved part or a direction normal to it is bad input;
// - the slider is a Coulomb slider along the line: below the sliding force the spring is elastic
//   (f = -k u), above it the force stays at F_s, the slip is u - F_s / k and the work F_s x slip;
//   across the line it stays elastic; its forces sum to zero; the anchor moves with the material
//   (a stretched host carries the slipped anchor to the stretched material point).
#include <gtest/gtest.h>

#include <cmath>

#include "drape/shell_stitch.hpp"
#include "drape/shell_stitch_connection.hpp"
#include "fem/errors.hpp"

using namespace ncfsim;

namespace {

// A flat plate of nx x ny quadrilaterals (part 0) over [0, a] x [0, b] at z = 0.
fem::Mesh plate(double a, double b, int nx, int ny) {
  fem::Mesh m;
  m.add_part("fabric");
  m.add_part("stitch");
  for (int j = 0; j <= ny; ++j)
    for (int i = 0; i <= nx; ++i) m.coords.insert(m.coords.end(), {a * i / nx, b * j / ny, 0.0});
  auto id = [&](int i, int j) { return static_cast<std::int32_t>(i + (nx + 1) * j); };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i)
      m.elements(fem::ElementKind::Quad4)
          .add({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}, 0);
  return m;
}

drape::ShellStitchSpec spec(std::array<double, 3> dir, double spacing, double step) {
  drape::ShellStitchSpec s;
  s.shell_part = 0;
  s.direction = dir;
  s.gauge = 5e-3;
  s.stitch_length = 5e-3;
  s.line_spacing = spacing;
  s.point_spacing = step;
  return s;
}

// Every stitch node is the point its weights give on its host.
void expect_sewn_on_host(const fem::Mesh& m, const drape::ShellStitchModel& st) {
  for (const auto& l : st.links) {
    double wsum = 0, p[3] = {0, 0, 0};
    for (int k = 0; k < 4; ++k) {
      wsum += l.weight[k];
      EXPECT_GE(l.weight[k], -1e-12);
      for (int d = 0; d < 3; ++d)
        p[d] += l.weight[k] * m.node(static_cast<std::size_t>(l.host[k]))[d];
    }
    EXPECT_NEAR(wsum, 1.0, 1e-12);
    for (int d = 0; d < 3; ++d)
      EXPECT_NEAR(p[d], m.node(static_cast<std::size_t>(l.stitch_node))[d], 1e-15);
  }
}

TEST(ShellStitch, LinesAlongXCoverThePlateAndSitOnTheirShells) {
  fem::Mesh m = plate(20e-3, 10e-3, 8, 4);
  const std::size_t n0 = m.n_nodes();
  const auto st = drape::sew_shell_stitch(m, spec({1, 0, 0}, 2.5e-3, 2.5e-3), 1, "f.toml",
                                          "mesh.shell_stitch[0]");
  EXPECT_EQ(st.n_lines, 4u);  // 10 mm / 2.5 mm, at y = 1.25, 3.75, 6.25, 8.75 mm
  EXPECT_NEAR(st.line_spacing, 2.5e-3, 1e-15);
  EXPECT_NEAR(st.pillar_share, 0.5, 1e-12);        // 2.5 mm of 5 mm gauge
  // Each interior node stands for 2.5 / 5 of a line of pillars and 2.5 / 5 of a stitch length;
  // the lines' ends for half that: 4 lines of 20 mm, 0.5 pillar each, a penetration per 5 mm.
  EXPECT_NEAR(st.penetrations, 4 * 0.5 * 20.0 / 5.0, 1e-12);
  ASSERT_EQ(st.links.size(), 4u * 9);
  EXPECT_EQ(m.n_nodes(), n0 + st.links.size());
  EXPECT_EQ(m.elements(fem::ElementKind::Bar2).size(), 4u * 8);
  int ends = 0;
  for (const auto& l : st.links) {
    const auto x = m.node(static_cast<std::size_t>(l.stitch_node));
    const double y = x[1] * 1e3;
    EXPECT_NEAR(y - 1.25 - 2.5 * std::round((y - 1.25) / 2.5), 0.0, 1e-9);
    if (l.prev < 0 || l.next < 0) {
      ++ends;
      EXPECT_TRUE(std::abs(x[0]) < 1e-15 || std::abs(x[0] - 20e-3) < 1e-15);
    }
  }
  EXPECT_EQ(ends, 8);
  expect_sewn_on_host(m, st);
}

TEST(ShellStitch, DiagonalLinesEndOnTheOutlineAndFillTheArea) {
  fem::Mesh m = plate(10e-3, 10e-3, 6, 6);
  const auto st = drape::sew_shell_stitch(m, spec({1, 1, 0}, 1e-3, 1e-3), 1, "f.toml", "k");
  double length = 0;
  for (const auto& l : st.links) {
    const auto x = m.node(static_cast<std::size_t>(l.stitch_node));
    if (l.prev < 0 || l.next < 0) {
      const bool on_outline = std::min({std::abs(x[0]), std::abs(x[1]), std::abs(x[0] - 10e-3),
                                        std::abs(x[1] - 10e-3)}) < 1e-12;
      EXPECT_TRUE(on_outline) << x[0] << ", " << x[1];
    }
    if (l.next >= 0) {
      const auto y = m.node(static_cast<std::size_t>(l.next));
      length += std::hypot(y[0] - x[0], y[1] - x[1]);
    }
  }
  // The lines at mid-strip sample the square: length x spacing = area within the strips' ends.
  EXPECT_NEAR(length * st.line_spacing, 1e-4, 0.02 * 1e-4);
  expect_sewn_on_host(m, st);
}

TEST(ShellStitch, CurvedPartOrNormalDirectionIsBadInput) {
  fem::Mesh m = plate(10e-3, 10e-3, 2, 2);
  EXPECT_THROW(drape::sew_shell_stitch(m, spec({0, 0, 1}, 1e-3, 1e-3), 1, "f.toml", "k"),
               InputError);
  m.coords[3 * 4 + 2] = 1e-3;  // the middle node lifted
  try {
    drape::sew_shell_stitch(m, spec({1, 0, 0}, 1e-3, 1e-3), 1, "f.toml", "mesh.shell_stitch[0]");
    FAIL() << "a curved part was accepted";
  } catch (const InputError& e) {
    EXPECT_EQ(e.key(), "mesh.shell_stitch[0].part");
    EXPECT_NE(std::string(e.what()).find("flat"), std::string::npos) << e.what();
  }
}

// One line of three stitch nodes at y = 0.5 mm over two 1 mm shells, every mass 1e-6 kg, step
// 1e-6 s: k = 0.1 m / dt^2 = 1e5 N/m; gauge and stitch length 1 mm, so the middle node stands for
// one penetration: sliding force 0.01 N (slides past 0.1 um).
struct OneLine {
  fem::Mesh mesh = plate(2e-3, 1e-3, 2, 1);
  drape::ShellStitchModel st;
  std::vector<double> x0, mass;
  std::unique_ptr<drape::StitchToShellConnection> c;
  std::size_t mid = 0;  // the middle link
  OneLine() {
    auto sp = spec({1, 0, 0}, 1e-3, 1e-3);
    sp.gauge = sp.stitch_length = 1e-3;
    st = drape::sew_shell_stitch(mesh, sp, 1, "f.toml", "k");
    x0 = mesh.coords;
    mass.assign(x0.size(), 1e-6);
    drape::ShellStitchSliderSettings s;
    s.sliding_force = 0.01;
    c = std::make_unique<drape::StitchToShellConnection>("line", st.links, s);
    fem::ContactSetup setup;
    setup.mesh = &mesh, setup.x0 = x0.data(), setup.mass = mass.data(), setup.dt = 1e-6;
    c->initialise(setup);
    for (std::size_t i = 0; i < st.links.size(); ++i)
      if (st.links[i].prev >= 0 && st.links[i].next >= 0) mid = i;
    EXPECT_NEAR(st.links[mid].penetrations, 1.0, 1e-12);
  }
  // Forces at positions x; checks that they sum to zero.
  std::vector<double> forces(const std::vector<double>& x) {
    std::vector<double> f(x.size(), 0.0);
    c->add_forces(x.data(), nullptr, mass.data(), 1e-6, f.data());
    for (int d = 0; d < 3; ++d) {
      double s = 0, mag = 0;
      for (std::size_t i = d; i < f.size(); i += 3) s += f[i], mag += std::abs(f[i]);
      EXPECT_LE(std::abs(s), 1e-12 * (1 + mag));
    }
    return f;
  }
  std::size_t a() const { return 3 * static_cast<std::size_t>(st.links[mid].stitch_node); }
};

TEST(StitchToShellConnection, ElasticBelowTheSlidingForceThenCoulombAlongTheLine) {
  OneLine t;
  ASSERT_EQ(t.st.links.size(), 3u);
  EXPECT_NEAR(t.c->stiffness(t.mid), 1e5, 1e-6);
  std::vector<double> x = t.x0;
  x[t.a()] += 0.05e-6;  // k u = 0.005 N < F_s
  auto f = t.forces(x);
  EXPECT_NEAR(f[t.a()], -0.005, 1e-12);
  EXPECT_EQ(t.c->slip(t.mid), 0.0);
  x[t.a()] = t.x0[t.a()] + 0.3e-6;  // k u = 0.03 N > F_s: slides by 0.2 um
  f = t.forces(x);
  EXPECT_NEAR(f[t.a()], -0.01, 1e-12);
  EXPECT_NEAR(t.c->slip(t.mid), 0.2e-6, 1e-15);
  EXPECT_NEAR(t.c->friction_dissipation(), 0.01 * 0.2e-6, 1e-16);
  // Across the line: elastic however far (the stitch stays on its row).
  std::vector<double> y = t.x0;
  y[t.a()] = t.x0[t.a()] + t.c->slip(t.mid);  // at the slipped anchor along the line
  y[t.a() + 1] += 0.3e-6;
  f = t.forces(y);
  EXPECT_NEAR(f[t.a() + 1], -0.03, 1e-12);
  EXPECT_NEAR(f[t.a()], 0.0, 1e-12);
  EXPECT_NEAR(t.c->slip(t.mid), 0.2e-6, 1e-15);
}

TEST(StitchToShellConnection, TheSlippedAnchorMovesWithTheStretchedFabric) {
  OneLine t;
  std::vector<double> x = t.x0;
  x[t.a()] += 0.3e-6;
  t.forces(x);  // slips 0.2 um along +x
  const double s = t.c->slip(t.mid);
  // Stretch everything by 10 % along x: the anchor is the material point X + s, now at
  // 1.1 (X + s); the stitch node placed half the stick limit beyond it feels 0.005 N back.
  std::vector<double> y = t.x0;
  for (std::size_t i = 0; i < y.size(); i += 3) y[i] *= 1.1;
  y[t.a()] = 1.1 * (t.x0[t.a()] + s) + 0.05e-6;
  const auto f = t.forces(y);
  EXPECT_NEAR(f[t.a()], -0.005, 1e-9);
  EXPECT_NEAR(t.c->slip(t.mid), s, 1e-15);
}

}  // namespace
