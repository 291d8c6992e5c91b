// Four-node Belytschko-Tsay shells against analytic solutions: the membrane patch test, a
// cantilever strip in bending (Euler-Bernoulli), energy conservation of a free vibration, and
// Coulomb friction of a shell pressed on a rigid plane and pulled.
#include "fem/elements/shell4_block.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kE = 200e9, kNu = 0.3, kRho = 7850;

// A flat plate of na x nb shells in the x-y plane, elastic isotropic, thickness t.
int add_plate(fem::Model& model, double a, double b, int na, int nb, double t, int ip = 2) {
  const int p = model.mesh.add_part("plate");
  const auto first = static_cast<std::int32_t>(model.mesh.n_nodes());
  for (int j = 0; j <= nb; ++j)
    for (int i = 0; i <= na; ++i)
      for (double c : {a * i / na, b * j / nb, 0.0}) model.mesh.coords.push_back(c);
  auto id = [&](int i, int j) { return first + i + (na + 1) * j; };
  auto& shells = model.mesh.elements(fem::ElementKind::Quad4);
  for (int j = 0; j < nb; ++j)
    for (int i = 0; i < na; ++i)
      shells.add({id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)}, p);
  model.materials.push_back(std::make_unique<fem::ElasticIsotropic>("steel", kRho, kE, kNu));
  model.parts.resize(static_cast<std::size_t>(p) + 1);
  auto& pp = model.parts[static_cast<std::size_t>(p)];
  pp.material = static_cast<int>(model.materials.size()) - 1;
  pp.shell_thickness = t;
  pp.shell_integration_points = ip;
  pp.hourglass_stiffness = 0.1;
  return p;
}

}  // namespace

