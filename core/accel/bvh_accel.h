// The home-written BVH backend: a reference to validate Embree against, and a yardstick.
#pragma once
#include "core/accel/accel.h"

namespace pt {

std::unique_ptr<Accel> make_bvh_accel(const Geometry& scene, TriangleTest test);

}  // namespace pt
