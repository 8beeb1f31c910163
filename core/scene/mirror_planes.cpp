#include "core/scene/mirror_planes.h"

#include <cmath>

namespace pt {

std::vector<MirrorPlane> find_mirror_planes(const Mesh& mesh, const std::vector<Material>& materials, float scene_size,
                                            std::vector<int32_t>& plane_of) {
  std::vector<MirrorPlane> planes;
  plane_of.clear();
  const float offset_tolerance = 1e-5f * std::max(scene_size, 1e-6f);
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (materials[mesh.material[t]].type != MaterialType::kMirror) continue;
    Vec3f g = mesh.geometric_normal(t);
    float len = length(g);
    if (!(len > 0) || !std::isfinite(len)) continue;
    Vec3f n = g / len;
    float d = dot(n, mesh.vertex(t, 0));
    if (plane_of.empty()) plane_of.assign(mesh.triangle_count(), -1);
    int found = -1;
    for (size_t i = 0; i < planes.size() && found < 0; ++i) {
      float c = dot(planes[i].n, n);
      // Opposite windings of one plane are one mirror: both faces reflect.
      float s = c < 0 ? -1.0f : 1.0f;
      if (std::abs(c) > 1.0f - 1.5e-7f && std::abs(s * d - planes[i].d) <= offset_tolerance) found = static_cast<int>(i);
    }
    if (found < 0) {
      planes.push_back({n, d, 0, 0.0f});
      found = static_cast<int>(planes.size() - 1);
    }
    plane_of[t] = found;
    ++planes[found].triangles;
    planes[found].area += 0.5f * len;
  }
  return planes;
}

}  // namespace pt
