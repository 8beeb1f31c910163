#include "core/scene/mirror_planes.h"

#include <cmath>

namespace pt {
namespace {

class PlaneFinder {
 public:
  PlaneFinder(std::vector<MirrorPlane>& planes, float scene_size)
      : planes_(planes), offset_tolerance_(1e-5f * std::max(scene_size, 1e-6f)) {}

  // The plane of the triangle with first vertex p0 and (unnormalised) geometric normal g, or -1
  // for a degenerate triangle.
  int add(const Vec3f& p0, const Vec3f& g) {
    float len = length(g);
    if (!(len > 0) || !std::isfinite(len)) return -1;
    Vec3f n = g / len;
    float d = dot(n, p0);
    int found = -1;
    for (size_t i = 0; i < planes_.size() && found < 0; ++i) {
      float c = dot(planes_[i].n, n);
      // Opposite windings of one plane are one mirror: both faces reflect.
      float s = c < 0 ? -1.0f : 1.0f;
      if (std::abs(c) > 1.0f - 1.5e-7f && std::abs(s * d - planes_[i].d) <= offset_tolerance_) found = static_cast<int>(i);
    }
    if (found < 0) {
      planes_.push_back({n, d, 0, 0.0f});
      found = static_cast<int>(planes_.size() - 1);
    }
    ++planes_[found].triangles;
    planes_[found].area += 0.5f * len;
    return found;
  }

 private:
  std::vector<MirrorPlane>& planes_;
  float offset_tolerance_;
};

// A BSDF of one delta reflection lobe is a perfect mirror; sampling through it takes its albedo as
// the tint at every angle (integrators/mirror_light.cpp), which a mirror's reflectance is.
bool is_mirror(const std::vector<Material>& materials, uint32_t m) {
  return materials[m].flags() == (kBsdfReflection | kBsdfDelta);
}

}  // namespace

std::vector<MirrorPlane> find_mirror_planes(const Geometry& geometry, const std::vector<Material>& materials,
                                            float scene_size, MirrorPlaneIndex& index) {
  std::vector<MirrorPlane> planes;
  index.clear();
  PlaneFinder finder(planes, scene_size);
  const Mesh& mesh = geometry.mesh();
  for (size_t t = 0; t < mesh.triangle_count(); ++t) {
    if (!is_mirror(materials, mesh.material[t])) continue;
    int plane = finder.add(mesh.vertex(t, 0), mesh.geometric_normal(t));
    if (plane < 0) continue;
    if (index.world.empty()) index.world.assign(mesh.triangle_count(), -1);
    index.world[t] = plane;
  }
  // Instances: each mirror triangle placed in the world, as the mesh baked there would have it.
  const std::vector<Instance>& instances = geometry.instances();
  std::vector<size_t> mirrors(geometry.objects().size(), 0);
  size_t total = 0;
  for (size_t m = 0; m < mirrors.size(); ++m) {
    for (uint32_t mat : geometry.objects()[m].mesh().material) mirrors[m] += is_mirror(materials, mat);
  }
  for (const Instance& i : instances) total += mirrors[i.mesh];
  if (total == 0 || total > kMaxInstancedMirrorTriangles) return planes;
  index.instances.resize(instances.size());
  for (size_t i = 0; i < instances.size(); ++i) {
    if (mirrors[instances[i].mesh] == 0) continue;
    const Mesh& object = geometry.instance_mesh(static_cast<uint32_t>(i));
    const Transform& to_world = instances[i].to_world;
    index.instances[i].assign(object.triangle_count(), -1);
    for (size_t t = 0; t < object.triangle_count(); ++t) {
      if (!is_mirror(materials, object.material[t])) continue;
      Vec3f p0 = to_world.point(object.vertex(t, 0));
      Vec3f g = cross(to_world.point(object.vertex(t, 1)) - p0, to_world.point(object.vertex(t, 2)) - p0);
      index.instances[i][t] = finder.add(p0, g);
    }
  }
  return planes;
}

}  // namespace pt
