// Warps from the unit square to directions and points, each with its pdf
// (Pharr, Jakob, Humphreys, "Physically Based Rendering", 3rd ed., ch. 13).
#pragma once
#include "core/math/vec.h"

namespace pt {

// sin and cos of an angle within [-pi/4, pi/4], by their Taylor series to degree 9 and 10: the
// remainders, (pi/4)^11 / 11! and (pi/4)^12 / 12!, are below 2e-9, under float's rounding. A call of
// libm's sincosf cost some 45 instructions on every diffuse bounce.
inline void sincos_quarter(float a, float& s, float& c) {
  const float a2 = a * a;
  s = a * (1.0f + a2 * (-1.0f / 6 + a2 * (1.0f / 120 + a2 * (-1.0f / 5040 + a2 * (1.0f / 362880)))));
  c = 1.0f + a2 * (-0.5f + a2 * (1.0f / 24 + a2 * (-1.0f / 720 + a2 * (1.0f / 40320 + a2 * (-1.0f / 3628800)))));
}

// Concentric square-to-disk map (Shirley & Chiu 1997): low distortion keeps stratification. The
// angle is pi/4 (oy/ox) in the sectors where |ox| is the larger, else pi/2 - pi/4 (ox/oy), whose
// cosine and sine are the sine and cosine of pi/4 (ox/oy).
inline Vec2f square_to_disk_concentric(Vec2f u) {
  const float ox = 2.0f * u.x - 1.0f, oy = 2.0f * u.y - 1.0f;
  if (ox == 0 && oy == 0) return {0, 0};
  const bool x_major = std::abs(ox) > std::abs(oy);
  const float r = x_major ? ox : oy;
  float s, c;
  sincos_quarter((kPi / 4) * ((x_major ? oy : ox) / r), s, c);
  return x_major ? Vec2f{r * c, r * s} : Vec2f{r * s, r * c};
}

inline Vec3f square_to_cosine_hemisphere(Vec2f u) {
  Vec2f d = square_to_disk_concentric(u);
  float z = std::sqrt(std::max(0.0f, 1.0f - d.x * d.x - d.y * d.y));
  return {d.x, d.y, z};
}
inline float cosine_hemisphere_pdf(float cos_theta) { return cos_theta > 0 ? cos_theta * kInvPi : 0.0f; }

inline Vec3f square_to_uniform_sphere(Vec2f u) {
  float z = 1.0f - 2.0f * u.x;
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
constexpr float uniform_sphere_pdf() { return 1.0f / (4.0f * kPi); }

inline Vec3f square_to_uniform_hemisphere(Vec2f u) {
  float z = u.x;
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
constexpr float uniform_hemisphere_pdf() { return 1.0f / (2.0f * kPi); }

// Uniform direction in the cone around +z whose half-angle has 1 - cos = one_minus_cos_max. The
// cone is given by 1 - cos, not cos: for a small distant sphere cos is within an ulp of 1 and
// 1 - cos in float would be 0 or twice the truth. sin^2 = (1 - z)(1 + z) keeps the radius exact.
inline Vec3f square_to_uniform_cone(Vec2f u, float one_minus_cos_max) {
  float one_minus_z = u.x * one_minus_cos_max;
  float z = 1.0f - one_minus_z;
  float r = std::sqrt(std::max(0.0f, one_minus_z * (2.0f - one_minus_z)));
  float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float uniform_cone_pdf(float one_minus_cos_max) { return 1.0f / (2.0f * kPi * one_minus_cos_max); }
// 1 - cos(theta) from sin^2(theta) without cancellation: sin^2 / (1 + cos).
inline float one_minus_cos_from_sin2(float sin2) { return sin2 / (1.0f + std::sqrt(std::max(0.0f, 1.0f - sin2))); }

// Uniform barycentrics on a triangle (PBRT 3rd ed. 13.6.5): returns (b1, b2), b0 = 1 - b1 - b2.
inline Vec2f square_to_triangle(Vec2f u) {
  float su = std::sqrt(u.x);
  return {1.0f - su, u.y * su};
}

// Cos^n lobe around +z, pdf (n+1)/(2 pi) cos^n (Lafortune & Willems 1994, modified Phong).
inline Vec3f square_to_phong_lobe(Vec2f u, float exponent) {
  float z = std::pow(u.x, 1.0f / (exponent + 1.0f));
  float r = std::sqrt(std::max(0.0f, 1.0f - z * z));
  float phi = 2.0f * kPi * u.y;
  return {r * std::cos(phi), r * std::sin(phi), z};
}
inline float phong_lobe_pdf(float cos_alpha, float exponent) {
  return cos_alpha > 0 ? (exponent + 1.0f) / (2.0f * kPi) * std::pow(cos_alpha, exponent) : 0.0f;
}

inline float power_heuristic(float pdf_a, float pdf_b) {
  float a = pdf_a * pdf_a, b = pdf_b * pdf_b;
  return a + b > 0 ? a / (a + b) : 0.0f;
}

}  // namespace pt
