// Stitch-to-tow connection: a stitch block joined to a clamped tow block by one connection and
// pulled at constant speed along the tow: the force rises with the connection stiffness, then stays
// at the sliding force (within 1 %); the energy dissipated equals F_s times the slip (within 1 %);
// the energy balance closes (< 1 %). Pulled across the tow it stays elastic past the sliding
// force, up to the transverse force. Turned rigidly with its tow it carries no force.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <map>
#include <utility>

#include "drape/fabric_generator.hpp"
#include "drape/stitch_connection.hpp"
#include "fem/solver.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

// A 1 mm stitch block pulled at 0.1 m/s along `dir` (unit, in x-y) from a clamped 1 mm tow block
// lying along x, joined by one connection of stiffness 2000 N/m and sliding force 0.5 N.
struct PulledJoint {
  fem::Model model;
  std::int32_t a = -1, b = -1;
  std::vector<std::int32_t> pulled;
};

void build_pulled_joint(PulledJoint& j, std::array<double, 3> dir, double transverse_force) {
  fem::Model& model = j.model;
  test::add_elastic_block(model, "tow", {0, 0, 0}, {1e-3, 1e-3, 1e-3}, {1, 1, 1}, 1000, 1e8, 0.3);
  test::add_elastic_block(model, "stitch", {2e-3, 0, 0}, {1e-3, 1e-3, 1e-3}, {1, 1, 1}, 1000, 1e8, 0.3);
  const auto tow_nodes = test::nodes_where(model.mesh, [](double x, double, double) { return x < 1.5e-3; });
  j.pulled = test::nodes_where(model.mesh, [](double x, double, double) { return x > 1.5e-3; });
  fem::FixedDofs clamp;
  clamp.name = "clamp";
  clamp.nodes = tow_nodes;
  model.fixed.push_back(clamp);
  fem::PrescribedVelocity pull;
  pull.name = "pull";
  pull.nodes = j.pulled;
  pull.dofs = {true, true, true};
  pull.velocity = {0.1 * dir[0], 0.1 * dir[1], 0.1 * dir[2]};
  pull.ramp_time = 1e-4;
  model.velocities.push_back(pull);
  auto node_at = [&](const std::vector<std::int32_t>& nodes, double x, double y) {
    for (auto i : nodes)
      if (std::abs(model.mesh.coords[3 * i] - x) < 1e-9 &&
          std::abs(model.mesh.coords[3 * i + 1] - y) < 1e-9 && model.mesh.coords[3 * i + 2] == 0)
        return i;
    return std::int32_t{-1};
  };
  // The stitch block's node at (2, 0, 0) mm joined to the tow's node at (1, 0, 0) mm; the tow runs
  // along x (its next node along it at the origin).
  j.a = node_at(j.pulled, 2e-3, 0);
  j.b = node_at(tow_nodes, 1e-3, 0);
  const std::int32_t along = node_at(tow_nodes, 0, 0);
  ASSERT_GE(j.a, 0);
  ASSERT_GE(j.b, 0);
  ASSERT_GE(along, 0);
  drape::StitchConnectionSettings s;
  s.sliding_force = 0.5;
  s.transverse_force = transverse_force;
  s.stiffness = 2000;  // N/m, below the stability cap (~3900 N/m here): slides after 0.25 mm
  model.contacts.push_back(std::make_unique<drape::StitchToTowConnection>(
      "stitch_tow", std::vector<drape::StitchConnection>{{j.a, j.b, along}}, s));
  model.time.end_time = 8e-3;  // 0.8 mm of pull
}

