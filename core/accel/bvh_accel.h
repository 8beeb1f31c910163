// The home-written BVH backend: a reference to validate Embree against, and a yardstick.
#pragma once
#include "core/accel/accel.h"

namespace pt {

namespace bvh {
struct BuildOptions;
}

std::unique_ptr<Accel> make_bvh_accel(const Geometry& geometry, TriangleTest test);
// With other build settings than the defaults (for the tests and benchmarks of the builder).
std::unique_ptr<Accel> make_bvh_accel(const Geometry& geometry, TriangleTest test, const bvh::BuildOptions& options);

}  // namespace pt
