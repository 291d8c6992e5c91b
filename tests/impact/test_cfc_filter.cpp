// SAE J211 / ISO 6487 CFC filter: a constant passes unchanged, a sine well inside the pass band
// keeps its amplitude and phase (forward-backward: no lag), the phaseless response is -3 dB near
// 1.67 CFC, and a sine at 10 x CFC is gone; bad classes and too slow sampling are refused.
#include <gtest/gtest.h>

#include <cmath>

#include "impact/cfc_filter.hpp"

namespace ncfsim {
namespace {

std::vector<double> sine(double f, double T, std::size_t n, double amplitude = 1.0,
                         double offset = 0.0) {
  std::vector<double> x(n);
  for (std::size_t i = 0; i < n; ++i)
    x[i] = offset + amplitude * std::sin(2 * M_PI * f * T * static_cast<double>(i));
  return x;
}

// Amplitude of a filtered sine away from the ends.
double amplitude(const std::vector<double>& y) {
  double m = 0;
  for (std::size_t i = y.size() / 4; i < 3 * y.size() / 4; ++i) m = std::max(m, std::abs(y[i]));
  return m;
}

TEST(CfcFilter, ConstantPassesUnchanged) {
  const std::vector<double> x(500, 3.25);
  for (double v : impact::cfc_filter(x, 1e-5, 60)) EXPECT_NEAR(v, 3.25, 1e-9);
}

TEST(CfcFilter, PassBandKeepsAmplitudeAndPhaseStopBandIsRemoved) {
  const double T = 1e-5;  // 100 kHz
  const double cfc = 600;
  // 100 Hz (CFC / 6): J211's corridor allows +0.5 / -1 dB; the phaseless Butterworth is ~0 dB.
  const auto x = sine(100, T, 40000);
  const auto y = impact::cfc_filter(x, T, cfc);
  EXPECT_NEAR(amplitude(y), 1.0, 0.01);
  for (std::size_t i = 10000; i < 30000; i += 997) EXPECT_NEAR(y[i], x[i], 0.01) << i;  // no lag
  // Half power near 1.67 CFC (the two passes give -3 dB where each gives -1.5 dB).
  const double a_cut = amplitude(impact::cfc_filter(sine(1.67 * cfc, T, 40000), T, cfc));
  EXPECT_NEAR(20 * std::log10(a_cut), -3.0, 0.5);
  // 10 x CFC: below -40 dB (J211's stop band asks -30 dB at 1.67 x the 10 kHz corner for CFC 1000).
  EXPECT_LT(amplitude(impact::cfc_filter(sine(10 * cfc, T, 40000), T, cfc)), 0.01);
}

TEST(CfcFilter, RefusesBadClassAndSlowSampling) {
  const std::vector<double> x(100, 1.0);
  EXPECT_THROW(impact::cfc_filter(x, 1e-5, 0), std::invalid_argument);
  EXPECT_THROW(impact::cfc_filter(x, 1e-3, 600), std::invalid_argument);  // 1 kHz < 6 kHz
}

}  // namespace
}  // namespace ncfsim
