#pragma once
// `ncfsim calibrate macro`: the macro fabric membrane law ([[membrane_law]] type = "fabric",
// drape/fabric_membrane.hpp) from the meso picture-frame virtual tests: their normalised shear
// force against shear angle, one curve per sign of the shear, resampled and made monotone.
//
// Signs: a meso frame case is "positive" when the wales (the stitch, material axis 1 of the macro
// law) run along the frame diagonal that lengthens (cases/drape/picture_frame_positive.toml,
// stitch_direction_deg = 45 with arms along x and y): the angle between the two tow families that
// holds the wale closes and the stitch stretches, which is the macro law's positive shear. So the
// meso positive frame gives `shear_angle_deg`/`shear_force`, the negative one
// `negative_shear_angle_deg`/`negative_shear_force` (force magnitudes; the frame angle of both
// meso runs is positive).
#include <array>
#include <filesystem>
#include <string>
#include <vector>

namespace ncfsim::workflow {

/// Normalised picture-frame shear force F_sh (N/m, Harrison: frame force x L_frame / L_fabric^2 /
/// (2 cos theta)) against shear angle (deg).
struct FrameCurve {
  std::vector<double> angle_deg, force;
};

/// A meso frame curve on the macro law's grid.
struct ResampledCurve {
  FrameCurve curve;              // starts at (0, 0), angles step_deg apart, force non-decreasing
  double clipped_from_deg = -1;  // first grid angle where the running maximum replaced the fit
                                 // and the force had reached 1 % of its largest (< 0: none)
  double largest_drop = 0;       // largest (running max - fit) / running max over the grid
  int n_clipped = 0;             // grid points held at the running maximum, noise included
  std::vector<double> fitted;    // the fits on the grid before the clipping (the meso curve)
};

/// Resamples a measured F_sh(angle) on 0, step, 2 step, ... up to max_deg (the largest grid angle
/// not past the data's largest angle when max_deg <= 0): each value is a linear least-squares fit
/// of the rows within +-step/2 of the grid angle, evaluated there (unbiased for a straight
/// stretch, smooths friction stick-slip); the value at 0 is 0; then clipped to the running
/// maximum (a macro law needs a force that does not fall with the angle). Rows need not be
/// sorted; NaN rows are skipped. Throws std::invalid_argument naming the problem (fewer than two
/// rows, a grid without a point past 0, a step outside (0, 45]).
ResampledCurve resample_frame_curve(const std::vector<double>& angle_deg,
                                    const std::vector<double>& force, double step_deg,
                                    double max_deg = 0);

/// Force of a curve at an angle (deg): linear between its points, the last slope beyond them.
double curve_force(const FrameCurve& c, double angle_deg);

/// The mean of two curves on the first one's grid up to the smaller of their last angles, made
/// monotone again (running maximum).
FrameCurve average_curves(const FrameCurve& a, const FrameCurve& b);

/// Normalised shear force (N/m) of tricot 'I' pillars (tension T(e) of `pillar`, a gauge apart)
/// that follow a picture frame exactly in positive shear: they stretch by
/// e = sqrt(2) cos(45 deg - g/2) - 1 (paper Eq. 4-5); their power per unit area T de/dg dg/dt /
/// gauge over cos(g) dg/dt (the frame's F_sh L cos g dg/dt on an area L^2 cos g).
double pillar_shear_force(const std::vector<double>& strain, const std::vector<double>& force,
                          double gauge, double angle_deg);

/// Bias-extension force (N) of a coupon of free length H and width W (m) at extension D (m) from
/// a frame curve, for ideal trellising (pin-jointed kinematics, inextensible fibres; Harrison et
/// al. 2004, the energy of the law F_sh cos(g) dg per unit area): the central zone (area
/// W (H - 3W/2)) shears by g(D) (Eq. 2), the four half zones (area W^2) by g/2, the clamp
/// triangles not at all: F = dg/dD [A_A F_sh(g) cos g + A_B F_sh(g/2) cos(g/2) / 2].
double bias_extension_force_from_curve(const FrameCurve& c, double length, double width,
                                       double extension);

struct MacroCalibrationOptions {
  std::filesystem::path positive, negative;            // meso picture-frame run folders (required)
  std::filesystem::path unstitched;                    // optional: a second, symmetric law
  std::filesystem::path bias_positive, bias_negative;  // optional meso bias-extension run folders
  std::filesystem::path output = "macro_membrane_law.toml";
  std::filesystem::path curves_csv;  // optional: the meso curves on the grid, fitted and clipped
  std::string frame = "frame";       // the [[boundary.picture_frame]] name of the meso runs
  std::string name = "ncf_macro";    // the [[membrane_law]] name
  bool symmetric = false;            // one curve, the mean of the two signs
  // The stitch is carried by bars on the shells ([[mesh.shell_stitch]]): the positive curve is
  // the tows' share, the positive frame less its 'I' pillars' kinematic force (paper Eq. 4-5,
  // the pillar law and gauge of the positive run's case.toml), and the pillar law is written
  // beside the membrane law.
  bool stitch_bars = false;
  double step_deg = 2.5;             // grid of the macro curve
  double max_angle_deg = 0;          // 0: as far as both runs reach
  // Constants the picture frame does not give (defaults: the representative fabric of
  // docs/fabric-data.md, two plies of 0.241 kg/m^2).
  double areal_density = 0.482;                         // kg/m^2
  std::array<double, 2> fibre_angles_deg{45.0, -45.0};  // from the wale
  double fibre_tension_stiffness = 2e5;                 // N/m per family
  double fibre_compression_ratio = 1e-3;
  double bending_stiffness = 1e-4;                   // N m
  double coupon_length = 0.25, coupon_width = 0.10;  // m, of the bias-extension check
};

struct BiasCheckRow {
  double extension_mm = 0, meso_force_N = 0, curve_force_N = 0, eq2_shear_deg = 0;
  double meso_shear_deg = 0;  // NaN: the run has no centre_shear_angle_deg column
};

struct MacroCalibration {
  ResampledCurve positive, negative, unstitched;  // unstitched empty when not given
  FrameCurve symmetric;                           // with --symmetric
  std::vector<BiasCheckRow> bias_positive, bias_negative;
  std::vector<std::string> notes;  // what the console shows (clipping, checks)
  std::string toml;                // the file written
};

/// Reads the runs (summary.json status "completed", history.csv columns
/// <frame>_shear_angle_deg and <frame>_normalised_shear_force_N_per_m), writes the TOML block
/// (atomically) and returns what it did. Throws InputError naming the folder, file or column.
MacroCalibration calibrate_macro(const MacroCalibrationOptions& o);

}  // namespace ncfsim::workflow
