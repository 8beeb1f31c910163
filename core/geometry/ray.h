// Rays and the hit record a backend returns: the contract both acceleration structures share.
#pragma once
#include <cstdint>

#include "core/math/vec.h"

namespace pt {

// How a ray's neighbours run beside it (Igehy 1999, "Tracing Ray Differentials"): the ray one pixel
// to the right passes through o + dodx + s (d + dddx), the one below likewise with dody, dddy. The
// camera makes them (Camera::ray with a pixel step); textures are filtered over the footprint they
// cut out of the surface hit (core/scene/footprint.h). All zero: no footprint, point lookups
// (shadow rays, tests). The backends never read them.
struct RayDifferential {
  Vec3f dodx, dody, dddx, dddy;
  // How much of a pixel one sample stands for: one cell of the pixel's stratification grid,
  // 1 / Camera::footprint_strata(spp), within [1/8, 1] (pbrt 3rd ed. 10.1.1 scales by 1/sqrt(spp)):
  // the footprint shrinks as samples accumulate. Bounces widen the footprint by this much of their lobe's width.
  float scale = 0.0f;
  // After a diffuse or glossy bounce: what the ray finds is integrated over the lobe, so textures
  // are filtered isotropically over the footprint's longer axis (one probe, not an anisotropic
  // series: the detail lost does not show in indirect light).
  bool rough = false;
  // Camera rays: where the footprint is centred, as a multiple of the differentials (each within
  // [-1/2, 1/2]): the centre of the cell of the pixel's stratification grid that holds the sample
  // (Camera::footprint_strata). A footprint one cell wide centred there filters the texture over
  // the cell, so a pixel's samples average to the texture's mean over the pixel whatever the jitter.
  Vec2f centre{0.0f, 0.0f};
  // A bounce ray's direction differentials, not made yet (bounce_differential, core/scene/footprint.h):
  // when above zero, dddx and dddy are this spread times the two unit vectors across the ray
  // (Frame(d).s and .t), made by direction_differentials() only where the ray meets a surface that needs them;
  // most bounce rays of a sky-lit scene never do.
  float spread = 0.0f;
  bool empty() const { return scale == 0.0f; }
};

struct Ray {
  Vec3f o, d;
  float tmin = 0.0f, tmax = kInf;
  RayDifferential diff{};  // an initializer, so aggregates that leave it out compile quietly
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
