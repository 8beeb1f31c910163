// An experimental copy of the BVH's traversal and kernels, built only with -DPT_BVH_EXPERIMENT=ON:
// the AVX-512 copy compiled with PT_BVH_EXP = 1, so that code under `#if PT_BVH_EXP` in
// bvh_traversal.h or bvh_kernels.h runs here and nowhere else. `pt bench rays --bvh-variant
// kernels=experiment` times it against the unchanged kernels in one process, on the same tree and
// rays (docs/bvh.md, "Measuring a build setting or a change to the traversal"). Needs a CPU with
// AVX-512 (bvh_isa.h).
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
#define PT_BVH_ISA experiment
#define PT_BVH_EXP 1
#define PT_BVH_AVX2 1
#define PT_BVH_AVX512 1
#include "core/accel/bvh_traversal.h"
#include "core/accel/bvh_two_level.h"  // trace_instances, which the traversal calls

namespace pt::bvh {

std::unique_ptr<Accel> make_accel_experiment(const Geometry& scene, TriangleTest test, const BuildOptions& options) {
  return experiment::make_accel(scene, test, options);
}

}  // namespace pt::bvh
