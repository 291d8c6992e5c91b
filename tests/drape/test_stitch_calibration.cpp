// Stitch calibration from bias-extension data (paper Eq. 2-6): the kinematics match the analytic
// values of data.md (gamma = 7.9, 16.5, 26.1 deg at 10, 20, 30 mm on a 250 x 100 mm coupon); a known
// nonlinear stitch law turned into synthetic coupon data (irregular extensions, 1 % noise) is
// recovered by the calibration within 5 % for both shear signs.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "drape/stitch_calibration.hpp"

using namespace ncfsim::drape;

TEST(StitchCalibration, BiasExtensionKinematicsEq2) {
  BiasExtensionCoupon c;
  c.length = 0.25, c.width = 0.10;
  const double deg = 180 / M_PI;
  EXPECT_NEAR(central_shear_angle(c, 0.010) * deg, 7.9, 0.1);
  EXPECT_NEAR(central_shear_angle(c, 0.020) * deg, 16.5, 0.1);
  EXPECT_NEAR(central_shear_angle(c, 0.030) * deg, 26.1, 0.1);
  EXPECT_NEAR(central_shear_angle(c, 0.040) * deg, 37.2, 0.1);
  // Eq. 4-5: the pillar along the load stretches by sqrt(2) cos(45 - gamma/2) - 1.
  const double g = 20 / deg;
  EXPECT_NEAR(stitch_strain(c, StitchSegment::I, ShearSign::Positive, g), std::sqrt(2.0) * std::cos((45 - 10) / deg) - 1, 1e-12);
  EXPECT_LT(stitch_strain(c, StitchSegment::I, ShearSign::Negative, g), 0) << "pillars go slack in negative shear";
}

namespace {
void round_trip(ShearSign sign) {
  BiasExtensionCoupon c;  // 250 x 50 mm stitch coupon of the paper
  StitchLaw truth;        // stiffening yarn: N per segment
  for (int k = 0; k <= 20; ++k) {
    const double e = 0.02 * k;
    truth.strain.push_back(e);
    truth.force.push_back(40 * e + 600 * e * e);
  }
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.3e-3, 0.3e-3);
  std::normal_distribution<double> noise(0.0, 0.01);
  std::vector<double> D;
  for (double d = 0.5e-3; d < 0.04; d += 1.1e-3) D.push_back(d + jitter(rng));
  auto F = coupon_force(c, sign, truth, D);
  for (double& f : F) f *= 1 + noise(rng);
  const StitchLaw law = calibrate_stitch_law(c, sign, D, F, 30.0, 10);
  ASSERT_EQ(law.strain.size(), 10u);
  EXPECT_EQ(law.force.front(), 0.0);
  const double emax = law.strain.back();
  EXPECT_GT(emax, 0.02) << "the calibration must reach a useful strain";
  for (std::size_t k = 1; k < law.strain.size(); ++k) {
    const double e = law.strain[k];
    const double expected = 40 * e + 600 * e * e;
    if (e < 0.25 * emax) continue;  // near zero the relative error of a tiny force means little
    EXPECT_NEAR(law.force[k], expected, 0.05 * expected) << "strain " << e;
  }
}
}  // namespace

TEST(StitchCalibration, RoundTripPositiveShearIStitches) { round_trip(ShearSign::Positive); }
TEST(StitchCalibration, RoundTripNegativeShearLambdaStitches) { round_trip(ShearSign::Negative); }

TEST(StitchCalibration, RejectsBadData) {
  BiasExtensionCoupon c;
  EXPECT_THROW(calibrate_stitch_law(c, ShearSign::Positive, {0.001, 0.001, 0.002}, {1, 2, 3}), std::invalid_argument);
  EXPECT_THROW(calibrate_stitch_law(c, ShearSign::Positive, {0.001}, {1, 2}), std::invalid_argument);
}
