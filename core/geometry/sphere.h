// Analytic spheres: drawn by both backends with the same intersection routine.
#pragma once
#include <cstdint>

#include "core/math/bbox.h"

namespace pt {

struct Sphere {
  Vec3f center;
  float radius = 1.0f;
  uint32_t material = 0;
  BBox bounds() const {
    BBox b;
    b.lo = center - Vec3f(radius);
    b.hi = center + Vec3f(radius);
    return b;
  }
  float area() const { return 4.0f * kPi * radius * radius; }
};

}  // namespace pt
