#pragma once
// Geometry of a bilinear quadrilateral segment x(xi, eta) = c + xi a1 + eta a2 + xi eta h
// (corners 1..4 at (xi, eta) = (-1,-1), (1,-1), (1,1), (-1,1), counter-clockwise seen from
// outside), prepared once per cycle so that projecting a node onto it costs a few dot products.
// Pure functions, no mesh lookups.
#include <cmath>
#include <cstdint>

namespace ncfsim::fem {

/// One segment's frame, packed in one 128-byte record: the node loop reads it through a
/// candidate index, so its fields are kept together rather than in separate arrays.
struct alignas(64) SegmentFrame {
  double c[3];   // centre
  double n[3];   // unit normal, a1 x a2 / |a1 x a2| (outward); a1, a2 are orthogonal to it
  double e1[3];  // dual tangent: e1 . a1 = 1, e1 . a2 = 0 (in the tangent plane)
  double e2[3];  // dual tangent: e2 . a2 = 1, e2 . a1 = 0
  double hn;     // h . n: warp of the segment
  double he1;    // h . e1
  double he2;    // h . e2
  double depth;  // largest penetration that still counts as contact (from the element thickness), m
};
static_assert(sizeof(SegmentFrame) == 128);

/// Frame of the segment with corner coordinates p[4][3] (the caller gathers them).
inline void segment_frame(const double (&p)[4][3], double depth, SegmentFrame& f) {
  double a1[3], a2[3], h[3];
  for (int k = 0; k < 3; ++k) {
    f.c[k] = 0.25 * (p[0][k] + p[1][k] + p[2][k] + p[3][k]);
    a1[k] = 0.25 * (-p[0][k] + p[1][k] + p[2][k] - p[3][k]);
    a2[k] = 0.25 * (-p[0][k] - p[1][k] + p[2][k] + p[3][k]);
    h[k] = 0.25 * (p[0][k] - p[1][k] + p[2][k] - p[3][k]);
  }
  const double nx = a1[1] * a2[2] - a1[2] * a2[1];
  const double ny = a1[2] * a2[0] - a1[0] * a2[2];
  const double nz = a1[0] * a2[1] - a1[1] * a2[0];
  const double nn = nx * nx + ny * ny + nz * nz;  // |a1 x a2|^2 = g11 g22 - g12^2
  const double inv_n = nn > 0 ? 1.0 / std::sqrt(nn) : 0.0;
  const double inv_det = inv_n * inv_n;
  f.n[0] = nx * inv_n, f.n[1] = ny * inv_n, f.n[2] = nz * inv_n;
  const double g11 = a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2];
  const double g12 = a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2];
  const double g22 = a2[0] * a2[0] + a2[1] * a2[1] + a2[2] * a2[2];
  double he1 = 0, he2 = 0, hn = 0;
  for (int k = 0; k < 3; ++k) {
    f.e1[k] = (g22 * a1[k] - g12 * a2[k]) * inv_det;
    f.e2[k] = (g11 * a2[k] - g12 * a1[k]) * inv_det;
    he1 += h[k] * f.e1[k];
    he2 += h[k] * f.e2[k];
    hn += h[k] * f.n[k];
  }
  f.hn = hn, f.he1 = he1, f.he2 = he2;
  f.depth = depth;
}

/// Projection of point (px, py, pz) onto the segment: local coordinates (one fixed-point
/// correction for the bilinear term, exact for parallelograms) and the gap along the normal
/// (positive outside).
struct SegmentProjection {
  double xi, eta, gap;
};
inline SegmentProjection project_on_segment(const SegmentFrame& f, double px, double py,
                                            double pz) {
  const double dx = px - f.c[0], dy = py - f.c[1], dz = pz - f.c[2];
  const double xi0 = dx * f.e1[0] + dy * f.e1[1] + dz * f.e1[2];
  const double eta0 = dx * f.e2[0] + dy * f.e2[1] + dz * f.e2[2];
  const double g0 = dx * f.n[0] + dy * f.n[1] + dz * f.n[2];
  const double xe = xi0 * eta0;
  const double xi = xi0 - xe * f.he1, eta = eta0 - xe * f.he2;
  return {xi, eta, g0 - xi * eta * f.hn};
}

/// Frames of kFrameLanes segments side by side (structure of arrays inside the block, so the
/// frame kernel runs in SIMD lanes); the node loop reads segment s from block s / kFrameLanes,
/// lane s % kFrameLanes. Same quantities as SegmentFrame.
constexpr int kFrameLanes = 8;
struct alignas(64) SegmentFrameBlock {
  double c[3][kFrameLanes];
  double n[3][kFrameLanes];
  double e1[3][kFrameLanes];
  double e2[3][kFrameLanes];
  double hn[kFrameLanes], he1[kFrameLanes], he2[kFrameLanes], depth[kFrameLanes];
};

