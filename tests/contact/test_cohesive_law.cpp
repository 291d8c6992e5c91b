// Bilinear mixed-mode cohesive law: a proportional opening, sliding or mixed path dissipates the
// mode I, mode II or Benzeggagh-Kenane energy, peaks at the strength in pure modes, never heals,
// and carries closing (compressive) normal separations undamaged.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>

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

// The law as written before its initiation measures were skipped below min(dn0, ds0): the
// mixed-mode dm0, dmf (and the pow of the B-K energy) made at every call.
void tractions_in_full(const fem::CohesiveLaw& law, double dn, double ds, fem::CohesiveState& st,
                       double& tn, double& ts) {
  const double dn0 = law.N / law.K, ds0 = law.S / law.K;
  const double dnp = std::max(dn, 0.0);
  const double dm = std::sqrt(dnp * dnp + ds * ds);
  double dm0 = ds0, dmf = 2 * law.GIIc / (law.K * ds0);
  if (dnp > 0) {
    const double b = ds / dnp;
    dm0 = dn0 * ds0 * std::sqrt((1 + b * b) / (ds0 * ds0 + b * b * dn0 * dn0));
    const double B = ds * ds / (dnp * dnp + ds * ds);
    dmf = 2 * (law.GIc + (law.GIIc - law.GIc) * std::pow(B, law.eta)) / (law.K * dm0);
  }
  if (dm > st.max_separation) {
    st.max_separation = dm;
    if (dm > dm0)
      st.damage = std::clamp(
          std::max(st.damage, dmf * (dm - dm0) / (dm * std::max(dmf - dm0, 1e-300))), 0.0, 1.0);
  }
  const double keep = 1 - st.damage;
  tn = dn > 0 ? keep * law.K * dn : law.K * dn;
  ts = keep * law.K * ds;
}

// The skip is exact: dm0 lies between dn0 and ds0 (1 / dm0^2 = (1 / dn0^2 + b^2 / ds0^2) /
// (1 + b^2), a weighted mean), so below the smaller the damage cannot move. Random walks of
// opening, closing and sliding, loading and unloading, from below initiation to separation, give
// the same state and tractions as the full evaluation, to the last bit.
TEST(CohesiveLaw, SkippingTheInitiationMeasuresBelowTheSmallerOnsetChangesNothing) {
  std::mt19937_64 rng(42);
  std::normal_distribution<double> step(0.0, 1.0);
  const double onset = std::min(kLaw.N, kLaw.S) / kLaw.K;
  int moved = 0;
  for (int walk = 0; walk < 200; ++walk) {
    fem::CohesiveState a, b;
    double dn = 0, ds = 0;
    const double h = onset * (0.01 + 0.2 * (walk % 10));
    for (int i = 0; i < 400 && a.damage < 1; ++i) {
      dn += h * step(rng), ds = std::abs(ds + h * step(rng));
      double tna, tsa, tnb, tsb;
      fem::cohesive_tractions(kLaw, dn, ds, a, tna, tsa);
      tractions_in_full(kLaw, dn, ds, b, tnb, tsb);
      ASSERT_EQ(a.damage, b.damage) << "walk " << walk << ", step " << i;
      ASSERT_EQ(a.max_separation, b.max_separation);
      ASSERT_EQ(tna, tnb);
      ASSERT_EQ(tsa, tsb);
    }
    moved += a.damage > 0;
  }
  EXPECT_GT(moved, 100) << "the walks should damage most interfaces";
}

}  // namespace
}  // namespace ncfsim
