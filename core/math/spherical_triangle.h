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
// of its steps solved in angles rather than cosines: his closed form for cos(a, C') cancels
// catastrophically for small u.x (a sample meant to lie 1e-4 inside the edge a-b landed on it, and
// rays along it missed the triangle), and so does 1 - cos for short arcs.
inline Vec3f sample_spherical_triangle(const SphericalTriangle& t, Vec2f u) {
  // C' = cos(theta) a + sin(theta) tc on the arc from a to c, where the sub-triangle a-b-C' has area
  // u.x * area. With Van Oosterom & Strackee's formula for that area, and a . (b x C') =
  // sin(theta) n for n = |a . (b x tc)|, the condition solves in half angles:
  //   tan(theta / 2) = sin(h) (1 + a.b) / (n cos(h) - sin(h) b.tc),  h = u.x * area / 2.
  Vec3f c_perp = t.c - t.a * dot(t.c, t.a);
  float lc = length(c_perp);
  if (!(lc > 0)) return t.a;
  Vec3f tc = c_perp / lc;
  float arc_ac = std::atan2(lc, dot(t.c, t.a));
  float n = std::abs(dot(t.a, cross(t.b, tc)));
  float h = 0.5f * u.x * t.area;
  float sin_h = std::sin(h), cos_h = std::cos(h);
  float theta = std::min(arc_ac, 2.0f * std::atan2(sin_h * (1.0f + dot(t.a, t.b)), n * cos_h - sin_h * dot(t.b, tc)));
  Vec3f c_hat = t.a * std::cos(theta) + tc * std::sin(theta);
  // Along the arc from b to C', uniform in 1 - cos(b, w) = 2 sin^2(phi / 2) up to the arc's length.
  Vec3f w_perp = c_hat - t.b * dot(c_hat, t.b);
  float lw = length(w_perp);
  if (!(lw > 0)) return t.b;
  float arc_bc = std::atan2(lw, dot(c_hat, t.b));
  float phi = 2.0f * std::asin(std::min(1.0f, std::sqrt(u.y) * std::sin(0.5f * arc_bc)));
  return normalize(t.b * std::cos(phi) + w_perp * (std::sin(phi) / lw));
}

}  // namespace pt
