// What the acceleration structures see of a scene: its world-space triangles and spheres, and its
// instances (an object-space mesh placed by a transform, core/geometry/instance.h). Kept apart from
// Scene so that core/accel depends on geometry only, never on materials or lights.
#pragma once
#include <vector>

#include "core/geometry/instance.h"
#include "core/geometry/mesh.h"
#include "core/geometry/sphere.h"

namespace pt {

class Geometry {
 public:
  Geometry() = default;
  // `meshes` are object-space meshes, each placed by the `instances` that name it.
  Geometry(Mesh mesh, std::vector<Sphere> spheres, std::vector<Mesh> meshes = {}, std::vector<Instance> instances = {});
  const Mesh& mesh() const { return mesh_; }
  const std::vector<Sphere>& spheres() const { return spheres_; }
  // One Geometry per instanced mesh, in the mesh's own space (a mesh and no spheres, no instances):
  // each backend builds its bottom level over these as it would over a scene.
  const std::vector<Geometry>& objects() const { return objects_; }
  const std::vector<Instance>& instances() const { return instances_; }
  const Mesh& instance_mesh(uint32_t inst) const { return objects_[instances_[inst].mesh].mesh(); }
  // Every triangle as it lies in the world, counting each instance's.
  size_t world_triangle_count() const;
  BBox bounds() const { return bounds_; }

 private:
  Mesh mesh_;
  std::vector<Sphere> spheres_;
  std::vector<Geometry> objects_;
  std::vector<Instance> instances_;
  BBox bounds_;
};

}  // namespace pt
