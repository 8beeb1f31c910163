// What the acceleration structures see of a scene: its triangles and its spheres, in world space.
// Kept apart from Scene so that core/accel depends on geometry only, never on materials or lights.
#pragma once
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/sphere.h"

namespace pt {

class Geometry {
 public:
  Geometry() = default;
  Geometry(Mesh mesh, std::vector<Sphere> spheres) : mesh_(std::move(mesh)), spheres_(std::move(spheres)) {
    mesh_.finalize();
  }
  const Mesh& mesh() const { return mesh_; }
  const std::vector<Sphere>& spheres() const { return spheres_; }
  BBox bounds() const {
    BBox b = mesh_.bounds();
    for (const Sphere& s : spheres_) b.expand(s.bounds());
    return b;
  }

 private:
  Mesh mesh_;
  std::vector<Sphere> spheres_;
};

}  // namespace pt