// Stitch node a at (1.2, 0.9, 0.1) mm over a tow hexahedron (1 x 1 x 0.2 mm below z = 0) whose
// top edge runs from its node b at (1, 0, 0) mm to c at the origin: nodes 0, 1, 2 = a, b, c.
fem::Mesh one_joint_mesh() {
  fem::Mesh mesh;
  mesh.coords = {1.2e-3, 0.9e-3, 0.1e-3, 1e-3, 0, 0, 0, 0, 0};
  for (double z : {-0.2e-3, 0.0})
    for (auto [x, y] :
         {std::pair{0.0, 0.0}, std::pair{1e-3, 0.0}, std::pair{1e-3, 1e-3}, std::pair{0.0, 1e-3}})
      if (!(z == 0 && y == 0)) mesh.coords.insert(mesh.coords.end(), {x, y, z});
  mesh.elements(fem::ElementKind::Hex8).add({3, 4, 5, 6, 2, 1, 7, 8}, 0);
  return mesh;
}

}  // namespace

TEST(StitchConnection, ElasticThenSlidingAlongTheTowAtTheSlidingForce) {
  PulledJoint j;
  build_pulled_joint(j, {1, 0, 0}, 0.0);
  fem::ExplicitSolver solver(j.model);
  const auto* conn = static_cast<const drape::StitchToTowConnection*>(solver.model().contacts[0].get());
  double f_at_01mm = 0;
  while (solver.time() < j.model.time.end_time) {
    solver.step([&] {
      const double u = test::node_coord(solver, j.a, 0) - 2e-3;
      if (f_at_01mm == 0 && u > 0.1e-3) f_at_01mm = solver.reaction_force(j.pulled).x;
    });
  }
  ASSERT_EQ(conn->stiffness(0), 2000.0);
  EXPECT_NEAR(f_at_01mm, 2000 * 0.1e-3, 0.02 * 0.2) << "elastic branch k u";
  const double F = solver.reaction_force(j.pulled).x;  // the puller holds the connection force
  EXPECT_NEAR(F, 0.5, 0.01 * 0.5) << "sliding force";
  const double u = test::node_coord(solver, j.a, 0) - 2e-3;
  const double slip = u - 0.5 / 2000;
  EXPECT_NEAR(conn->slip_length(0), slip, 0.01 * slip);
  EXPECT_NEAR(conn->friction_dissipation(), 0.5 * slip, 0.01 * 0.5 * slip);
  EXPECT_LT(solver.energy().error(), 0.01);
}

// Across the tow the yarn bears on the tow's side: elastic past the sliding force (k u at 0.4 mm,
// 0.8 N against F_s = 0.5 N), up to the transverse force F_t = 1 N, which it then holds and
// dissipates F_t times the slip (1 %).
TEST(StitchConnection, ElasticAcrossTheTowUpToTheTransverseForce) {
  PulledJoint j;
  build_pulled_joint(j, {0, 1, 0}, 1.0);
  fem::ExplicitSolver solver(j.model);
  const auto* conn =
      static_cast<const drape::StitchToTowConnection*>(solver.model().contacts[0].get());
  double f_at_04mm = 0;
  while (solver.time() < j.model.time.end_time)
    solver.step([&] {
      if (f_at_04mm == 0 && test::node_coord(solver, j.a, 1) > 0.4e-3)
        f_at_04mm = solver.reaction_force(j.pulled).y;
    });
  EXPECT_NEAR(f_at_04mm, 2000 * 0.4e-3, 0.01 * 0.8) << "elastic across the tow past F_s";
  const double u = test::node_coord(solver, j.a, 1);
  EXPECT_NEAR(solver.reaction_force(j.pulled).y, 1.0, 0.01) << "transverse force";
  const double slip = u - 1.0 / 2000;
  EXPECT_NEAR(conn->slip_length(0), slip, 0.01 * slip);
  EXPECT_NEAR(conn->friction_dissipation(), 1.0 * slip, 0.01 * slip);
  EXPECT_LT(solver.energy().error(), 0.01);
}

