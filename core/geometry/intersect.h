// Ray/primitive tests shared by both backends (Embree calls intersect_sphere from its user geometry).
#pragma once
#include "core/geometry/ray.h"

namespace pt {

// Möller & Trumbore, "Fast, Minimum Storage Ray/Triangle Intersection", JGT 1997.
// On a hit in (tmin, tmax) writes t and the barycentrics (u, v) of p1 and p2. The barycentric
// tests compare the undivided values, with the sign of the determinant folded in, against 0 and
// |det|, so that a miss costs no division; the BVH's four-wide test does exactly the same operations.
// The test on the edges e1 = p1 - p0 and e2 = p2 - p0 (the BVH stores them so, which saves the
// subtractions; the results are the same bit for bit).
inline bool intersect_triangle_mt_edges(const Ray& ray, const Vec3f& p0, const Vec3f& e1, const Vec3f& e2,
                                        float& t, float& u, float& v) {
  Vec3f pvec = cross(ray.d, e2);
  float det = dot(e1, pvec);
  float abs_det = std::abs(det);
  if (!(abs_det > 0.0f && abs_det < kInf)) return false;
  Vec3f tvec = ray.o - p0;
  float uu = dot(tvec, pvec);
  Vec3f qvec = cross(tvec, e1);
  float vv = dot(ray.d, qvec);
  float us = std::copysign(1.0f, det) * uu, vs = std::copysign(1.0f, det) * vv;
  if (us < 0.0f || vs < 0.0f || us + vs > abs_det) return false;
  float inv_det = 1.0f / det;
  float tt = dot(e2, qvec) * inv_det;
  if (!(tt > ray.tmin && tt < ray.tmax)) return false;
  t = tt;
  u = uu * inv_det;
  v = vv * inv_det;
  return true;
}

inline bool intersect_triangle_mt(const Ray& ray, const Vec3f& p0, const Vec3f& p1, const Vec3f& p2,
                                  float& t, float& u, float& v) {
  return intersect_triangle_mt_edges(ray, p0, p1 - p0, p2 - p0, t, u, v);
}

// Watertight ray/triangle test of Woop, Benthin and Wald, "Watertight Ray/Triangle Intersection",
// JCGT 2(1), 2013. The ray is sheared so it runs along +z from the origin; the 2D edge functions
// are then evaluated on the same values for a shared edge in both triangles, so a ray through an
// edge or vertex hits at least one of the triangles that share it (no cracks).
struct WatertightRay {
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;
  explicit WatertightRay(const Vec3f& d) {
    Vec3f a = vabs(d);
    kz = max_axis(a);
    kx = kz == 2 ? 0 : kz + 1;
    ky = kx == 2 ? 0 : kx + 1;
    if (d[kz] < 0.0f) std::swap(kx, ky);  // keep the winding, so the sign of det keeps its meaning
    sx = d[kx] / d[kz];
    sy = d[ky] / d[kz];
    sz = 1.0f / d[kz];
  }
};

// A product kept out of any fused multiply-add: the compiler may not contract across the empty asm
// (GCC contracts a * b - c * d into an FMA by default, and which product it fuses depends on the
// operand order, so an edge taken in the other direction by the neighbouring triangle would no
// longer give exactly the negated value).
inline float rounded_product(float a, float b) {
  float p = a * b;
#if defined(__x86_64__) || defined(__i386__)
  asm("" : "+x"(p));
#else
  volatile float keep = p;
  p = keep;
#endif
  return p;
}

// The test in float, operation for operation what the BVH's SIMD kernel (bvh_kernels.h) does, so
// both give the same bits. Why float suffices: each product is rounded on its own, so for a shared
// edge the two triangles compute exactly negated edge functions; and rounding is monotonic, so
// fl(p) - fl(q) has the sign of p - q or is zero. Every edge function therefore has the exact sign
// of the edge function of the sheared, rounded corners, or is zero; a zero only accepts more (both
// tests are inclusive). The paper's double-precision fallback at exactly zero is not needed for
// that reason.
inline bool intersect_triangle_watertight(const Ray& ray, const WatertightRay& w, const Vec3f& p0, const Vec3f& p1,
                                          const Vec3f& p2, float& t, float& u, float& v) {
  Vec3f a = p0 - ray.o, b = p1 - ray.o, c = p2 - ray.o;
  float ax = a[w.kx] - rounded_product(w.sx, a[w.kz]), ay = a[w.ky] - rounded_product(w.sy, a[w.kz]);
  float bx = b[w.kx] - rounded_product(w.sx, b[w.kz]), by = b[w.ky] - rounded_product(w.sy, b[w.kz]);
  float cx = c[w.kx] - rounded_product(w.sx, c[w.kz]), cy = c[w.ky] - rounded_product(w.sy, c[w.kz]);
  float e0 = rounded_product(cx, by) - rounded_product(cy, bx);  // weight of p0
  float e1 = rounded_product(ax, cy) - rounded_product(ay, cx);  // weight of p1
  float e2 = rounded_product(bx, ay) - rounded_product(by, ax);  // weight of p2
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) return false;
  float det = (e0 + e1) + e2;
  if (!(std::abs(det) > 0.0f && std::abs(det) < kInf)) return false;
  float az = rounded_product(w.sz, a[w.kz]), bz = rounded_product(w.sz, b[w.kz]), cz = rounded_product(w.sz, c[w.kz]);
  float inv_det = 1.0f / det;
  float tt = rounded_product((rounded_product(e0, az) + rounded_product(e1, bz)) + rounded_product(e2, cz), inv_det);
  if (!(tt > ray.tmin && tt < ray.tmax)) return false;
  t = tt;
  u = rounded_product(e1, inv_det);
  v = rounded_product(e2, inv_det);
  return true;
}

inline bool intersect_triangle_watertight(const Ray& ray, const Vec3f& p0, const Vec3f& p1, const Vec3f& p2,
                                          float& t, float& u, float& v) {
  return intersect_triangle_watertight(ray, WatertightRay(ray.d), p0, p1, p2, t, u, v);
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
