// Orthonormal frame around a normal, for local shading coordinates (z = normal).
#pragma once
#include "core/math/vec.h"

namespace pt {

struct Frame {
  Vec3f s, t, n;
  Frame() = default;
  // Branchless construction: Duff et al., "Building an Orthonormal Basis, Revisited", JCGT 2017.
  explicit Frame(const Vec3f& normal) : n(normal) {
    float sign = std::copysign(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float b = n.x * n.y * a;
    s = {1.0f + sign * n.x * n.x * a, sign * b, -sign * n.x};
    t = {b, sign + n.y * n.y * a, -n.y};
  }
  Vec3f to_local(const Vec3f& v) const { return {dot(v, s), dot(v, t), dot(v, n)}; }
  Vec3f to_world(const Vec3f& v) const { return s * v.x + t * v.y + n * v.z; }
};

}  // namespace pt