// Patch test: a patch of four distorted shells whose boundary nodes follow a uniform membrane
// strain field (eps_xx, eps_yy, gamma_xy) slowly, with the interior node free: the interior
// node settles on the same linear field and every shell carries the uniform plane-stress
// membrane force N = t Q eps (to 0.1 %), whatever the distortion.
TEST(Shell4, MembranePatchTestIsPassedByDistortedShells) {
  fem::Model model;
  const double t = 0.001;
  const int p = model.mesh.add_part("patch");
  // 3 x 3 nodes, the centre one off-centre.
  model.mesh.coords = {0, 0,   0,     0.05, 0, 0,   0.1, 0,     0,   0, 0.05, 0,   0.06, 0.04,
                       0, 0.1, 0.052, 0,    0, 0.1, 0,   0.045, 0.1, 0, 0.1,  0.1, 0};
  auto& shells = model.mesh.elements(fem::ElementKind::Quad4);
  shells.add({0, 1, 4, 3}, p);
  shells.add({1, 2, 5, 4}, p);
  shells.add({3, 4, 7, 6}, p);
  shells.add({4, 5, 8, 7}, p);
  model.materials.push_back(std::make_unique<fem::ElasticIsotropic>("steel", kRho, kE, kNu));
  model.parts.resize(1);
  model.parts[0].material = 0;
  model.parts[0].shell_thickness = t;
  // Boundary nodes move with the rate field L = [[a, c], [0, b]]: one velocity set per node.
  const double rate = 1.0, T = 2e-3;  // strains ~ 1e-3 at the end
  const double La = 1.0 * rate, Lb = -0.4 * rate, Lc = 0.6 * rate;
  for (int node : {0, 1, 2, 3, 5, 6, 7, 8}) {
    const double x = model.mesh.coords[3 * node], y = model.mesh.coords[3 * node + 1];
    fem::PrescribedVelocity pv{"edge", {node}, {true, true, true}, {La * x + Lc * y, Lb * y, 0.0},
                               0.0,    0.0};
    model.velocities.push_back(pv);
  }
  model.mass_damping = 2e4;  // settles the free node far faster than the run
  model.time.end_time = T;
  fem::ExplicitSolver solver(model);
  // Stop the drive at T/2 and let the free node settle.
  while (solver.time() < T / 2) solver.step();
  for (auto& v : model.velocities) v.velocity = {0, 0, 0};
  while (solver.time() < T) solver.step();

  // Displacement gradient H = L T/2 as it ends (to second order: the motion is x' = x + L x dt
  // applied in steps, so the end field is exp(L T/2) x; take it from the corner nodes).
  const double* X0 = model.mesh.coords.data();
  auto X = solver.x.view();
  const double H11 = (X[3 * 2] - X0[3 * 2]) / 0.1, H22 = (X[3 * 6 + 1] - X0[3 * 6 + 1]) / 0.1;
  const double H12 = (X[3 * 6] - X0[3 * 6]) / 0.1;
  const double ux = H11 * X0[12] + H12 * X0[13], uy = H22 * X0[13];
  EXPECT_NEAR(X[12] - X0[12], ux, 1e-3 * std::abs(ux) + 1e-9);
  EXPECT_NEAR(X[13] - X0[13], uy, 1e-3 * std::abs(uy) + 1e-9);
  // Green-Lagrange strain of F = I + H, then S = Q E t, pushed forward.
  const double F[4] = {1 + H11, H12, 0, 1 + H22};
  const double E11 = 0.5 * (F[0] * F[0] + F[2] * F[2] - 1),
               E22 = 0.5 * (F[1] * F[1] + F[3] * F[3] - 1), E12 = 0.5 * (F[0] * F[1] + F[2] * F[3]);
  const double Q11 = kE / (1 - kNu * kNu);
  const double S11 = t * Q11 * (E11 + kNu * E22), S22 = t * Q11 * (E22 + kNu * E11),
               S12 = t * kE / (1 + kNu) * E12;
  // Cauchy membrane force N = F S F^T / J in global axes.
  const double J = F[0] * F[3] - F[1] * F[2];
  const double a11 = F[0] * S11 + F[1] * S12, a12 = F[0] * S12 + F[1] * S22;
  const double a21 = F[2] * S11 + F[3] * S12, a22 = F[2] * S12 + F[3] * S22;
  const double Nxx = (a11 * F[0] + a12 * F[1]) / J, Nyy = (a21 * F[2] + a22 * F[3]) / J,
               Nxy = (a11 * F[2] + a12 * F[3]) / J;
  const auto& b = solver.blocks<fem::Shell4Block>().at(0);
  std::vector<double> N(6 * b.n);
  fem::shell4_output_fields(b, X.data(), nullptr, N.data(), nullptr, nullptr);
  for (std::size_t e = 0; e < 4; ++e) {
    const double tol = 1e-3 * std::abs(Nxx);
    EXPECT_NEAR(N[6 * e], Nxx, tol) << "shell " << e;
    EXPECT_NEAR(N[6 * e + 1], Nyy, tol) << "shell " << e;
    EXPECT_NEAR(N[6 * e + 3], Nxy, tol) << "shell " << e;
  }
}

namespace {

struct StripRun {
  double tip, analytic, balance, hourglass_share;
};

// The cantilever strip of the bending tests: 200 x 20 x 2 mm steel, na x nb shells, clamped at
// x = 0 (translations and rotations), tip load P = 5 N in -z ramped over 20 ms, mass damping at
// twice its first bending frequency (critical for mode 1). Returns that frequency (rad/s).
constexpr double kStripL = 0.2, kStripW = 0.02, kStripT = 0.002, kStripP = 5.0;

double clamped_strip(fem::Model& model, int na, int nb, int ip) {
  add_plate(model, kStripL, kStripW, na, nb, kStripT, ip);
  fem::FixedDofs root;
  root.nodes = test::nodes_at(model.mesh, 0, 0.0);
  root.rotations = {true, true, true};
  model.fixed.push_back(root);
  fem::NodalLoad tip;
  tip.nodes = test::nodes_at(model.mesh, 0, kStripL);
  tip.force_per_node = {0, 0, -kStripP / static_cast<double>(tip.nodes.size())};
  tip.ramp_time = 0.02;
  model.loads.push_back(tip);
  const double I = kStripW * std::pow(kStripT, 3) / 12;
  const double omega1 =
      1.875 * 1.875 * std::sqrt(kE * I / (kRho * kStripW * kStripT * std::pow(kStripL, 4)));
  model.mass_damping = 2.0 * omega1;
  return omega1;
}

// Cantilever strip: L x w, clamped at x = 0 (translations and rotations), tip load P in -z.
StripRun cantilever_strip(int na, int nb, int ip) {
  fem::Model model;
  const double L = kStripL, w = kStripW, t = kStripT, P = kStripP;
  clamped_strip(model, na, nb, ip);
  const auto& tip = model.loads.front();
  const double I = w * t * t * t / 12;
  model.time.end_time = 0.15;
  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  double dz = 0;
  for (auto i : tip.nodes)
    dz += test::node_coord(solver, i, 2) / static_cast<double>(tip.nodes.size());
  const auto& en = solver.energy();
  return {-dz, P * L * L * L / (3 * kE * I), en.error(), en.stabilisation / en.internal};
}

}  // namespace

