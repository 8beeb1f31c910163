// Axis-aligned bounding box, used by scene bounds, the default camera and the BVH.
#pragma once
#include "core/math/vec.h"

namespace pt {

struct BBox {
  Vec3f lo{kInf}, hi{-kInf};
  void expand(const Vec3f& p) { lo = vmin(lo, p); hi = vmax(hi, p); }
  void expand(const BBox& b) { lo = vmin(lo, b.lo); hi = vmax(hi, b.hi); }
  bool empty() const { return lo.x > hi.x || lo.y > hi.y || lo.z > hi.z; }
  Vec3f extent() const { return hi - lo; }
  Vec3f center() const { return (lo + hi) * 0.5f; }
  float surface_area() const {
    if (empty()) return 0.0f;
    Vec3f e = extent();
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
  bool contains(const BBox& b) const {
    return b.lo.x >= lo.x && b.lo.y >= lo.y && b.lo.z >= lo.z && b.hi.x <= hi.x && b.hi.y <= hi.y &&
           b.hi.z <= hi.z;
  }
};

}  // namespace pt
