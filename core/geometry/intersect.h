// Ray/primitive tests shared by both backends (Embree calls intersect_sphere from its user geometry).
#pragma once
#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

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
  static constexpr int kMaxAxis[8] = {2, 1, 2, 1, 2, 2, 0, 0};  // the largest axis by (x > y, x > z, y > z)
  int kx = 0, ky = 1, kz = 2;
  float sx = 0, sy = 0, sz = 1;
  float s2 = 0;  // 2 max(|sx|, |sy|), for the fallback's filter (watertight_near_edge)
  WatertightRay() = default;  // the values set by the caller (the BVH's kernels hold them already)
  // Without a branch on the direction: once per ray, such branches mispredicted about one time in
  // two (the axes of max_axis and Vec3f::operator[], whose index is a variable here).
  explicit WatertightRay(const Vec3f& d) {
    const float c[3] = {d.x, d.y, d.z};
    float ax = std::abs(d.x), ay = std::abs(d.y), az = std::abs(d.z);
    // max_axis(vabs(d)), ties alike, by table (GCC turns the conditional forms back into branches)
    static constexpr int kNext[3] = {1, 2, 0};
    kz = kMaxAxis[(int(ax > ay) << 2) | (int(ax > az) << 1) | int(ay > az)];
    kx = kNext[kz];
    ky = kNext[kx];
    int swap = (kx ^ ky) & -static_cast<int>(c[kz] < 0.0f);  // keep the winding, so the sign of det keeps its meaning
    kx ^= swap;
    ky ^= swap;
#if defined(__SSE2__)
    // The three quotients in one division: the same bits as three (each lane is correctly rounded).
    alignas(16) float q[4];
    _mm_store_ps(q, _mm_div_ps(_mm_setr_ps(c[kx], c[ky], 1.0f, 1.0f), _mm_set1_ps(c[kz])));
    sx = q[0];
    sy = q[1];
    sz = q[2];
#else
    sx = c[kx] / c[kz];
    sy = c[ky] / c[kz];
    sz = 1.0f / c[kz];
#endif
    s2 = 2.0f * std::max(std::abs(sx), std::abs(sy));
  }
};

// A product kept out of any fused multiply-add: the compiler may not contract across the empty asm
// (GCC contracts a * b - c * d into an FMA by default, and which product it fuses depends on the
// operand order, so an edge taken in the other direction by the neighbouring triangle would no
// longer give exactly the negated value).
// Floats, and doubles for the edge functions of the fallback below.
template <class T>
inline T rounded_product(T a, T b) {
  T p = a * b;
#if defined(__x86_64__) || defined(__i386__)
  asm("" : "+x"(p));
#else
  volatile T keep = p;
  p = keep;
#endif
  return p;
}

// Float rounding of the shear (a_x - s_x a_z, where a_z, the distance along the ray, can be
// hundreds of times the triangle's size in the ray's view) can give an edge function the wrong
// sign when the ray passes within about 1e-6 of the edge, relative to the corners' distance. At a
// silhouette, where the two triangles on an edge face opposite ways and so lie on one side of it
// in the ray's view, the ray then misses both (the Chinese dragon scan had one such ray in 1 M).
// Hence a fallback on the float test's rejections: an edge function whose magnitude is within its
// rounding error bound (`watertight_edge_bound`) is computed again in double from the float
// corners and the unrounded shear d_x / d_z, which gives the exact sign unless the ray passes
// 2^29 times nearer still. The bound and the double value are functions of the edge's two corners
// alone, symmetric in them, and the double value is formed like the float one, so the two
// triangles on a shared edge take the same branch and compute exactly negated values: the fallback
// keeps the test watertight. The paper's fallback (at exactly zero) covers rounding in the edge
// function's own products, which float already handles (see below), not in the shear.
//
// The bound: with u = 2^-24 and m_x = |x| + 2 |s_x| |z| (likewise m_y), each sheared coordinate
// is within 2u m of its exact value, so the edge function q_x p_y - q_y p_x is within
// 4u T + 8u^2 S of the exact one, T = |p_x| m_qy + m_px |q_y| + |p_y| m_qx + m_py |q_x| and
// S = m_px m_qy + m_py m_qx; the bound is twice that or more, 2^-20 T + 2^-44 S, in double (the
// products of floats exact). T, not 2S: a ray near a small triangle far away has small |x|, |y|
// and large m, and a bound in m alone was 10^4 times too wide there (on primary rays at dense-82k
// it sent so many lanes to the fallback that they took 1.3x the time).
struct WatertightCorner {
  float x, y, z;    // sheared x, y and the distance along kz, as the float test forms them
  float mx, my;     // the magnitudes the error bound scales with
  double dx, dy;    // x and y sheared in double
};

