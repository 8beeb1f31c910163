// Clipping a triangle to boxes and slabs, for the spatial splits of the BVH builder (Stich, Friedrich
// and Dietrich, "Spatial Splits in Bounding Volume Hierarchies", HPG 2009): a reference to part of a
// triangle is bounded by the box of the triangle's intersection with a region, not by the region.
// The polygon is clipped in double (Sutherland-Hodgman) and its bounds rounded outward to float, so
// a part's box always contains the part.
#pragma once
#include <cmath>

#include "core/math/bbox.h"

namespace pt::bvh {

// A convex polygon: a triangle clipped by at most eight planes has at most eleven vertices.
struct ClipPolygon {
  static constexpr int kMax = 12;
  double v[kMax][3];
  int n = 0;
};

inline ClipPolygon triangle_polygon(const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  ClipPolygon p;
  for (const Vec3f* q : {&a, &b, &c}) {
    p.v[p.n][0] = q->x;
    p.v[p.n][1] = q->y;
    p.v[p.n][2] = q->z;
    ++p.n;
  }
  return p;
}

// Keeps the part with sign * (x[axis] - at) >= 0.
inline ClipPolygon clip_plane(const ClipPolygon& in, int axis, double at, double sign) {
  ClipPolygon out;
  for (int i = 0; i < in.n; ++i) {
    const double* p = in.v[i];
    const double* q = in.v[(i + 1) % in.n];
    double dp = sign * (p[axis] - at), dq = sign * (q[axis] - at);
    if (dp >= 0 && out.n < ClipPolygon::kMax) {
      for (int k = 0; k < 3; ++k) out.v[out.n][k] = p[k];
      ++out.n;
    }
    if ((dp < 0 && dq > 0) || (dp > 0 && dq < 0)) {
      double s = dp / (dp - dq);
      if (out.n < ClipPolygon::kMax) {
        for (int k = 0; k < 3; ++k) out.v[out.n][k] = p[k] + s * (q[k] - p[k]);
        out.v[out.n][axis] = at;  // exactly on the plane
        ++out.n;
      }
    }
  }
  return out;
}

inline ClipPolygon clip_slab(const ClipPolygon& in, int axis, double lo, double hi) {
  return clip_plane(clip_plane(in, axis, lo, 1.0), axis, hi, -1.0);
}

inline ClipPolygon clip_box(ClipPolygon p, const BBox& box) {
  for (int axis = 0; axis < 3 && p.n > 0; ++axis) p = clip_slab(p, axis, box.lo[axis], box.hi[axis]);
  return p;
}

// The float box around the polygon (clipped from a triangle with bounds `triangle`), rounded
// outward, cut down to `limit` (which the exact polygon lies in). Empty when the polygon is.
inline BBox polygon_bounds(const ClipPolygon& p, const BBox& limit, const BBox& triangle) {
  BBox b;
  if (p.n == 0) return b;
  for (int axis = 0; axis < 3; ++axis) {
    double lo = p.v[0][axis], hi = p.v[0][axis];
    for (int i = 1; i < p.n; ++i) {
      lo = std::min(lo, p.v[i][axis]);
      hi = std::max(hi, p.v[i][axis]);
    }
    // A computed crossing point is off by a few double ulps of the triangle's coordinates; widening
    // by 2^-40 of them (far less than a float ulp) covers that.
    double slack = std::ldexp(std::max(std::abs(triangle.lo[axis]), std::abs(triangle.hi[axis])), -40);
    lo -= slack;
    hi += slack;
    float flo = static_cast<float>(lo), fhi = static_cast<float>(hi);
    if (static_cast<double>(flo) > lo) flo = std::nextafter(flo, -kInf);
    if (static_cast<double>(fhi) < hi) fhi = std::nextafter(fhi, kInf);
    b.lo[axis] = std::max(flo, limit.lo[axis]);
    b.hi[axis] = std::min(fhi, limit.hi[axis]);
  }
  return b;
}

}  // namespace pt::bvh