/// Frames of a block from gathered corners p[corner][xyz][lane] (a lane of four equal corners,
/// e.g. padding, gets a zero normal and dual basis).
inline void segment_frames(const double (&p)[4][3][kFrameLanes], const double (&depth)[kFrameLanes],
                           SegmentFrameBlock& f) {
  for (int l = 0; l < kFrameLanes; ++l) {
    double a1[3], a2[3], h[3];
    for (int k = 0; k < 3; ++k) {
      f.c[k][l] = 0.25 * (p[0][k][l] + p[1][k][l] + p[2][k][l] + p[3][k][l]);
      a1[k] = 0.25 * (-p[0][k][l] + p[1][k][l] + p[2][k][l] - p[3][k][l]);
      a2[k] = 0.25 * (-p[0][k][l] - p[1][k][l] + p[2][k][l] + p[3][k][l]);
      h[k] = 0.25 * (p[0][k][l] - p[1][k][l] + p[2][k][l] - p[3][k][l]);
    }
    const double nx = a1[1] * a2[2] - a1[2] * a2[1];
    const double ny = a1[2] * a2[0] - a1[0] * a2[2];
    const double nz = a1[0] * a2[1] - a1[1] * a2[0];
    const double nn = nx * nx + ny * ny + nz * nz;
    const double inv_n = nn > 0 ? 1.0 / std::sqrt(nn) : 0.0;
    const double inv_det = inv_n * inv_n;
    const double g11 = a1[0] * a1[0] + a1[1] * a1[1] + a1[2] * a1[2];
    const double g12 = a1[0] * a2[0] + a1[1] * a2[1] + a1[2] * a2[2];
    const double g22 = a2[0] * a2[0] + a2[1] * a2[1] + a2[2] * a2[2];
    const double n[3] = {nx * inv_n, ny * inv_n, nz * inv_n};
    double he1 = 0, he2 = 0, hn = 0;
    for (int k = 0; k < 3; ++k) {
      const double e1 = (g22 * a1[k] - g12 * a2[k]) * inv_det;
      const double e2 = (g11 * a2[k] - g12 * a1[k]) * inv_det;
      f.n[k][l] = n[k];
      f.e1[k][l] = e1;
      f.e2[k][l] = e2;
      he1 += h[k] * e1;
      he2 += h[k] * e2;
      hn += h[k] * n[k];
    }
    f.hn[l] = hn, f.he1[l] = he1, f.he2[l] = he2;
    f.depth[l] = depth[l];
  }
}

inline SegmentProjection project_on_segment(const SegmentFrameBlock& f, int l, double px, double py,
                                            double pz) {
  const double dx = px - f.c[0][l], dy = py - f.c[1][l], dz = pz - f.c[2][l];
  const double xi0 = dx * f.e1[0][l] + dy * f.e1[1][l] + dz * f.e1[2][l];
  const double eta0 = dx * f.e2[0][l] + dy * f.e2[1][l] + dz * f.e2[2][l];
  const double g0 = dx * f.n[0][l] + dy * f.n[1][l] + dz * f.n[2][l];
  const double xe = xi0 * eta0;
  const double xi = xi0 - xe * f.he1[l], eta = eta0 - xe * f.he2[l];
  return {xi, eta, g0 - xi * eta * f.hn[l]};
}

/// Bilinear shape functions at (xi, eta), clamped to the segment.
inline void segment_shape(double xi, double eta, double (&N)[4]) {
  xi = xi < -1 ? -1 : (xi > 1 ? 1 : xi);
  eta = eta < -1 ? -1 : (eta > 1 ? 1 : eta);
  N[0] = 0.25 * (1 - xi) * (1 - eta);
  N[1] = 0.25 * (1 + xi) * (1 - eta);
  N[2] = 0.25 * (1 + xi) * (1 + eta);
  N[3] = 0.25 * (1 - xi) * (1 + eta);
}

/// Gathers the four corners of a segment from nodal positions x [3*n_nodes].
inline void gather_segment(const double* x, const std::int32_t* nodes4, double (&p)[4][3]) {
  for (int a = 0; a < 4; ++a) {
    const double* q = x + 3 * static_cast<std::size_t>(nodes4[a]);
    p[a][0] = q[0], p[a][1] = q[1], p[a][2] = q[2];
  }
}

}  // namespace ncfsim::fem
