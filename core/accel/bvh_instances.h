// The BVH backend for a scene with instances: two levels. The bottom level is the ordinary BVH
// (bvh_accel.*), one per instanced mesh in the mesh's own space and one over the world-space mesh
// and spheres; the top level is a binary BVH over the instances' world boxes, built by the same
// SAH builder (bvh_build.h). A ray that reaches an instance's leaf is taken into the mesh's space by
// the instance's inverse transform and traced there; with an affine transform and the direction
// left unnormalised, t means the same distance along the ray in both spaces.
#pragma once
#include "core/accel/accel.h"

namespace pt {

std::unique_ptr<Accel> make_instanced_bvh_accel(const Geometry& geometry, TriangleTest test);

}  // namespace pt
