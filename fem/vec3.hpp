#pragma once
// A small 3-vector for geometry outside the element kernels (tools, contact, loads).
#include <array>
#include <cmath>

namespace ncfsim::fem {

struct V3 {
  double x = 0, y = 0, z = 0;
  static V3 from(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }
  static V3 at(const double* p) { return {p[0], p[1], p[2]}; }
  std::array<double, 3> arr() const { return {x, y, z}; }
};
inline V3 operator+(V3 a, V3 b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
inline V3 operator-(V3 a, V3 b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
inline V3 operator-(V3 a) { return {-a.x, -a.y, -a.z}; }
inline V3 operator*(double s, V3 a) { return {s * a.x, s * a.y, s * a.z}; }
inline V3& operator+=(V3& a, V3 b) { return a = a + b; }
inline V3& operator-=(V3& a, V3 b) { return a = a - b; }
inline double dot(V3 a, V3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline V3 cross(V3 a, V3 b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
inline double norm(V3 a) { return std::sqrt(dot(a, a)); }
inline V3 normalized(V3 a) { const double n = norm(a); return n > 0 ? (1.0 / n) * a : V3{}; }

// The same on xyz triples stored in place (a kernel's rows of an interleaved array).
inline double dot3(const double* a, const double* b) {
  return a[0] * b[0] + a[1] * b[1] + a[2] * b[2];
}
inline void cross3(const double* a, const double* b, double* c) {
  c[0] = a[1] * b[2] - a[2] * b[1];
  c[1] = a[2] * b[0] - a[0] * b[2];
  c[2] = a[0] * b[1] - a[1] * b[0];
}

}  // namespace ncfsim::fem
