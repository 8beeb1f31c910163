// The BVH backend for a scene with instances: two levels, the top one an 8-wide tree over the
// instances' world boxes whose leaves trace the instanced meshes' own trees (bvh_two_level.h,
// compiled with each instruction set's traversal; the copy is chosen as for make_bvh_accel).
#pragma once
#include "core/accel/accel.h"

namespace pt {

std::unique_ptr<Accel> make_instanced_bvh_accel(const Geometry& geometry, TriangleTest test);

}  // namespace pt
