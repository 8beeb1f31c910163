// Flat mirrors: the scene's perfect-mirror triangles grouped by the plane they lie in. The path
// tracer samples lights through each plane by the method of images (see integrators/mirror_light.h).
#pragma once
#include <cstdint>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/scene/material.h"

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

// Groups the non-degenerate triangles whose material is a mirror into planes (normals within
// about 0.03 degrees, offsets within 1e-5 of the scene's size). plane_of[t] is the plane index of
// triangle t, or -1; it is left empty when there are no mirror triangles.
std::vector<MirrorPlane> find_mirror_planes(const Mesh& mesh, const std::vector<Material>& materials, float scene_size,
                                            std::vector<int32_t>& plane_of);

}  // namespace pt
