// The solid angle a triangle subtends from a point, and directions spread uniformly over it.
//
// Sampling: Arvo, "Stratified Sampling of Spherical Triangles", SIGGRAPH 1995. The first number
// picks the sub-triangle a-b-C' of area u.x * area; the second picks a point on the arc from b to
// C' so that the density stays uniform. The area comes from Van Oosterom & Strackee, "The Solid
// Angle of a Plane Triangle" (IEEE Trans. Biomed. Eng. 30, 1983), whose atan2 keeps precision for
// small triangles where Arvo's "sum of angles minus pi" cancels.
#pragma once
#include <algorithm>
#include <cmath>

#include "core/math/vec.h"

namespace pt {

struct SphericalTriangle {
  Vec3f a, b, c;      // unit directions from the viewpoint to the vertices
  float area = 0;     // solid angle in steradians
};

// False when p lies on a vertex or the triangle's plane (no solid angle).
inline bool make_spherical_triangle(const Vec3f& p, const Vec3f& v0, const Vec3f& v1, const Vec3f& v2,
                                    SphericalTriangle& t) {
  Vec3f a = v0 - p, b = v1 - p, c = v2 - p;
  float la = length(a), lb = length(b), lc = length(c);
  if (!(la > 0 && lb > 0 && lc > 0)) return false;
  t.a = a / la;
  t.b = b / lb;
  t.c = c / lc;
  float triple = std::abs(dot(t.a, cross(t.b, t.c)));
  t.area = 2.0f * std::atan2(triple, 1.0f + dot(t.a, t.b) + dot(t.b, t.c) + dot(t.c, t.a));
  return t.area > 0 && std::isfinite(t.area);
}

// A unit direction inside the spherical triangle, with density 1 / t.area. Arvo's map, with both
// of its steps solved in half angles rather than cosines: his closed form for cos(a, C') cancels
// catastrophically for small u.x (a sample meant to lie 1e-4 inside the edge a-b landed on it, and
// rays along it missed the triangle), and so does 1 - cos for short arcs. Half angles also need no
// inverse trigonometry: one sine and cosine per sample.
inline Vec3f sample_spherical_triangle(const SphericalTriangle& t, Vec2f u) {
  // C' = cos(theta) a + sin(theta) tc on the arc from a to c, where the sub-triangle a-b-C' has area
  // u.x * area. With Van Oosterom & Strackee's formula for that area, and a . (b x C') =
  // sin(theta) n for n = |a . (b x tc)|, the condition solves in half angles:
  //   tan(theta / 2) = sin(h) (1 + a.b) / (n cos(h) - sin(h) b.tc),  h = u.x * area / 2.
  const float cos_ac = dot(t.c, t.a);
  Vec3f c_perp = t.c - t.a * cos_ac;
  float lc = length(c_perp);
  if (!(lc > 0)) return t.a;
  Vec3f tc = c_perp / lc;
  float h = 0.5f * u.x * t.area;
  float sin_h = std::sin(h), cos_h = std::cos(h);
  float y = sin_h * (1.0f + dot(t.a, t.b));
  float x = std::abs(dot(t.a, cross(t.b, tc))) * cos_h - sin_h * dot(t.b, tc);
  // theta / 2 lies in [0, pi / 2); past the arc's end, tan(arc / 2) = sin / (1 + cos), C' is c.
  Vec3f c_hat = t.c;
  if (x > 0 && y * (1.0f + cos_ac) < lc * x) {
    float r2 = x * x + y * y;
    c_hat = t.a * ((x * x - y * y) / r2) + tc * (2.0f * x * y / r2);
  }
  // Along the arc from b to C', uniform in 1 - cos(b, w) = 2 sin^2(phi / 2) up to the arc's end,
  // where sin(arc / 2) is half the chord |C' - b|.
  Vec3f w_perp = c_hat - t.b * dot(c_hat, t.b);
  float lw = length(w_perp);
  if (!(lw > 0)) return t.b;
  float s = std::min(1.0f, std::sqrt(u.y) * 0.5f * length(c_hat - t.b));  // sin(phi / 2)
  float cos_phi = 1.0f - 2.0f * s * s, sin_phi = 2.0f * s * std::sqrt(std::max(0.0f, 1.0f - s * s));
  return normalize(t.b * cos_phi + w_perp * (sin_phi / lw));
}

}  // namespace pt
