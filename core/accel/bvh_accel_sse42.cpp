// The BVH's traversal and kernels for SSE4.2: four-lane packs, nodes one child at a time.
// Chosen at start-up by bvh_accel.cpp when the CPU supports them. Everything shared is included
// before the #pragma (so its out-of-line copies stay baseline code); bvh_traversal.h and
// bvh_kernels.h after it, in their own namespace.
#include <immintrin.h>

#include <bit>
#include <chrono>
#include <cstring>
#include <memory>

#include "core/accel/accel.h"
#include "core/accel/bvh_build.h"
#include "core/accel/bvh_isa.h"
#include "core/geometry/geometry.h"
#include "core/geometry/instance.h"
#include "core/geometry/intersect.h"

#pragma GCC target("sse4.2,popcnt")
#define PT_BVH_ISA sse42
#define PT_BVH_AVX2 0
#include "core/accel/bvh_traversal.h"
#include "core/accel/bvh_two_level.h"

namespace pt::bvh {

std::unique_ptr<Accel> make_accel_sse42(const Geometry& scene, TriangleTest test, const BuildOptions& options) {
  return sse42::make_accel(scene, test, options);
}

std::unique_ptr<Accel> make_two_level_accel_sse42(const Geometry& geometry, TriangleTest test) {
  return sse42::make_two_level_accel(geometry, test);
}

}  // namespace pt::bvh