// The rest offset turns with the tow's axis: a stitch node and its tow turned rigidly by 50 deg
// about an axis square to the tow (0, 0.6, 0.8): turned in the ply, as in a sheared fabric, and
// out of it, as over a punch) carry no force (1e-9 of the force of an offset of 1 mm), and a
// slide along the turned tow is still a slide along it. (A twist about the tow's own axis is not
// followed: the joint resists the tow rolling under the stitch.)
TEST(StitchConnection, RestOffsetTurnsWithTheTow) {
  const fem::Mesh mesh =
      one_joint_mesh();  // a: stitch node; b: tow node; c: next along the tow (x)
  const std::vector<double> mass(mesh.coords.size(), 1e-6);
  drape::StitchConnectionSettings s;
  s.sliding_force = 0.5;
  s.stiffness = 1000;
  drape::StitchToTowConnection conn("joint", {{0, 1, 2}}, s);
  conn.initialise({&mesh, mesh.coords.data(), mass.data(), 1e-5});
  const double deg = M_PI / 180, th = 50 * deg, k[3] = {0, 0.6, 0.8};
  auto turned = [&](double shift_along) {  // Rodrigues: v cos + (k x v) sin + k (k.v)(1 - cos)
    std::vector<double> x(mesh.coords.size());
    for (std::size_t i = 0; i < mesh.n_nodes(); ++i) {
      const double v[3] = {mesh.coords[3 * i] + (i == 0 ? shift_along : 0.0),
                           mesh.coords[3 * i + 1],
                           mesh.coords[3 * i + 2]};  // the stitch node moves along the tow
      const double kxv[3] = {k[1] * v[2] - k[2] * v[1], k[2] * v[0] - k[0] * v[2],
                             k[0] * v[1] - k[1] * v[0]};
      const double kv = k[0] * v[0] + k[1] * v[1] + k[2] * v[2];
      for (std::size_t c = 0; c < 3; ++c)
        x[3 * i + c] = v[c] * std::cos(th) + kxv[c] * std::sin(th) + k[c] * kv * (1 - std::cos(th));
    }
    return x;
  };
  std::vector<double> f(mesh.coords.size(), 0.0);
  conn.add_forces(turned(0).data(), nullptr, nullptr, 1e-5, f.data());
  for (double c : f) EXPECT_NEAR(c, 0.0, 1e-9 * 1000 * 1e-3);
  EXPECT_EQ(conn.slip_length(0), 0.0);
  // Then 2 mm along the turned tow: it slides (2 mm - F_s / k) and holds F_s, along the tow
  // (x turned: (cos, 0.8 sin, -0.6 sin)).
  std::fill(f.begin(), f.end(), 0.0);
  conn.add_forces(turned(2e-3).data(), nullptr, nullptr, 1e-5, f.data());
  EXPECT_NEAR(conn.slip_length(0), 2e-3 - 0.5 / 1000, 1e-12);
  EXPECT_NEAR(std::hypot(f[0], f[1], f[2]), 0.5, 1e-9);
  EXPECT_NEAR(f[0], -0.5 * std::cos(th), 1e-9) << "the force on the stitch node is along the tow";
  EXPECT_NEAR(f[1], -0.5 * 0.8 * std::sin(th), 1e-9);
  EXPECT_NEAR(f[2], 0.5 * 0.6 * std::sin(th), 1e-9);
}

// A joint whose axis hexahedron is eroded is released: no force after it, however far the
// stitch node moves (that piece of tow is gone).
TEST(StitchConnection, ReleasedWhenItsAxisHexahedronIsEroded) {
  const fem::Mesh mesh = one_joint_mesh();
  const std::vector<double> mass(mesh.coords.size(), 1e-6);
  drape::StitchConnectionSettings s;
  s.stiffness = 1000;
  drape::StitchToTowConnection conn("joint", {{0, 1, 2}}, s);
  conn.initialise({&mesh, mesh.coords.data(), mass.data(), 1e-5});
  std::vector<double> x = mesh.coords, f(x.size(), 0.0);
  x[0] += 0.1e-3;
  conn.add_forces(x.data(), nullptr, nullptr, 1e-5, f.data());
  EXPECT_GT(std::abs(f[0]), 0.01);
  conn.erode({0});
  EXPECT_EQ(conn.released(), 1u);
  std::fill(f.begin(), f.end(), 0.0);
  x[0] += 0.1e-3;
  conn.add_forces(x.data(), nullptr, nullptr, 1e-5, f.data());
  for (double c : f) EXPECT_EQ(c, 0.0);
}

