// Analytic spheres: drawn by both backends with the same intersection routine.
#pragma once
#include <cmath>
#include <cstdint>

#include "core/math/bbox.h"

namespace pt {

struct Sphere {
  Vec3f center;
  float radius = 1.0f;
  uint32_t material = 0;
  // Rounded outward: far from the origin center +- radius can round back to the center (1e6 +
  // 0.01 is 1e6 in float), and a box that small would cull rays that hit the sphere.
  BBox bounds() const {
    BBox b;
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = std::nextafter(center[a] - radius, -kInf);
      b.hi[a] = std::nextafter(center[a] + radius, kInf);
    }
    return b;
  }
  float area() const { return 4.0f * kPi * radius * radius; }
};

}  // namespace pt
