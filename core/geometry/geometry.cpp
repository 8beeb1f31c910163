#include "core/geometry/geometry.h"

namespace pt {

Geometry::Geometry(Mesh mesh, std::vector<Sphere> spheres, std::vector<Mesh> meshes, std::vector<Instance> instances)
    : mesh_(std::move(mesh)), spheres_(std::move(spheres)), instances_(std::move(instances)) {
  mesh_.finalize();
  objects_.reserve(meshes.size());
  for (Mesh& m : meshes) objects_.emplace_back(std::move(m), std::vector<Sphere>{});
  bounds_ = mesh_.bounds();
  for (const Sphere& s : spheres_) bounds_.expand(s.bounds());
  std::vector<const Mesh*> object_meshes;
  for (const Geometry& o : objects_) object_meshes.push_back(&o.mesh());
  bounds_.expand(instances_bounds(object_meshes, instances_));
}

size_t Geometry::world_triangle_count() const {
  size_t n = mesh_.triangle_count();
  for (const Instance& i : instances_) n += objects_[i.mesh].mesh().triangle_count();
  return n;
}

}  // namespace pt
