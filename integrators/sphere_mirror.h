// The geometry of one reflection in a convex spherical mirror, for light sampling through mirror
// spheres (integrators/mirror_light.h): the point of the sphere that reflects a light point y
// toward a shading point x, and the density conversion of that path.
//
// The reflection point is a stationary point of the path length |x - m| + |m - y| over the sphere
// (Fermat), in the plane through the centre, x and y (Alhazen's problem). Parameterised by the
// angle phi of m in that plane, each distance is convex in phi wherever m is visible from its
// point (with l > R the distance, (l - R cos phi)(l cos phi - R) > 0 there), so on the arc seen
// from both points the length has one minimum: the root of its derivative is bracketed and unique,
// and is found by Newton's method kept inside the bracket. The second specular manifold method of Hanika,
// Droske & Fascione (EGSR 2015) finds the same point by Newton iteration; a sphere needs no more.
//
// The density: a point source at distance s from the mirror, seen by x at distance d after a
// reflection at incidence theta, reaches x as if from an effective squared distance
//   D^2 = (s + d + 2 s d / (R cos theta)) (s + d + 2 s d cos theta / R),
// the reflected pencil's two principal curvatures by Coddington's equations for a mirror (the
// tangential one gains 2 / (R cos theta), the sagittal one 2 cos theta / R). A flat mirror (R -> inf)
// gives (s + d)^2. A light patch dA at y with cosine cos_y toward m then subtends
// dw = cos_y dA / D^2 at x. Symmetric in s and d, as reciprocity requires.
#pragma once
#include <algorithm>
#include <cmath>

#include "core/math/vec.h"

namespace pt {

struct SphereReflection {
  Vec3f m;            // the reflection point on the sphere
  float cos_theta;    // cosine of the angle of incidence at m
  float d, s;         // |x - m| and |m - y|
};

// The point of the sphere (centre c, radius r) reflecting y toward x, both outside it and each
// seeing that point. False when there is none (a point inside the sphere, or y hidden behind it
// from every point x sees).
inline bool reflect_in_sphere(const Vec3f& c, float r, const Vec3f& x, const Vec3f& y, SphereReflection& out) {
  const double R = r;
  const double ax = x.x - c.x, ay = x.y - c.y, az = x.z - c.z;
  const double bx = y.x - c.x, by = y.y - c.y, bz = y.z - c.z;
  const double la = std::sqrt(ax * ax + ay * ay + az * az), lb = std::sqrt(bx * bx + by * by + bz * bz);
  if (!(la > R * (1 + 1e-6)) || !(lb > R * (1 + 1e-6))) return false;
  // The plane of c, x and y: e1 toward x, e2 toward y's side.
  const double e1x = ax / la, e1y = ay / la, e1z = az / la;
  const double b1 = bx * e1x + by * e1y + bz * e1z;
  double px = bx - b1 * e1x, py = by - b1 * e1y, pz = bz - b1 * e1z;
  const double b2 = std::sqrt(px * px + py * py + pz * pz);
  double e2x = 0, e2y = 0, e2z = 0;
  if (b2 > 1e-9 * lb) e2x = px / b2, e2y = py / b2, e2z = pz / b2;
  const double beta = std::atan2(b2, b1);  // the angle between x and y seen from c, in [0, pi]
  // m at angle phi must be seen by x (la cos phi > R) and by y (lb cos(beta - phi) > R).
  const double lo = std::max(0.0, beta - std::acos(R / lb)), hi = std::min(beta, std::acos(R / la));
  double phi;
  if (b2 <= 1e-9 * lb) {
    if (b1 < 0) return false;  // y straight behind the sphere from x
    phi = 0;                   // y on the ray from c through x: the back-reflection point
  } else {
    if (!(lo < hi)) return false;
    // L(phi) = f(la, phi) + f(lb, beta - phi), f(l, t) = sqrt(l^2 + R^2 - 2 l R cos t): Newton on
    // L' = 0 from the bisector (the answer for distant points), kept inside the bracket [a, b]
    // where L' changes sign (bisection when a step leaves it). L'' > 0 on the arc both see.
    const double cb = std::cos(beta), sb = std::sin(beta);
    auto slope = [&](double f, double& d2) {
      const double c1 = std::cos(f), s1 = std::sin(f);
      const double c2 = cb * c1 + sb * s1, s2 = sb * c1 - cb * s1;  // cos, sin of beta - f
      const double f1 = std::sqrt(la * la + R * R - 2 * la * R * c1), f2 = std::sqrt(lb * lb + R * R - 2 * lb * R * c2);
      d2 = la * R * (la - R * c1) * (la * c1 - R) / (f1 * f1 * f1) + lb * R * (lb - R * c2) * (lb * c2 - R) / (f2 * f2 * f2);
      return la * R * s1 / f1 - lb * R * s2 / f2;
    };
    double a = lo, b = hi, d2;
    if (slope(a, d2) > 0 || slope(b, d2) < 0) return false;  // the reflection point is not on the arc both see
    phi = std::clamp(0.5 * beta, a, b);
    for (int i = 0; i < 40; ++i) {
      const double g = slope(phi, d2);
      if (g == 0) break;
      (g > 0 ? b : a) = phi;
      double next = d2 > 0 ? phi - g / d2 : 0.5 * (a + b);
      if (!(next > a && next < b)) next = 0.5 * (a + b);
      const bool done = std::abs(next - phi) <= 1e-9 * (1 + beta);
      phi = next;
      if (done || b - a <= 1e-12) break;
    }
  }
  const double cp = std::cos(phi), sp = std::sin(phi);
  const double ux = cp * e1x + sp * e2x, uy = cp * e1y + sp * e2y, uz = cp * e1z + sp * e2z;
  out.m = {static_cast<float>(c.x + R * ux), static_cast<float>(c.y + R * uy), static_cast<float>(c.z + R * uz)};
  const double mx = ax - R * ux, my = ay - R * uy, mz = az - R * uz;  // x - m
  const double d = std::sqrt(mx * mx + my * my + mz * mz);
  const double nx = bx - R * ux, ny = by - R * uy, nz = bz - R * uz;  // y - m
  const double s = std::sqrt(nx * nx + ny * ny + nz * nz);
  const double cos_theta = (mx * ux + my * uy + mz * uz) / d;
  if (!(cos_theta > 0) || !(d > 0) || !(s > 0)) return false;
  out.cos_theta = static_cast<float>(cos_theta);
  out.d = static_cast<float>(d);
  out.s = static_cast<float>(s);
  return true;
}

// The effective squared distance D^2 of the reflected path (the header's comment).
inline float sphere_mirror_distance2(float s, float d, float cos_theta, float r) {
  const double sd2 = 2.0 * static_cast<double>(s) * d / r;
  const double a = static_cast<double>(s) + d;
  return static_cast<float>((a + sd2 / cos_theta) * (a + sd2 * cos_theta));
}

}  // namespace pt
