#include "drape/fabric.hpp"

#include <cmath>
#include <sstream>

#include "fem/errors.hpp"

namespace ncfsim::drape {

double FabricSpec::tow_thickness() const {
  return areal_weight / (fibre_density * tow_fibre_volume_fraction * tow_width / tow_pitch());
}

double FabricSpec::gauge() const { return stitch_gauge > 0 ? stitch_gauge : tow_pitch() * std::sqrt(2.0); }

double FabricSpec::penetration_spacing() const { return stitch_length > 0 ? stitch_length : gauge(); }

namespace {
// True when v is a positive integer multiple of unit within 1 %.
bool integer_multiple(double v, double unit) {
  const double k = v / unit;
  return std::round(k) >= 1 && std::abs(k - std::round(k)) < 0.01;
}
}  // namespace

void validate(const FabricSpec& f, const std::string& file, const std::string& prefix) {
  auto fail = [&](const std::string& key, const std::string& msg) {
    throw InputError(file, prefix.empty() ? key : prefix + "." + key, msg);
  };
  if (f.ply_angles_deg.empty()) fail("ply_angles_deg", "needs at least one ply");
  for (double a : f.ply_angles_deg)
    if (!(a >= -90 && a <= 90)) fail("ply_angles_deg", "angles must be in [-90, 90] degrees");
  if (!(f.tow_width > 0 && f.tow_width < 0.05)) fail("tow_width", "must be in (0, 0.05) m");
  if (!(f.tow_gap > 0 && f.tow_gap < f.tow_width))
    fail("tow_gap", "must be > 0 (tows must not touch initially) and smaller than the tow width");
  if (!(f.areal_weight > 0 && f.areal_weight < 5)) fail("areal_weight", "must be in (0, 5) kg/m^2 per ply");
  if (!(f.fibre_density > 0)) fail("fibre_density", "must be > 0");
  if (!(f.tow_fibre_volume_fraction > 0 && f.tow_fibre_volume_fraction <= 0.9069))
    fail("tow_fibre_volume_fraction", "must be in (0, 0.9069] (hexagonal packing limit)");
  const double t = f.tow_thickness();
  if (!(t < f.tow_width))
    fail("areal_weight", "gives a tow thicker (" + std::to_string(t * 1e3) + " mm) than wide: check areal weight, "
                         "fibre density and volume fraction");
  if (f.elements_across_tow < 1 || f.elements_across_tow > 16) fail("elements_across_tow", "must be in [1, 16]");
  if (f.elements_through_thickness < 1 || f.elements_through_thickness > 8)
    fail("elements_through_thickness", "must be in [1, 8]");
  if (f.element_length < 0) fail("element_length", "must be >= 0 (0: one tow pitch)");
  if (f.stitch != StitchPattern::None) {
    if (f.stitch_gauge < 0) fail("stitch_gauge", "must be >= 0 (0: derived from the tow pitch)");
    if (f.stitch_length < 0) fail("stitch_length", "must be >= 0 (0: equal to the gauge)");
    // Penetration points must fall into the gaps of every ply: along x and y their spacing must be
    // a whole number of tow pitches projected on the axes, p / |sin a| and p / |cos a|.
    const double p = f.tow_pitch();
    if (!(f.stitch_direction_deg >= -90 && f.stitch_direction_deg <= 90))
      fail("stitch_direction_deg", "must be in [-90, 90] degrees");
    for (double a : f.ply_angles_deg) {
      const double ar = (a - f.stitch_direction_deg) * M_PI / 180.0;  // tow angle to the wales
      const double sx = std::abs(std::sin(ar)), cy = std::abs(std::cos(ar));
      std::ostringstream why;
      if (sx > 1e-9 && !integer_multiple(f.penetration_spacing(), p / sx)) {
        why << "stitch penetrations every " << f.penetration_spacing() * 1e3 << " mm along the wales do not fall into the gaps "
            << "between tows of the " << a << " deg ply (tow pitch " << p * 1e3 << " mm needs a multiple of "
            << p / sx * 1e3 << " mm): the tow is wider than the stitch geometry allows";
        fail(f.stitch_length > 0 ? "stitch_length" : "tow_width", why.str());
      }
      if (cy > 1e-9 && !integer_multiple(f.gauge(), p / cy)) {
        why << "the stitch gauge " << f.gauge() * 1e3 << " mm does not put the wales into the gaps between tows of the "
            << a << " deg ply (tow pitch " << p * 1e3 << " mm needs a multiple of " << p / cy * 1e3
            << " mm): the tow is wider than the gauge allows";
        fail(f.stitch_gauge > 0 ? "stitch_gauge" : "tow_width", why.str());
      }
    }
  }
}

}  // namespace ncfsim::drape