// The double shear d_x / d_z, d_y / d_z of the fallback, once per triangle (not per corner: two
// double divisions each).
struct WatertightShear {
  double sx, sy;
  WatertightShear(const Ray& ray, const WatertightRay& w)
      : sx(double(ray.d[w.kx]) / double(ray.d[w.kz])), sy(double(ray.d[w.ky]) / double(ray.d[w.kz])) {}
};

inline WatertightCorner watertight_corner(const Ray& ray, const WatertightRay& w, const WatertightShear& s,
                                          const Vec3f& p) {
  WatertightCorner c;
  Vec3f a = p - ray.o;
  c.z = a[w.kz];
  c.x = a[w.kx] - rounded_product(w.sx, a[w.kz]);
  c.y = a[w.ky] - rounded_product(w.sy, a[w.kz]);
  float az = std::abs(a[w.kz]);
  c.mx = std::abs(c.x) + rounded_product(2.0f * std::abs(w.sx), az);
  c.my = std::abs(c.y) + rounded_product(2.0f * std::abs(w.sy), az);
  double z = double(p[w.kz]) - double(ray.o[w.kz]);
  c.dx = (double(p[w.kx]) - double(ray.o[w.kx])) - rounded_product(s.sx, z);
  c.dy = (double(p[w.ky]) - double(ray.o[w.ky])) - rounded_product(s.sy, z);
  return c;
}

inline WatertightCorner watertight_corner(const Ray& ray, const WatertightRay& w, const Vec3f& p) {
  return watertight_corner(ray, w, WatertightShear(ray, w), p);
}

// The error bound of the edge from p to q; from q to p the same terms in the same pairs. Its two
// factors are named once: the SIMD kernels' filter (edges_within_bounds in bvh_kernels.h) forms
// the same bound in float.
constexpr float kWatertightEdgeBoundT = 0x1p-20f, kWatertightEdgeBoundS = 0x1p-44f;
inline double watertight_edge_bound(const WatertightCorner& p, const WatertightCorner& q) {
  auto m = [](float a, float b) { return rounded_product(double(a), double(b)); };
  double t = (m(std::abs(p.x), q.my) + m(p.my, std::abs(q.x))) + (m(p.mx, std::abs(q.y)) + m(std::abs(p.y), q.mx));
  return double(kWatertightEdgeBoundT) * t + double(kWatertightEdgeBoundS) * (m(p.mx, q.my) + m(p.my, q.mx));
}

// The edge function of the edge from p to q, q_x p_y - q_y p_x (so from q to p it is exactly
// negated), in float, and again in double where the float value is within its bound.
inline double watertight_edge(const WatertightCorner& p, const WatertightCorner& q) {
  float e = rounded_product(q.x, p.y) - rounded_product(q.y, p.x);
  if (std::abs(e) > watertight_edge_bound(p, q)) return e;
  return rounded_product(q.dx, p.dy) - rounded_product(q.dy, p.dx);
}

// The fallback itself, for a triangle the float test rejected with edge functions of both signs.
inline bool intersect_triangle_watertight_refined(const Ray& ray, const WatertightRay& w, const Vec3f& p0,
                                                  const Vec3f& p1, const Vec3f& p2, float tmax, float& t, float& u,
                                                  float& v) {
  const WatertightShear s(ray, w);
  WatertightCorner a = watertight_corner(ray, w, s, p0), b = watertight_corner(ray, w, s, p1),
                   c = watertight_corner(ray, w, s, p2);
  double e0 = watertight_edge(b, c), e1 = watertight_edge(c, a), e2 = watertight_edge(a, b);
  if ((e0 < 0 || e1 < 0 || e2 < 0) && (e0 > 0 || e1 > 0 || e2 > 0)) return false;
  double det = (e0 + e1) + e2;
  if (!(std::abs(det) > 0 && std::abs(det) < 1e300)) return false;
  double tz = (e0 * double(a.z) + e1 * double(b.z)) + e2 * double(c.z);
  float tt = static_cast<float>(tz / (det * double(ray.d[w.kz])));
  if (!(tt > ray.tmin && tt < tmax)) return false;
  t = tt;
  u = static_cast<float>(e1 / det);
  v = static_cast<float>(e2 / det);
  return true;
}

