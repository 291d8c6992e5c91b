#pragma once
// SAE J211-1 / ISO 6487 channel frequency class (CFC) filter of crash signals: a second-order
// Butterworth low-pass run forward then backward (phaseless, fourth order in amplitude), with the
// J211 Appendix C coefficients for the sampling interval T:
//   wd = 2 pi CFC 2.0775, wa = tan(wd T / 2), k = 1 + sqrt2 wa + wa^2
//   a0 = wa^2 / k, a1 = 2 a0, a2 = a0, b1 = -2 (wa^2 - 1) / k, b2 = (-1 + sqrt2 wa - wa^2) / k
//   y[n] = a0 x[n] + a1 x[n-1] + a2 x[n-2] + b1 y[n-1] + b2 y[n-2]
// (-3 dB at about 1.67 CFC in the phaseless pass; CFC 60 for forces on a part, 180, 600, 1000).
// The ends are padded with the end values so that a constant passes unchanged.
#include <vector>

namespace ncfsim::impact {

/// Filters samples taken every `sample_interval` s. Throws std::invalid_argument unless
/// cfc > 0 and the sampling frequency is at least 10 x CFC (J211's minimum for the class).
std::vector<double> cfc_filter(const std::vector<double>& x, double sample_interval, double cfc);

}  // namespace ncfsim::impact
