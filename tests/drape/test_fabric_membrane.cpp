// The macro fabric membrane law (drape/fabric_membrane.hpp) on its own and in a shell.
#include "drape/fabric_membrane.hpp"
#include "fem/elements/shell4_block.hpp"
#include "tests/test_support.hpp"

using namespace ncfsim;

namespace {

constexpr double kDeg = M_PI / 180;

// A rising, locking picture-frame curve (N/m at deg), and a softer one for negative shear.
drape::FabricMembraneConstants fabric(bool signed_curves) {
  drape::FabricMembraneConstants c;
  c.areal_density = 0.48;
  c.fibre_angles = {45 * kDeg, -45 * kDeg};
  c.fibre_tension_stiffness = 2e5;
  c.fibre_compression_ratio = 1e-3;
  c.bending_stiffness = 1e-4;
  c.positive =
      drape::ShearCurve({10 * kDeg, 30 * kDeg, 45 * kDeg, 55 * kDeg}, {20.0, 80.0, 300.0, 1500.0});
  if (signed_curves)
    c.negative = drape::ShearCurve({10 * kDeg, 30 * kDeg, 45 * kDeg, 55 * kDeg},
                                   {10.0, 50.0, 250.0, 1400.0});
  return c;
}

// Membrane force of the law for one in-plane deformation gradient, material axes = frame axes.
std::array<double, 3> membrane(const drape::FabricMembraneLaw& law, const double F[4]) {
  double Fa[4] = {F[0], F[1], F[2], F[3]}, ax[4] = {1, 0, 0, 1}, N[3];
  fem::MembraneBatch b;
  b.n = 1, b.stride = 1, b.F = Fa, b.axes = ax, b.resultant = N;
  law.update(b);
  return {N[0], N[1], N[2]};
}

// Picture-frame kinematics of the +-45 fabric at shear angle g (fibres turn by -g/2 and +g/2,
// unstretched): F maps A_k (at +-45 deg) to the turned directions.
void frame_gradient(double g, double F[4]) {
  const double a1 = 45 * kDeg - 0.5 * g, a2 = -45 * kDeg + 0.5 * g;
  // F = [a1 a2] [A1 A2]^-1 with A1 = (c, s), A2 = (c, -s), c = s = 1/sqrt(2).
  const double r = 1 / std::sqrt(2.0);
  const double M[2][2] = {{std::cos(a1), std::cos(a2)}, {std::sin(a1), std::sin(a2)}};
  // [A1 A2]^-1 = 1/(-2cs) [[-s, -c], [-s, c]] = [[r, r], [r, -r]] (c = s = r)
  F[0] = M[0][0] * r + M[0][1] * r, F[1] = M[0][0] * r - M[0][1] * r;
  F[2] = M[1][0] * r + M[1][1] * r, F[3] = M[1][0] * r - M[1][1] * r;
}

// Normalised shear force from the law's power in picture-frame kinematics: per unit reference
// area J N : sym(dF/dg F^-1) = F_sh cos g.
double frame_force(const drape::FabricMembraneLaw& law, double g) {
  const double h = 1e-6;
  double F[4], Fp[4], Fm[4];
  frame_gradient(g, F);
  frame_gradient(g + h, Fp);
  frame_gradient(g - h, Fm);
  double dF[4];
  for (int k = 0; k < 4; ++k) dF[k] = (Fp[k] - Fm[k]) / (2 * h);
  const double J = F[0] * F[3] - F[1] * F[2];
  const double Fi[4] = {F[3] / J, -F[1] / J, -F[2] / J, F[0] / J};
  const double L11 = dF[0] * Fi[0] + dF[1] * Fi[2], L12 = dF[0] * Fi[1] + dF[1] * Fi[3];
  const double L21 = dF[2] * Fi[0] + dF[3] * Fi[2], L22 = dF[2] * Fi[1] + dF[3] * Fi[3];
  const auto N = membrane(law, F);
  const double power = J * (N[0] * L11 + N[1] * L22 + N[2] * (L12 + L21));
  return power / std::cos(g);
}

}  // namespace

