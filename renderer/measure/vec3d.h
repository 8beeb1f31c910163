// Double-precision 3-vectors for the benchmarks' ground truth (closed-form references, stability
// verdicts): the answer must be far more accurate than the float arithmetic it judges.
#pragma once
#include <cmath>

#include "core/math/vec.h"

namespace pt {

struct D3 {
  double x = 0, y = 0, z = 0;
  D3() = default;
  D3(double a, double b, double c) : x(a), y(b), z(c) {}
  explicit D3(const Vec3f& v) : x(v.x), y(v.y), z(v.z) {}
  D3 operator+(const D3& o) const { return {x + o.x, y + o.y, z + o.z}; }
  D3 operator-(const D3& o) const { return {x - o.x, y - o.y, z - o.z}; }
  D3 operator*(double s) const { return {x * s, y * s, z * s}; }
  Vec3f f() const { return {static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)}; }
};
inline double dot(const D3& a, const D3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
inline D3 cross(const D3& a, const D3& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline double length(const D3& a) { return std::sqrt(dot(a, a)); }
inline D3 normalize(const D3& a) { return a * (1.0 / length(a)); }

}  // namespace pt