// A bound on every edge's watertight_edge_bound of a triangle, from mxy = max |x|, |y| over its
// corners and n = mxy + 2 max(|s_x|, |s_y|) max |z| >= every m (in float too: rounding is
// monotonic): T <= 4 mxy n and S <= 2 n^2, so 2^-18 mxy n + 2^-43 n^2 does; the factor
// 1 + 2^-20 covers its three roundings (and the double bound's own). A rejection can turn into a
// hit only where every edge function of one sign is within its bound, so min(-lo, hi) is within
// this one; a lane beyond it gets the float answer, which the fallback would give too (a looser
// threshold only sends lanes to the fallback for nothing: on a field of far instances, many). The
// SIMD kernels compute it on all lanes, in these operations and with these constants, and then,
// for the few lanes it lets through, each edge against its own bound (edges_within_bounds in
// bvh_kernels.h), which the fallback's answer does not change either.
constexpr float kWatertightThresholdN = 0x1p-25f;
constexpr float kWatertightThresholdScale = 0x1p-18f * (1.0f + 0x1p-20f);
inline float watertight_threshold(float mxy, float n) {
  return rounded_product(rounded_product(n, mxy + rounded_product(n, kWatertightThresholdN)), kWatertightThresholdScale);
}

// Whether the float test's rejection of a triangle should go to the fallback: edge functions of
// both signs (lo < 0 < hi), and those of one sign all within the threshold above. Only where this
// holds can the fallback turn the rejection into a hit.
inline bool watertight_near_edge(float lo, float hi, float threshold) {
  return lo < 0.0f && hi > 0.0f && std::min(-lo, hi) <= threshold;
}

// The test in float, operation for operation what the BVH's SIMD kernel (bvh_kernels.h) does, so
// both give the same bits. Why float suffices for rounding in the edge functions' products: each
// product is rounded on its own, so for a shared edge the two triangles compute exactly negated
// edge functions; and rounding is monotonic, so fl(p) - fl(q) has the sign of p - q or is zero.
// Every edge function therefore has the exact sign of the edge function of the sheared, rounded
// corners, or is zero; a zero only accepts more (both tests are inclusive). The rounding of the
// shear itself is what the fallback above is for.
inline bool intersect_triangle_watertight(const Ray& ray, const WatertightRay& w, const Vec3f& p0, const Vec3f& p1,
                                          const Vec3f& p2, float& t, float& u, float& v) {
  Vec3f a = p0 - ray.o, b = p1 - ray.o, c = p2 - ray.o;
  float ax = a[w.kx] - rounded_product(w.sx, a[w.kz]), ay = a[w.ky] - rounded_product(w.sy, a[w.kz]);
  float bx = b[w.kx] - rounded_product(w.sx, b[w.kz]), by = b[w.ky] - rounded_product(w.sy, b[w.kz]);
  float cx = c[w.kx] - rounded_product(w.sx, c[w.kz]), cy = c[w.ky] - rounded_product(w.sy, c[w.kz]);
  float e0 = rounded_product(cx, by) - rounded_product(cy, bx);  // weight of p0
  float e1 = rounded_product(ax, cy) - rounded_product(ay, cx);  // weight of p1
  float e2 = rounded_product(bx, ay) - rounded_product(by, ax);  // weight of p2
  if ((e0 < 0.0f || e1 < 0.0f || e2 < 0.0f) && (e0 > 0.0f || e1 > 0.0f || e2 > 0.0f)) {
    float mxy = std::max({std::abs(ax), std::abs(ay), std::abs(bx), std::abs(by), std::abs(cx), std::abs(cy)});
    float mz = std::max({std::abs(a[w.kz]), std::abs(b[w.kz]), std::abs(c[w.kz])});
    float n = mxy + rounded_product(w.s2, mz);
    if (!watertight_near_edge(std::min({e0, e1, e2}), std::max({e0, e1, e2}), watertight_threshold(mxy, n))) return false;
    return intersect_triangle_watertight_refined(ray, w, p0, p1, p2, ray.tmax, t, u, v);
  }
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