TEST(FabricMembrane, PictureFramePowerGivesBackTheTabulatedShearForce) {
  const drape::FabricMembraneLaw law("ncf", fabric(true));
  for (double deg : {5.0, 10.0, 20.0, 30.0, 40.0, 45.0, 50.0, 55.0}) {
    const double g = deg * kDeg;
    EXPECT_TRUE(test::near_rel(frame_force(law, g), law.shear_force(g), 1e-6)) << deg << " deg";
    EXPECT_TRUE(test::near_rel(frame_force(law, -g), law.shear_force(-g), 1e-6)) << -deg << " deg";
  }
  // The table itself: 30 deg -> 80 N/m, 45 deg -> 300 N/m; negative: 30 -> 50.
  EXPECT_NEAR(law.shear_force(30 * kDeg), 80.0, 1e-9);
  EXPECT_NEAR(law.shear_force(-30 * kDeg), -50.0, 1e-9);
  EXPECT_NEAR(law.shear_force(37.5 * kDeg), 190.0, 1e-9);  // between 80 and 300
}

TEST(FabricMembrane, OneCurveForBothSignsIsSymmetric) {
  const drape::FabricMembraneLaw law("ncf", fabric(false));
  for (double deg : {10.0, 30.0, 50.0})
    EXPECT_DOUBLE_EQ(law.shear_force(-deg * kDeg), -law.shear_force(deg * kDeg));
}

// Stretch along family 1 only (F = I + e A1 A1): family 2 keeps its length and the angle stays
// 90 deg, so the membrane force along family 1 is K e in tension and K e / 1000 in compression.
TEST(FabricMembrane, FibreTensionIsStiffAndCompressionAlmostFree) {
  const drape::FabricMembraneLaw law("ncf", fabric(false));
  const double r = 1 / std::sqrt(2.0);
  for (double e : {0.01, -0.01}) {
    const double F[4] = {1 + e * r * r, e * r * r, e * r * r, 1 + e * r * r};
    const auto N = membrane(law, F);
    const double along = N[0] * r * r + N[1] * r * r + 2 * N[2] * r * r;   // a1.N.a1
    const double across = N[0] * r * r + N[1] * r * r - 2 * N[2] * r * r;  // a2.N.a2
    const double K = e > 0 ? 2e5 : 2e5 * 1e-3;
    // N = K e (1 + e) a1 a1 / J with J = 1 + e.
    EXPECT_TRUE(test::near_rel(along, K * e, 1e-9)) << "strain " << e;
    EXPECT_NEAR(across, 0.0, 1e-9 * std::abs(K * e));
  }
}

namespace {

// One square shell, fibres +-45 to x, driven by the nodal velocity field of a homogeneous
// deformation rate L (constant): returns the element's shear-angle output and its membrane
// force along the way.
struct ShellShear {
  double shear_deg, kinematic_deg, power_force, table_force;
};

ShellShear drive_shell(const drape::FabricMembraneLaw& law, const double L[4], double T) {
  fem::Model model;
  const int p = model.mesh.add_part("fabric");
  model.mesh.coords = {0, 0, 0, 0.01, 0, 0, 0.01, 0.01, 0, 0, 0.01, 0};
  model.mesh.elements(fem::ElementKind::Quad4).add({0, 1, 2, 3}, p);
  model.membrane_laws.push_back(std::make_unique<drape::FabricMembraneLaw>(law));
  model.parts.resize(1);
  model.parts[0].membrane_law = 0;
  model.parts[0].shell_thickness = 3e-4;
  model.time.end_time = T;
  for (int i = 0; i < 4; ++i)
    model.velocities.push_back({"drive", {i}, {true, true, true}, {0, 0, 0}, 0.0, 0.0});
  fem::ExplicitSolver solver(model);
  // x' = L x at every node, prescribed each cycle from the current positions (x = exp(L t) X).
  while (solver.time() < T) {
    {
      auto X = solver.x.view();
      for (std::size_t i = 0; i < 4; ++i)
        model.velocities[i].velocity = {L[0] * X[3 * i] + L[1] * X[3 * i + 1],
                                        L[2] * X[3 * i] + L[3] * X[3 * i + 1], 0.0};
    }
    solver.step();
  }
  auto X = solver.x.view();
  const auto& b = solver.blocks<fem::Shell4Block>().at(0);
  double g = 0;
  fem::shell4_output_fields(b, X.data(), &g, nullptr, nullptr, nullptr);
  // Kinematic: F from the corner nodes (homogeneous), the convected +-45 directions.
  const double F[4] = {(X[3] - X[0]) / 0.01, (X[9] - X[0]) / 0.01, (X[4] - X[1]) / 0.01,
                       (X[10] - X[1]) / 0.01};
  const double r = 1 / std::sqrt(2.0);
  const double a1[2] = {F[0] * r + F[1] * r, F[2] * r + F[3] * r},
               a2[2] = {F[0] * r - F[1] * r, F[2] * r - F[3] * r};
  const double cosang =
      (a1[0] * a2[0] + a1[1] * a2[1]) / std::hypot(a1[0], a1[1]) / std::hypot(a2[0], a2[1]);
  const double kin = 90 - std::acos(cosang) / kDeg;
  return {g, kin, 0, 0};
}

}  // namespace

