// A ray's hit turned into what shading needs: point, normals, uv, material.
#pragma once
#include <cstdint>

#include "core/geometry/ray.h"
#include "core/math/vec.h"

namespace pt {

struct SurfaceInteraction {
  Vec3f p;
  Vec3f ng;  // unit geometric normal, front face (triangle winding / sphere outside)
  Vec3f ns;  // unit shading normal, on the same side as ng
  Vec2f uv;
  Vec3f color{1.0f};  // the vertex colour (Mesh::corner_colors), white where there is none
  uint32_t material = 0;
  uint32_t geom = 0, prim = 0;
  uint32_t inst = kNoInstance;  // as Hit::inst
};

}  // namespace pt