// The joints are conservative: their forces on the stitch nodes, the tow nodes and the nodes of the
// hexahedron that gives the tow's axis are minus the gradient of their energy sum k |d|^2 / 2
// (central differences, within 1e-6 of the largest force), and they sum to zero, for stitch nodes
// and a tow element moved and turned arbitrarily (elastic: limits far above the forces). Two
// joints share the hexahedron, set up from its edge in opposite directions (tow node b with axis
// node c, and c with b): they share its axis and its forces are summed before they are scattered.
// (Their moment is not zero: the offset turns by the smallest rotation from the tow's set-up axis,
// so a turn of the whole joint about that axis loads it, as a twist of the tow under the stitch
// does.)
TEST(StitchConnection, ForcesAreTheGradientOfTheSpringEnergy) {
  fem::Mesh mesh = one_joint_mesh();
  const auto a2 = static_cast<std::int32_t>(mesh.n_nodes());  // a second stitch node, over c
  mesh.coords.insert(mesh.coords.end(), {-0.3e-3, 0.4e-3, 0.15e-3});
  const std::vector<double> mass(mesh.coords.size(), 1e-6);
  drape::StitchConnectionSettings s;
  s.sliding_force = 1e6, s.transverse_force = 1e6, s.stiffness = 1000;
  drape::StitchToTowConnection conn("joint", {{0, 1, 2}, {a2, 2, 1}}, s);
  conn.initialise({&mesh, mesh.coords.data(), mass.data(), 1e-5});
  ASSERT_EQ(conn.axis_hexahedra(), 1u);
  // A deformed state: every node moved by up to 0.3 mm, not a rigid motion.
  const std::size_t nd = mesh.coords.size();
  std::vector<double> x(nd);
  for (std::size_t k = 0; k < nd; ++k)
    x[k] = mesh.coords[k] + 0.3e-3 * std::sin(1.7 * static_cast<double>(k) + 0.4);
  auto energy = [&](const std::vector<double>& at) {
    std::vector<double> f(nd, 0.0);
    conn.add_forces(at.data(), nullptr, nullptr, 1e-5, f.data());
    return 0.5 * (std::pow(conn.force_magnitude(0), 2) + std::pow(conn.force_magnitude(1), 2)) /
           1000;
  };
  std::vector<double> f(nd, 0.0);
  conn.add_forces(x.data(), nullptr, nullptr, 1e-5, f.data());
  double f_max = 0;
  for (double c : f) f_max = std::max(f_max, std::abs(c));
  ASSERT_GT(f_max, 0.1);
  const double h = 1e-9;
  for (std::size_t k = 0; k < nd; ++k) {
    std::vector<double> xp = x, xm = x;
    xp[k] += h, xm[k] -= h;
    EXPECT_NEAR(f[k], -(energy(xp) - energy(xm)) / (2 * h), 1e-6 * f_max) << "dof " << k;
  }
  for (std::size_t c = 0; c < 3; ++c) {
    double sum = 0;
    for (std::size_t i = 0; i < mesh.n_nodes(); ++i) sum += f[3 * i + c];
    EXPECT_NEAR(sum, 0.0, 1e-12 * f_max);
  }
}