// The shell's shear-angle output follows the kinematic angle of the convected fibres under a
// simple-shear history (x' = x + k y: it also rotates the fabric) and a pure-shear one.
TEST(FabricMembrane, ShellFibresStayAtTheKinematicAngle) {
  const drape::FabricMembraneLaw law("ncf", fabric(true));
  // Simple shear along family 1 (planes normal to family 2 slide along it): L = k' A1 A2, with
  // k' = 40 /s: k = 0.4 at 10 ms.
  const double simple[4] = {20.0, -20.0, 20.0, -20.0};
  const auto s = drive_shell(law, simple, 0.01);
  EXPECT_NEAR(s.shear_deg, s.kinematic_deg, 0.01);
  EXPECT_GT(std::abs(s.shear_deg), 15.0);
  const double pure[4] = {20.0, 0, 0, -20.0};  // stretch along x, shorten along y
  const auto q = drive_shell(law, pure, 0.01);
  EXPECT_NEAR(q.shear_deg, q.kinematic_deg, 0.01);
  EXPECT_GT(std::abs(q.shear_deg), 10.0);
}

// Pure shear of one shell in picture-frame kinematics: the power of its nodal forces over the
// frame velocity field, per unit area and cos g, is the tabulated force (within 1 %).
TEST(FabricMembrane, ShellInPictureFrameShearReproducesTheCurve) {
  const drape::FabricMembraneLaw law("ncf", fabric(true));
  fem::Shell4Block b;
  b.n = 1;
  b.conn = {0, 1, 2, 3};
  b.user_id = {1};
  b.section.thickness = 3e-4;
  b.section.law = &law;
  const double X[12] = {0, 0, 0, 0.01, 0, 0, 0.01, 0.01, 0, 0, 0.01, 0};
  const double axis[3] = {1, 0, 0};
  fem::shell4_initialise(b, X, axis);
  for (double deg : {-40.0, -20.0, 10.0, 30.0, 50.0}) {
    const double g = deg * kDeg, h = 1e-6;
    double F[4], Fp[4];
    frame_gradient(g, F);
    frame_gradient(g + h, Fp);
    double x[12] = {}, v[12] = {};
    for (int I = 0; I < 4; ++I) {
      x[3 * I] = F[0] * X[3 * I] + F[1] * X[3 * I + 1];
      x[3 * I + 1] = F[2] * X[3 * I] + F[3] * X[3 * I + 1];
      v[3 * I] = ((Fp[0] - F[0]) * X[3 * I] + (Fp[1] - F[1]) * X[3 * I + 1]) / h;
      v[3 * I + 1] = ((Fp[2] - F[2]) * X[3 * I] + (Fp[3] - F[3]) * X[3 * I + 1]) / h;
    }
    fem::Shell4Block bb = b;
    double f[12] = {}, m[12] = {};
    const double zero[12] = {};
    fem::ElementEnergyIncrement en;
    fem::StableStep st;
    fem::shell4_internal_forces(bb, x, zero, zero, 0.0, f, m, en, st);
    double power = 0;  // f holds minus the internal forces
    for (int k = 0; k < 12; ++k) power -= f[k] * v[k];
    const double area0 = 1e-4;
    EXPECT_TRUE(test::near_rel(power / (area0 * std::cos(g)), law.shear_force(g), 0.01))
        << deg << " deg";
  }
}
