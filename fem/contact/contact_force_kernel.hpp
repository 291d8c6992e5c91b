#pragma once
// Penalty contact force law over a batch of active contacts (pure function, structure of arrays,
// no branches inside the loop, so it runs in SIMD lanes): normal penalty k * penetration with
// viscous damping that never pulls, and regularised Coulomb friction (an elastic tangential
// spring of stiffness k on the relative slip, capped at mu times the elastic normal force).
// k = kscale * m_eff with m_eff = m_s m_m / (m_s + m_m).
#include <algorithm>
#include <cmath>
#include <cstdint>

namespace ncfsim::fem {

constexpr int kContactBatch = 64;

struct ContactBatch {
  int n = 0;
  // Inputs, [kContactBatch] each (filled by the caller).
  double pen[kContactBatch];                                       // thickness - gap, m (> 0)
  double nx[kContactBatch], ny[kContactBatch], nz[kContactBatch];  // unit normal, master outward
  double m_s[kContactBatch], m_m[kContactBatch];  // slave mass, master mass at the contact point
  double rx[kContactBatch], ry[kContactBatch], rz[kContactBatch];  // v_slave - v_master, m/s
  double mu[kContactBatch];                                        // Coulomb coefficient
  // State in and out: elastic friction force on the slave, N.
  double tx[kContactBatch], ty[kContactBatch], tz[kContactBatch];
  // Output: total force on the slave node, N (its reaction goes to the master segment), and the
  // energy dissipated by friction and damping over the step, J.
  double fx[kContactBatch], fy[kContactBatch], fz[kContactBatch];
  double dissipated[kContactBatch];
  // Bookkeeping for the scatter (not read by the kernel).
  std::int32_t slave[kContactBatch], seg[kContactBatch], state[kContactBatch], cell[kContactBatch];
  double N[4][kContactBatch];  // shape functions of the master point
};

/// Forces of contacts [0, b.n); returns the energy dissipated by friction and damping over this
/// step (dt, the step that produced the relative velocities), J.
/// kscale = penalty_scale / dt0^2; damp = 2 zeta sqrt(kscale) (damping coefficient / m_eff).
inline double contact_forces(ContactBatch& b, double kscale, double damp, double dt) {
  const double inv_kscale = 1.0 / kscale;
  const int n = b.n;
  const double* __restrict pen = b.pen;
  const double* __restrict bnx = b.nx;
  const double* __restrict bny = b.ny;
  const double* __restrict bnz = b.nz;
  const double* __restrict ms = b.m_s;
  const double* __restrict mm_ = b.m_m;
  const double* __restrict brx = b.rx;
  const double* __restrict bry = b.ry;
  const double* __restrict brz = b.rz;
  const double* __restrict bmu = b.mu;
  double* __restrict btx = b.tx;
  double* __restrict bty = b.ty;
  double* __restrict btz = b.tz;
  double* __restrict bfx = b.fx;
  double* __restrict bfy = b.fy;
  double* __restrict bfz = b.fz;
  double* __restrict diss = b.dissipated;
  for (int l = 0; l < n; ++l) {  // no reduction inside: the loop runs in SIMD lanes
    // k and 1/k from one division.
    const double mm = ms[l] * mm_[l], sum = ms[l] + mm_[l], q = 1.0 / (mm * sum);
    const double m_eff = mm * mm * q, k = kscale * m_eff, inv_k = sum * sum * q * inv_kscale;
    const double nx = bnx[l], ny = bny[l], nz = bnz[l];
    const double rx = brx[l], ry = bry[l], rz = brz[l];
    const double rn = rx * nx + ry * ny + rz * nz;  // > 0: separating
    const double fn = k * pen[l];
    const double f_normal = std::max(fn - damp * m_eff * rn, 0.0);
    const double damped = (fn - f_normal) * rn * dt;
    // Trial tangential force: the old one turned into the tangent plane, plus k times the slip.
    const double on = btx[l] * nx + bty[l] * ny + btz[l] * nz, kdt = k * dt;
    double tx = btx[l] - on * nx - kdt * (rx - rn * nx);
    double ty = bty[l] - on * ny - kdt * (ry - rn * ny);
    double tz = btz[l] - on * nz - kdt * (rz - rn * nz);
    const double cap = bmu[l] * fn, mag2 = tx * tx + ty * ty + tz * tz;
    const bool slide = mag2 > cap * cap;  // mu = 0: any trial force slides to zero
    const double mag = std::sqrt(slide ? mag2 : 1.0);
    const double r = slide ? cap / mag : 1.0;
    diss[l] = damped + (slide ? cap * (mag - cap) * inv_k : 0.0);
    tx *= r, ty *= r, tz *= r;
    btx[l] = tx, bty[l] = ty, btz[l] = tz;
    bfx[l] = f_normal * nx + tx, bfy[l] = f_normal * ny + ty, bfz[l] = f_normal * nz + tz;
  }
  double dissipated = 0;
  for (int l = 0; l < n; ++l) dissipated += diss[l];
  return dissipated;
}

}  // namespace ncfsim::fem
