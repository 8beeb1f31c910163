// Ray/primitive tests shared by both backends (Embree calls intersect_sphere from its user geometry).
#pragma once
#include "core/geometry/ray.h"

namespace pt {

// Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection", JGT 1997.
// On a hit in (tmin, tmax) writes t and the barycentrics (u, v) of p1 and p2.
inline bool intersect_triangle_mt(const Ray& ray, const Vec3f& p0, const Vec3f& p1, const Vec3f& p2,
                                  float& t, float& u, float& v) {
  Vec3f e1 = p1 - p0, e2 = p2 - p0;
  Vec3f pvec = cross(ray.d, e2);
  float det = dot(e1, pvec);
  if (det == 0.0f || !std::isfinite(det)) return false;
  float inv_det = 1.0f / det;
  Vec3f tvec = ray.o - p0;
  float uu = dot(tvec, pvec) * inv_det;
  if (uu < 0.0f || uu > 1.0f) return false;
  Vec3f qvec = cross(tvec, e1);
  float vv = dot(ray.d, qvec) * inv_det;
  if (vv < 0.0f || uu + vv > 1.0f) return false;
  float tt = dot(e2, qvec) * inv_det;
  if (!(tt > ray.tmin && tt < ray.tmax)) return false;
  t = tt;
  u = uu;
  v = vv;
  return true;
}

// Ray/sphere with the precision improvements of Haines et al., "Precision Improvements for
// Ray/Sphere Intersection", Ray Tracing Gems ch. 7 (2019): the discriminant is formed from the
// distance of the centre to the ray line, and the nearer root from the stable quadratic form.
inline bool intersect_sphere(const Ray& ray, const Vec3f& center, float radius, float& t) {
  Vec3f f = ray.o - center;
  float a = dot(ray.d, ray.d);
  float b = -dot(f, ray.d);  // b' = -f.d
  Vec3f l = f + (b / a) * ray.d;  // f minus its projection on d: centre-to-line offset
  float disc = a * (radius * radius - dot(l, l));
  if (disc < 0.0f) return false;
  float c = dot(f, f) - radius * radius;
  float q = b + std::copysign(std::sqrt(disc), b);
  float t0, t1;
  if (q == 0.0f) {
    t0 = t1 = 0.0f;
  } else {
    t0 = c / q;
    t1 = q / a;
  }
  if (t0 > t1) std::swap(t0, t1);
  if (t0 > ray.tmin && t0 < ray.tmax) {
    t = t0;
    return true;
  }
  if (t1 > ray.tmin && t1 < ray.tmax) {
    t = t1;
    return true;
  }
  return false;
}

}  // namespace pt
