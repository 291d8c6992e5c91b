#pragma once
// The energy balance of an explicit run. Works of forces are integrated with the trapezoidal
// rule over displacement increments; because the central-difference scheme is staggered, the
// half of a step that lies beyond t^n is held as `pending` until the next cycle, so every number
// reported at t^n covers exactly [0, t^n].
namespace ncfsim::fem {

struct WorkAccumulator {
  double committed = 0, pending = 0;
  /// Force F^n with displacement increments before (du_old) and after (du_new) t^n, as dot
  /// products F.du_old and F.du_new.
  void add(double f_dot_du_old, double f_dot_du_new) {
    committed += pending + 0.5 * f_dot_du_old;
    pending = 0.5 * f_dot_du_new;
  }
};

/// Energies below this are round-off for the balance (J); the smallest physical energies of the
/// project's models (a single tow bent by its weight) are ~1e-7 J.
inline constexpr double kEnergyScaleFloor = 1e-12;

struct EnergyBalance {
  double time = 0;
  double kinetic = 0;             // incl. rotational_kinetic
  double rotational_kinetic = 0;  // of shell nodes' rotations (held by the shell groups)
  double internal = 0;         // stress work of all elements, incl. physical stabilisation
  double stabilisation = 0;    // part of internal carried by the hex stabilisation
  double hourglass = 0;        // viscous (non-physical) hourglass work
  double contact = 0;          // interface energy: penalty stored + friction dissipated
  double friction = 0;         // part of contact dissipated by friction
  double damping = 0;          // dissipated by mass damping
  double external_work = 0;    // applied loads, gravity, supports, tools
  double initial_total = 0;    // kinetic + internal at t = 0
  double eroded_internal = 0;  // elastic energy held by eroded elements when they went (part of
                               // internal: it stays counted there, it is no longer recoverable)
  double eroded_kinetic = 0;   // kinetic energy of nodes left with no element by erosion when
                               // they were taken out of the model (they stop and leave contact)

  /// The largest energy in play so far in the run (see scale(); updated by the solver each cycle).
  double scale_max = 0;

  double total() const {
    return kinetic + internal + hourglass + contact + damping + eroded_kinetic;
  }
  /// The energy in play now: max(|E0| + |W_ext|, sum of the magnitudes of the terms), J.
  double scale() const;
  /// |E - E0 - W_ext| over the largest energy in play over the run so far (scale_max), at least
  /// kEnergyScaleFloor: a run whose energies are all near zero (a tool still closing, a model at
  /// rest) has round-off residuals of 1e-20 J that mean nothing, not a 100 % error.
  double error() const;
};

}  // namespace ncfsim::fem