// The stitch pins the two plies of a blanket to each other at its penetration points: a 20 x 20 mm
// +-45 blanket whose bottom ply is held while the top ply is pulled 20 um along x (tows stiff,
// no contact, so only the stitch couples the plies) is held back by the stitch nodes on the ply
// interface. Each is joined to n1 tows of the bottom ply (+45) and n2 of the top one (-45), which
// slide past it along their own directions only: the node follows neither ply and every joint
// slides by u / sqrt(2) along its tow, carrying F_s there, while the joints of the other ply hold
// that across their tows (elastic). Along x the node then holds (n1 + n2) F_s / sqrt(2) (the sum
// within 2 %), where joints sliding in any direction held min(n1, n2) F_s. The legs, tension-only
// bars across a ply, add only a second-order term (a tilt d over the ply thickness t stretches a
// leg by d^2 / 2t): with the leg from the top face to the bottom face alone the plies would slide
// over each other almost freely.
TEST(StitchConnection, StitchPinsThePliesToEachOther) {
  fem::Model model;
  drape::FabricSpec f;
  drape::BlanketSpec bl;
  bl.size = {0.02, 0.02};
  const drape::FabricModel fm = drape::generate_blanket(model.mesh, f, bl);
  model.parts.resize(model.mesh.part_names.size());
  model.materials.push_back(std::make_unique<fem::ElasticIsotropic>("tow", 1080, 1e9, 0.3));
  for (int p : fm.ply_parts)
    model.parts[static_cast<std::size_t>(p)] = {.material = 0};
  // A heavy yarn (100 x 76 dtex) lets the joints be stiff (their stiffness is capped by the stitch
  // node mass): they slide after ~0.1 um, well before the 20 um of pull.
  model.bar_laws.push_back(fem::BarForceLaw::linear("stitch", 2.0, true, 7.6e-4));
  for (int p : {fm.stitch_I_part, fm.stitch_Lambda_part, fm.stitch_leg_part}) {
    model.parts[static_cast<std::size_t>(p)].bar_law = 0;
  }
  std::vector<int> ply_of_node(model.mesh.n_nodes(), -1);
  for (std::size_t e = 0; e < model.mesh.n_elements(fem::ElementKind::Hex8); ++e)
    for (auto nd : model.mesh.elements(fem::ElementKind::Hex8).nodes(e))
      ply_of_node[static_cast<std::size_t>(nd)] =
          fm.ply_of_tow[static_cast<std::size_t>(fm.tow_of_hex[e])];
  fem::FixedDofs hold;
  hold.name = "bottom_ply";
  fem::PrescribedVelocity pull;
  pull.name = "top_ply";
  pull.dofs = {true, true, true};
  pull.velocity = {0.01, 0, 0};  // m/s: 20 um in 2 ms (+ half the ramp)
  pull.ramp_time = 5e-4;
  for (std::size_t i = 0; i < ply_of_node.size(); ++i) {
    if (ply_of_node[i] == 0) hold.nodes.push_back(static_cast<std::int32_t>(i));
    if (ply_of_node[i] == 1) pull.nodes.push_back(static_cast<std::int32_t>(i));
  }
  model.fixed.push_back(hold);
  model.velocities.push_back(pull);
  drape::StitchConnectionSettings s;
  s.sliding_force = 0.05;
  model.contacts.push_back(
      std::make_unique<drape::StitchToTowConnection>("stitch_tow", fm.connections, s));
  model.time.end_time = 2.25e-3;
  // What the interface nodes can hold once their joints slide.
  const double t = fm.tow_thickness;
  std::map<std::int32_t, std::array<int, 2>> per_ply;
  for (const auto& c : fm.connections)
    if (std::abs(model.mesh.coords[3 * static_cast<std::size_t>(c.stitch_node) + 2] - t) < 1e-9 * t)
      ++per_ply[c.stitch_node]
               [static_cast<std::size_t>(ply_of_node[static_cast<std::size_t>(c.tow_node)])];
  double holding = 0;
  for (const auto& [nd, n] : per_ply) holding += (n[0] + n[1]) * s.sliding_force / std::sqrt(2.0);
  ASSERT_GT(holding, 10 * s.sliding_force);

  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  const fem::V3 F = solver.reaction_force(pull.nodes);
  EXPECT_NEAR(F.x, holding, 0.02 * holding) << "the top ply is held by the interface joints";
  EXPECT_LT(solver.energy().error(), 0.01);
}