// Euler-Bernoulli: delta = P L^3 / (3 E I) for a narrow strip (free edges: the anticlastic
// curvature is free, so the strip bends with E, not E / (1 - nu^2)). Within 5 %.
TEST(Shell4, CantileverStripBendsAsBeamTheorySays) {
  const auto r = cantilever_strip(20, 2, 2);
  EXPECT_TRUE(test::near_rel(r.tip, r.analytic, 0.05))
      << "tip " << r.tip << " m, Euler-Bernoulli " << r.analytic << " m";
  EXPECT_LT(r.balance, 0.01);
  EXPECT_LT(r.hourglass_share, 0.05) << "the hourglass control must not carry the bending";
}

TEST(Shell4, CantileverStripWithMoreThicknessPointsGivesTheSameDeflection) {
  const auto r2 = cantilever_strip(20, 2, 2), r5 = cantilever_strip(20, 2, 5);
  EXPECT_TRUE(test::near_rel(r5.tip, r2.tip, 1e-3)) << "elastic: 2 Gauss points are exact";
  const auto r1 = cantilever_strip(20, 2, 1);
  EXPECT_GT(r1.tip, 10 * r2.tip) << "one point carries no bending (membrane only)";
}

// Free vibration of the undamped cantilever strip released from its static deflection under a
// tip load (load and damping removed at once): over 10 periods kinetic and internal energy
// trade places and their sum stays within 0.5 % of the energy at release.
TEST(Shell4, UndampedVibrationConservesEnergyOverTenPeriods) {
  fem::Model model;
  const double omega1 = clamped_strip(model, 20, 2, 2);
  const double period = 2 * M_PI / omega1;
  model.time.end_time = 0.12 + 10 * period;
  fem::ExplicitSolver solver(model);
  while (solver.time() < 0.12) solver.step();
  model.loads.clear();
  model.mass_damping = 0;
  solver.step();
  auto total = [&] {
    const auto& en = solver.energy();
    return en.kinetic + en.internal + en.hourglass;
  };
  const double e0 = total();
  ASSERT_GT(e0, 0);
  double drift = 0, ke_max = 0, rke_max = 0;
  while (solver.time() < model.time.end_time) {
    solver.step();
    const auto& en = solver.energy();
    drift = std::max(drift, std::abs(total() - e0) / e0);
    ke_max = std::max(ke_max, en.kinetic);
    rke_max = std::max(rke_max, en.rotational_kinetic);
  }
  EXPECT_LT(drift, 0.005);
  EXPECT_GT(ke_max, 0.9 * e0) << "the strip must really vibrate (all kinetic at the centre)";
  EXPECT_LT(rke_max, 0.01 * e0) << "the rotations' share stays that of the scaled inertia";
}

