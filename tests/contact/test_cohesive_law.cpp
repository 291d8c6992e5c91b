// Bilinear mixed-mode cohesive law: a proportional opening, sliding or mixed path dissipates the
// mode I, mode II or Benzeggagh-Kenane energy, peaks at the strength in pure modes, never heals,
// and carries closing (compressive) normal separations undamaged.
#include <gtest/gtest.h>

#include <cmath>

#include "fem/contact/cohesive_law.hpp"
#include "tests/test_support.hpp"

namespace ncfsim {
namespace {

const fem::CohesiveLaw kLaw{1e14,  40e6,  60e6,
                            300.0, 900.0, 1.45};  // K Pa/m, N, S Pa, GIc, GIIc J/m^2

// Work per area along dn = t cos(a), ds = t sin(a) to full separation; also the peak tractions.
struct Path {
  double work = 0, peak_n = 0, peak_s = 0;
};
Path proportional(double angle, double end, int steps) {
  fem::CohesiveState st;
  Path p;
  double tn0 = 0, ts0 = 0, dn0 = 0, ds0 = 0;
  for (int i = 1; i <= steps; ++i) {
    const double t = end * i / steps;
    const double dn = t * std::cos(angle), ds = t * std::sin(angle);
    double tn, ts;
    fem::cohesive_tractions(kLaw, dn, ds, st, tn, ts);
    p.work += 0.5 * (tn + tn0) * (dn - dn0) + 0.5 * (ts + ts0) * (ds - ds0);
    p.peak_n = std::max(p.peak_n, tn);
    p.peak_s = std::max(p.peak_s, ts);
    tn0 = tn, ts0 = ts, dn0 = dn, ds0 = ds;
  }
  EXPECT_DOUBLE_EQ(st.damage, 1.0);
  return p;
}

TEST(CohesiveLaw, PureModesPeakAtTheStrengthAndDissipateTheirFractureEnergy) {
  const auto I = proportional(0.0, 3 * 2 * 300.0 / 40e6, 30000);
  EXPECT_TRUE(test::near_rel(I.peak_n, 40e6, 1e-3));
  EXPECT_TRUE(test::near_rel(I.work, 300.0, 2e-3));
  const auto II = proportional(M_PI / 2, 3 * 2 * 900.0 / 60e6, 30000);
  EXPECT_TRUE(test::near_rel(II.peak_s, 60e6, 1e-3));
  EXPECT_TRUE(test::near_rel(II.work, 900.0, 2e-3));
}

TEST(CohesiveLaw, MixedModeDissipatesTheBenzeggaghKenaneEnergy) {
  const double a = std::atan(1.0);  // dn = ds: B = 1/2
  const double Gc = 300.0 + (900.0 - 300.0) * std::pow(0.5, 1.45);
  const auto m = proportional(a, 3 * 2 * 900.0 / 40e6, 40000);
  EXPECT_TRUE(test::near_rel(m.work, Gc, 3e-3)) << m.work << " vs " << Gc;
}

TEST(CohesiveLaw, DamageNeverHealsAndClosingIsCarried) {
  fem::CohesiveState st;
  double tn, ts;
  fem::cohesive_tractions(kLaw, 2 * 40e6 / 1e14, 0, st, tn, ts);  // twice the initiation opening
  const double d = st.damage;
  EXPECT_GT(d, 0.0);
  fem::cohesive_tractions(kLaw, 0.5 * 40e6 / 1e14, 0, st, tn, ts);  // unload
  EXPECT_DOUBLE_EQ(st.damage, d);
  EXPECT_NEAR(tn, (1 - d) * 1e14 * 0.5 * 40e6 / 1e14, 1e-6);
  fem::cohesive_tractions(kLaw, -1e-7, 0, st, tn, ts);  // closing: full penalty
  EXPECT_DOUBLE_EQ(tn, -1e14 * 1e-7);
}

}  // namespace
}  // namespace ncfsim
