// The BVH's traversal and kernels for the AVX2 kernels compiled for AVX-512 (EVEX encodings, 32 vector registers, mask compares).
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

#pragma GCC target("avx512f,avx512vl,avx512bw,avx512dq,avx2,fma,bmi,bmi2,lzcnt,popcnt")
#define PT_BVH_ISA avx512
#define PT_BVH_AVX2 1
#define PT_BVH_AVX512 1
#include "core/accel/bvh_traversal.h"
#include "core/accel/bvh_two_level.h"

namespace pt::bvh {

std::unique_ptr<Accel> make_accel_avx512(const Geometry& scene, TriangleTest test, const BuildOptions& options) {
  return avx512::make_accel(scene, test, options);
}

std::unique_ptr<Accel> make_two_level_accel_avx512(const Geometry& geometry, TriangleTest test) {
  return avx512::make_two_level_accel(geometry, test);
}

}  // namespace pt::bvh