// A shell lying on a rigid plane (contact offset t/2: the shell's lower face touches), pressed
// by a load N and pulled sideways at constant velocity: the plane's tangential force is mu N
// (Coulomb, sliding), within 2 %.
TEST(Shell4, ShellPulledOnARigidPlaneFeelsMuN) {
  fem::Model model;
  const double t = 0.001, mu = 0.3, N = 20.0;
  add_plate(model, 0.04, 0.04, 4, 4, t);
  auto& plane = test::add_rigid_plane(model, "table", {0, 0, -0.5 * t}, {0, 0, 1},
                                      test::all_nodes(model.mesh), mu);
  plane.thickness = 0.5 * t;
  fem::NodalLoad press;
  press.nodes = test::all_nodes(model.mesh);
  press.force_per_node = {0, 0, -N / static_cast<double>(press.nodes.size())};
  press.ramp_time = 2e-3;
  model.loads.push_back(press);
  fem::PrescribedVelocity pull{
      "pull", test::all_nodes(model.mesh), {true, false, false}, {0.05, 0, 0}, 1e-3, 3e-3};
  model.velocities.push_back(pull);
  model.mass_damping = 2e3;
  model.time.end_time = 8e-3;
  fem::ExplicitSolver solver(model);
  while (solver.time() < model.time.end_time) solver.step();
  const auto& tool = solver.model().tools.at(0);
  EXPECT_TRUE(test::near_rel(tool.force.z, -N, 0.02)) << "normal force " << tool.force.z;
  EXPECT_TRUE(test::near_rel(tool.force.x, mu * N, 0.02)) << "friction " << tool.force.x;
}

// Objectivity: the forces of a stretched, sheared shell turned by a rigid rotation are the
// same forces turned (the co-rotational frame and the total membrane strain see no rotation).
TEST(Shell4, RigidRotationTurnsTheForcesWithTheShell) {
  fem::Shell4Block b;
  b.n = 1;
  b.conn = {0, 1, 2, 3};
  b.user_id = {1};
  b.section.thickness = 0.001;
  b.section.youngs_modulus = kE, b.section.poisson_ratio = kNu, b.section.density = kRho;
  const double x_ref[12] = {0, 0, 0, 0.01, 0, 0, 0.012, 0.01, 0, -0.001, 0.009, 0};
  const double axis[3] = {1, 0, 0};
  fem::shell4_initialise(b, x_ref, axis);
  double x[12];
  for (int I = 0; I < 4; ++I) {  // F = [[1.002, 0.001], [0, 0.999]]
    x[3 * I] = 1.002 * x_ref[3 * I] + 0.001 * x_ref[3 * I + 1];
    x[3 * I + 1] = 0.999 * x_ref[3 * I + 1];
    x[3 * I + 2] = 0;
  }
  // R: 70 degrees about the axis (1, 2, 2)/3.
  const double th = 70 * M_PI / 180, c = std::cos(th), s = std::sin(th);
  const double u[3] = {1.0 / 3, 2.0 / 3, 2.0 / 3};
  double R[3][3];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double eps = (i == j) ? 1 : 0;
      double cr = 0;
      const int k = 3 - i - j;
      if (i != j) cr = ((i + 1) % 3 == j ? -1 : 1) * u[k];
      R[i][j] = c * eps + (1 - c) * u[i] * u[j] + s * cr;
    }
  double xr[12];
  for (int I = 0; I < 4; ++I)
    for (int i = 0; i < 3; ++i)
      xr[3 * I + i] = R[i][0] * x[3 * I] + R[i][1] * x[3 * I + 1] + R[i][2] * x[3 * I + 2];
  const double zero[12] = {};
  auto forces = [&](const double* pos, double* f) {
    fem::Shell4Block bb = b;
    double m[12] = {};
    fem::ElementEnergyIncrement en;
    fem::StableStep st;
    std::fill(f, f + 12, 0.0);
    fem::shell4_internal_forces(bb, pos, zero, zero, 0.0, f, m, en, st);
  };
  double f1[12], f2[12];
  forces(x, f1);
  forces(xr, f2);
  double fmax = 0;
  for (double v : f1) fmax = std::max(fmax, std::abs(v));
  ASSERT_GT(fmax, 1.0);
  for (int I = 0; I < 4; ++I)
    for (int i = 0; i < 3; ++i) {
      const double want = R[i][0] * f1[3 * I] + R[i][1] * f1[3 * I + 1] + R[i][2] * f1[3 * I + 2];
      EXPECT_NEAR(f2[3 * I + i], want, 1e-9 * fmax) << "node " << I << " component " << i;
    }
}
