// Rays and the hit record a backend returns: the contract both acceleration structures share.
#pragma once
#include <cstdint>

#include "core/math/vec.h"

namespace pt {

struct Ray {
  Vec3f o, d;
  float tmin = 0.0f, tmax = kInf;
};

// Geometry ids: the world-space triangles form one mesh, all spheres one set (a scene without spheres
// has none). A triangle of an instanced mesh is kGeomTriangles with the instance in Hit::inst.
constexpr uint32_t kGeomTriangles = 0;
constexpr uint32_t kGeomSpheres = 1;
// Hit::inst of world-space geometry (the world mesh, spheres).
constexpr uint32_t kNoInstance = UINT32_MAX;

struct Hit {
  float t = kInf;
  uint32_t geom = 0, prim = 0;
  float u = 0, v = 0;  // triangle barycentrics of vertices 1 and 2; unused for spheres
  uint32_t inst = kNoInstance;  // the instance whose mesh holds triangle `prim` (Geometry::instances())
};

}  // namespace pt
