// A ray's hit turned into what shading needs: point, normals, uv, material, and, where the scene has
// surface textures, the surface's derivatives and the footprint of the ray on it.
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
  // Set only where the scene has surface textures (Scene::textured()), else zero. The derivatives
  // of the surface point along u and v (zero where the uv map is degenerate); the interpolated
  // tangent (along increasing u) and handedness (the bitangent is tangent_sign * cross(ns, tangent))
  // where the mesh has tangents; the ray's footprint (core/scene/footprint.h): how the point and uv
  // move from this pixel's ray to its neighbours'. A zero footprint means point lookups.
  Vec3f dpdu, dpdv;
  Vec3f tangent;
  float tangent_sign = 1.0f;
  Vec3f dpdx, dpdy;
  Vec2f duvdx{0.0f, 0.0f}, duvdy{0.0f, 0.0f};
  Vec2f duv_centre{0.0f, 0.0f};  // uv from the hit to the footprint's centre (RayDifferential::centre)
  bool rough_footprint = false;  // RayDifferential::rough: filter isotropically
};

}  // namespace pt
