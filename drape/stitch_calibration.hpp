#pragma once
// Stitch force-strain laws from bias-extension force data (the paper's Eq. 2-6).
//
// Kinematics of the central pure-shear zone of a bias-extension coupon of free length H and width W
// pulled by D (Eq. 2, data.md): gamma = 90 deg - 2 acos((L0 + D) / (sqrt(2) L0)), L0 = H - W.
// The fabric's stretches along and across the load are lambda_l = sqrt(2) cos(45 - gamma/2) and
// lambda_t = sqrt(2) sin(45 - gamma/2). A stitch segment with components (a along the load, b
// across it) takes the length sqrt((lambda_l a)^2 + (lambda_t b)^2) (Eq. 3-4); its strain is
// Eq. 5-6. Tricot: the 'I' pillar runs along the wale (a = c0, b = 0), the 'Lambda' underlap spans
// one stitch length along the wale and one gauge across (c0, h0). Positive shear pulls along the
// wales (the 'I' stitches stretch); negative shear pulls across them ('I' slack; the 'Lambda'
// stitches stretch with components (h0, c0) on the load axes).
//
// Calibration (the paper's procedure, up to ~30 deg shear, where the stitches dominate): the force
// per stitch segment is the coupon force shared by the segments across the width, projected on the
// segment: F_seg = F / (n_seg cos phi), n_seg = W / gauge (per face), phi the segment's angle to the
// load; F_seg against the segment strain gives the law, resampled on a strain grid, monotone,
// through (0, 0).
#include <string>
#include <vector>

namespace ncfsim::drape {

enum class ShearSign { Positive, Negative };
enum class StitchSegment { I, Lambda };

struct BiasExtensionCoupon {
  double length = 0.25;   // m, free length H
  double width = 0.05;    // m, W
  double stitch_length = 2.5e-3;  // c0, m
  double gauge = 5.08e-3;         // h0, m
};

/// Central shear angle (rad) at extension D (m), Eq. 2.
double central_shear_angle(const BiasExtensionCoupon& c, double extension);
/// Strain of a stitch segment at shear angle gamma (rad), Eq. 3-6.
double stitch_strain(const BiasExtensionCoupon& c, StitchSegment seg, ShearSign sign, double gamma);
/// Angle (rad) between the segment and the load at shear gamma.
double stitch_angle_to_load(const BiasExtensionCoupon& c, StitchSegment seg, ShearSign sign, double gamma);

struct StitchLaw {
  std::vector<double> strain, force;  // N per stitch segment
};

/// Forward model: coupon force at each extension from a stitch law (the segment that the sign
/// loads; the other is taken slack). Used to make synthetic data and to plot the fit.
std::vector<double> coupon_force(const BiasExtensionCoupon& c, ShearSign sign, const StitchLaw& law,
                                 const std::vector<double>& extensions);

/// Calibrates the law of the segment that `sign` loads ('I' for positive, 'Lambda' for negative)
/// from (extension, force) samples; uses samples up to max_shear_deg of central shear; returns the
/// law on `n_points` equally spaced strains from 0 to the largest strain reached. Throws
/// std::invalid_argument naming the problem (too few samples, non-increasing extensions, ...).
StitchLaw calibrate_stitch_law(const BiasExtensionCoupon& c, ShearSign sign, const std::vector<double>& extension,
                               const std::vector<double>& force, double max_shear_deg = 30.0, int n_points = 12);

}  // namespace ncfsim::drape
