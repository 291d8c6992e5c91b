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
  auto key = [&](const std::string& k) { return prefix.empty() ? k : prefix + "." + k; };
  auto fail = [&](const std::string& k, const std::string& msg) { throw InputError(file, key(k), msg); };
  auto check = [&](const std::string& k, double v, const Range& r) { check_range(file, key(k), v, r); };
  // The only range checks of these [[mesh.fabric]] keys (the case reader, drape/case, reads them).
  if (f.ply_angles_deg.empty()) fail("ply_angles_deg", "needs at least one ply");
  for (std::size_t i = 0; i < f.ply_angles_deg.size(); ++i)
    if (!Range::closed(-90, 90).contains(f.ply_angles_deg[i]))
      throw InputError::out_of_range(file, key("ply_angles_deg"), f.ply_angles_deg[i], Range::closed(-90, 90),
                                     static_cast<long>(i));
  check("tow_width", f.tow_width, Range::open(0, 0.05));
  check("tow_gap", f.tow_gap, Range::positive());
  if (!(f.tow_gap < f.tow_width))
    fail("tow_gap", "must be smaller than the tow width (tows must not touch initially, gap > 0)");
  check("areal_weight", f.areal_weight, Range::open(0, 5));
  check("fibre_density", f.fibre_density, Range::positive());
  check("tow_fibre_volume_fraction", f.tow_fibre_volume_fraction, Range::open_closed(0, 0.9069));
  const double t = f.tow_thickness();
  if (!(t < f.tow_width))
    fail("areal_weight", "gives a tow thicker (" + std::to_string(t * 1e3) + " mm) than wide: check areal weight, "
                         "fibre density and volume fraction");
  check("elements_across_tow", f.elements_across_tow, Range::closed(1, 16));
  check("elements_through_thickness", f.elements_through_thickness, Range::closed(1, 8));
  check("element_length", f.element_length, Range::non_negative());
  check("stitch_direction_deg", f.stitch_direction_deg, Range::closed(-90, 90));
  check("stitch_gauge", f.stitch_gauge, Range::non_negative());   // 0: derived from the tow pitch
  check("stitch_length", f.stitch_length, Range::non_negative());  // 0: equal to the gauge
  if (f.stitch != StitchPattern::None) {
    // Penetration points must fall into the gaps of every ply: along x and y their spacing must be
    // a whole number of tow pitches projected on the axes, p / |sin a| and p / |cos a|.
    const double p = f.tow_pitch();
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
