// Flat mirrors: the scene's perfect-mirror triangles grouped by the plane they lie in. The path
// tracer samples lights through each plane by the method of images (see integrators/mirror_light.h).
#pragma once
#include <cstdint>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/material/material.h"

namespace pt {

struct MirrorPlane {
  Vec3f n;         // unit normal (either side: pt's mirrors reflect on both faces)
  float d = 0;     // the plane is dot(n, p) = d
  size_t triangles = 0;
  float area = 0;
  float signed_distance(const Vec3f& p) const { return dot(n, p) - d; }
  Vec3f reflect_point(const Vec3f& p) const { return p - n * (2.0f * signed_distance(p)); }
  Vec3f reflect_direction(const Vec3f& w) const { return w - n * (2.0f * dot(n, w)); }
};

// The plane each mirror triangle lies in, by (instance, triangle): world triangles by index (empty
// when none is a mirror), an instance's by the triangle of its mesh (empty for an instance of a mesh
// without mirrors).
struct MirrorPlaneIndex {
  std::vector<int32_t> world;
  std::vector<std::vector<int32_t>> instances;
  int of(uint32_t geom, uint32_t prim, uint32_t inst) const {
    if (geom != kGeomTriangles) return -1;
    if (inst == kNoInstance) return world.empty() ? -1 : world[prim];
    return inst < instances.size() && !instances[inst].empty() ? instances[inst][prim] : -1;
  }
  void clear() {
    world.clear();
    instances.clear();
  }
};

// Groups the non-degenerate triangles whose material is a mirror into planes (normals within
// about 0.03 degrees, offsets within 1e-5 of the scene's size): the world mesh's first, then each
// instance's, in world space. Instanced mirrors are grouped only while they number at most
// kMaxInstancedMirrorTriangles in all (each instance's triangles are planes of their own in the
// world); beyond, they are left to BSDF sampling.
constexpr size_t kMaxInstancedMirrorTriangles = size_t(1) << 20;
std::vector<MirrorPlane> find_mirror_planes(const Geometry& geometry, const std::vector<Material>& materials,
                                            float scene_size, MirrorPlaneIndex& index);

}  // namespace pt
