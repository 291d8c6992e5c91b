#pragma once
// Bilinear mixed-mode cohesive law of a tied interface (Camanho & Davila 2002,
// NASA/TM-2002-211737): a penalty K up to initiation, then linear softening to full separation;
// mode I (opening) and mode II (sliding, the magnitude of both shear directions) mixed by the
// Benzeggagh-Kenane criterion G_c = G_Ic + (G_IIc - G_Ic) B^eta, B = G_II / (G_I + G_II) = ds^2 /
// (dn^2 + ds^2).
//   initiation (quadratic traction): dm0 = dn0 ds0 sqrt((1 + b^2) / (ds0^2 + (b dn0)^2)), b = ds /
//   dn full separation: dmf = 2 G_c / (K dm0) damage on the largest mixed separation dm_max
//   reached: d = dmf (dm_max - dm0) / (dm_max (dmf - dm0)) tractions (1 - d) K delta, except a
//   closing normal separation, which is carried undamaged (contact of the crack faces).
// dn0 = N / K, ds0 = S / K from the normal and shear strengths. Pure function: the state (dm_max,
// the damage) lives with the caller.
#include <algorithm>
#include <cmath>

namespace ncfsim::fem {

struct CohesiveLaw {
  double K = 0;              // penalty stiffness per area, Pa/m
  double N = 0, S = 0;       // normal and shear strengths, Pa
  double GIc = 0, GIIc = 0;  // fracture energies, J/m^2
  double eta = 1.45;         // B-K exponent (carbon/epoxy: 1.45 to 2.3)
};

struct CohesiveState {
  double max_separation = 0;  // largest mixed-mode separation reached, m
  double damage = 0;          // [0, 1]; 1: separated
};

/// Tractions (normal tn, shear ts along the sliding direction) at separations dn (opening > 0)
/// and ds (sliding magnitude >= 0); updates the state (irreversible).
inline void cohesive_tractions(const CohesiveLaw& law, double dn, double ds, CohesiveState& st,
                               double& tn, double& ts) {
  const double dnp = std::max(dn, 0.0);
  const double dm = std::sqrt(dnp * dnp + ds * ds);
  // The damage moves only past the largest separation so far and past initiation; dm0 lies
  // between dn0 and ds0 (1 / dm0^2 is a weighted mean of 1 / dn0^2 and 1 / ds0^2), so below the
  // smaller of the two the mixed-mode measures (a pow: most of a tie's cycle in a crush) are not
  // made. The same state (but where dm0, rounded, falls under that bound: damage of a rounding).
  if (dm > st.max_separation) {
    st.max_separation = dm;
    const double dn0 = law.N / law.K, ds0 = law.S / law.K;
    if (dm > std::min(dn0, ds0)) {
      double dm0 = ds0, dmf = 2 * law.GIIc / (law.K * ds0);
      if (dnp > 0) {
        const double b = ds / dnp;
        dm0 = dn0 * ds0 * std::sqrt((1 + b * b) / (ds0 * ds0 + b * b * dn0 * dn0));
        const double B = ds * ds / (dnp * dnp + ds * ds);
        const double Gc = law.GIc + (law.GIIc - law.GIc) * std::pow(B, law.eta);
        dmf = 2 * Gc / (law.K * dm0);
      }
      if (dm > dm0) {
        const double d = dmf * (dm - dm0) / (dm * std::max(dmf - dm0, 1e-300));
        st.damage = std::clamp(std::max(st.damage, d), 0.0, 1.0);
      }
    }
  }
  const double keep = 1 - st.damage;
  tn = dn > 0 ? keep * law.K * dn : law.K * dn;
  ts = keep * law.K * ds;
}

}  // namespace ncfsim::fem
