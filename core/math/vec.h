// Small fixed-size vectors for geometry and colour. Float everywhere (Embree's precision).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace pt {

constexpr float kPi = 3.14159265358979323846f;
constexpr float kInvPi = 1.0f / kPi;
constexpr float kInf = std::numeric_limits<float>::infinity();

struct Vec2f {
  float x = 0, y = 0;
  constexpr Vec2f() = default;
  constexpr Vec2f(float x_, float y_) : x(x_), y(y_) {}
  constexpr Vec2f operator+(Vec2f b) const { return {x + b.x, y + b.y}; }
  constexpr Vec2f operator-(Vec2f b) const { return {x - b.x, y - b.y}; }
  constexpr Vec2f operator*(float s) const { return {x * s, y * s}; }
};

struct Vec3f {
  float x = 0, y = 0, z = 0;
  constexpr Vec3f() = default;
  constexpr explicit Vec3f(float s) : x(s), y(s), z(s) {}
  constexpr Vec3f(float x_, float y_, float z_) : x(x_), y(y_), z(z_) {}
  constexpr float operator[](int i) const { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr float& operator[](int i) { return i == 0 ? x : (i == 1 ? y : z); }
  constexpr Vec3f operator-() const { return {-x, -y, -z}; }
  constexpr Vec3f operator+(const Vec3f& b) const { return {x + b.x, y + b.y, z + b.z}; }
  constexpr Vec3f operator-(const Vec3f& b) const { return {x - b.x, y - b.y, z - b.z}; }
  constexpr Vec3f operator*(const Vec3f& b) const { return {x * b.x, y * b.y, z * b.z}; }
  constexpr Vec3f operator/(const Vec3f& b) const { return {x / b.x, y / b.y, z / b.z}; }
  constexpr Vec3f operator*(float s) const { return {x * s, y * s, z * s}; }
  constexpr Vec3f operator/(float s) const { return {x / s, y / s, z / s}; }
  constexpr Vec3f& operator+=(const Vec3f& b) { x += b.x; y += b.y; z += b.z; return *this; }
  constexpr Vec3f& operator-=(const Vec3f& b) { x -= b.x; y -= b.y; z -= b.z; return *this; }
  constexpr Vec3f& operator*=(const Vec3f& b) { x *= b.x; y *= b.y; z *= b.z; return *this; }
  constexpr Vec3f& operator*=(float s) { x *= s; y *= s; z *= s; return *this; }
  constexpr Vec3f& operator/=(float s) { x /= s; y /= s; z /= s; return *this; }
  constexpr bool operator==(const Vec3f&) const = default;
};

// Colour is RGB radiance in linear sRGB primaries.
using Spectrum = Vec3f;

constexpr Vec3f operator*(float s, const Vec3f& v) { return v * s; }
constexpr float dot(const Vec3f& a, const Vec3f& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
constexpr Vec3f cross(const Vec3f& a, const Vec3f& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}
inline float length(const Vec3f& v) { return std::sqrt(dot(v, v)); }
constexpr float length_squared(const Vec3f& v) { return dot(v, v); }
inline Vec3f normalize(const Vec3f& v) { return v / length(v); }
inline Vec3f vmin(const Vec3f& a, const Vec3f& b) {
  return {std::min(a.x, b.x), std::min(a.y, b.y), std::min(a.z, b.z)};
}
inline Vec3f vmax(const Vec3f& a, const Vec3f& b) {
  return {std::max(a.x, b.x), std::max(a.y, b.y), std::max(a.z, b.z)};
}
inline Vec3f vabs(const Vec3f& a) { return {std::abs(a.x), std::abs(a.y), std::abs(a.z)}; }
inline float max_component(const Vec3f& v) { return std::max(v.x, std::max(v.y, v.z)); }
inline float min_component(const Vec3f& v) { return std::min(v.x, std::min(v.y, v.z)); }
inline int max_axis(const Vec3f& v) {
  return v.x > v.y ? (v.x > v.z ? 0 : 2) : (v.y > v.z ? 1 : 2);
}
inline bool is_finite(const Vec3f& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}
inline bool is_black(const Spectrum& s) { return s.x == 0 && s.y == 0 && s.z == 0; }
// Rec. 709 luminance, used to choose lights by power and for the film's variance summary.
constexpr float luminance(const Spectrum& s) { return 0.2126f * s.x + 0.7152f * s.y + 0.0722f * s.z; }
inline Vec3f reflect(const Vec3f& wi, const Vec3f& n) { return 2.0f * dot(wi, n) * n - wi; }

}  // namespace pt
