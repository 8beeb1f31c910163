// The BVH backend's entry points: the kernels chosen for this CPU (bvh_isa.h), the tree built with
// the defaults that suit them.
#include "core/accel/bvh_accel.h"

#include <cstdio>
#include <cstdlib>
#include <cstring>

#include "core/accel/bvh_build.h"
#include "core/accel/bvh_instances.h"
#include "core/accel/bvh_isa.h"

namespace pt {
namespace bvh {

const char* isa_name(Isa isa) {
  switch (isa) {
    case Isa::kSse42: return "sse4.2";
    case Isa::kAvx2: return "avx2";
    case Isa::kAvx512: return "avx512";
  }
  return "?";
}

bool isa_supported(Isa isa) {
  __builtin_cpu_init();  // may run before the constructor that does it (a static initialiser)
  switch (isa) {
    case Isa::kSse42: return __builtin_cpu_supports("sse4.2") && __builtin_cpu_supports("popcnt");
    case Isa::kAvx2:
      return __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
             __builtin_cpu_supports("bmi2");
    case Isa::kAvx512:
      return isa_supported(Isa::kAvx2) && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  }
  return false;
}

Isa active_isa() {
  static const Isa chosen = [] {
    Isa best = Isa::kSse42;
    for (Isa isa : kIsas)
      if (isa_supported(isa)) best = isa;
    if (const char* forced = std::getenv("PT_BVH_ISA")) {
      bool taken = false;
      for (Isa isa : kIsas) {
        if (std::strcmp(forced, isa_name(isa)) == 0 && isa_supported(isa)) {
          best = isa;
          taken = true;
        }
      }
      // Said, not ignored: a misspelt name would run the best kernels while the caller believes
      // it measures or tests another set (cmake/portable.sh's SSE4.2 pass did, with "sse42").
      if (!taken) {
        std::fprintf(stderr, "pt: warning: PT_BVH_ISA=%s: not sse4.2, avx2 or avx512, or not one this CPU runs; using %s\n",
                     forced, isa_name(best));
      }
    }
    return best;
  }();
  return chosen;
}

float default_pack_pair_cost() { return isa_pairs_packs(active_isa()) ? 1.2f : 2.0f; }
int default_max_leaf(size_t primitives) {
  if (!isa_pairs_packs(active_isa())) return 12;
  return primitives <= kSmallTreePrims ? 8 : 16;
}

std::unique_ptr<Accel> make_bvh_accel_isa(const Geometry& geometry, TriangleTest test, const BuildOptions& options, Isa isa) {
  switch (isa) {
    case Isa::kAvx512: return make_accel_avx512(geometry, test, options);
    case Isa::kAvx2: return make_accel_avx2(geometry, test, options);
    case Isa::kSse42: break;
  }
  return make_accel_sse42(geometry, test, options);
}

#if !defined(PT_BVH_EXPERIMENT_BUILT)
bool experiment_kernels_built() { return false; }
std::unique_ptr<Accel> make_accel_experiment(const Geometry&, TriangleTest, const BuildOptions&) { return nullptr; }
#else
bool experiment_kernels_built() { return true; }
#endif

std::unique_ptr<Accel> make_two_level_accel_isa(const Geometry& geometry, TriangleTest test, Isa isa) {
  switch (isa) {
    case Isa::kAvx512: return make_two_level_accel_avx512(geometry, test);
    case Isa::kAvx2: return make_two_level_accel_avx2(geometry, test);
    case Isa::kSse42: break;
  }
  return make_two_level_accel_sse42(geometry, test);
}

}  // namespace bvh

std::unique_ptr<Accel> make_instanced_bvh_accel(const Geometry& geometry, TriangleTest test) {
  return bvh::make_two_level_accel_isa(geometry, test, bvh::active_isa());
}

std::unique_ptr<Accel> make_bvh_accel(const Geometry& scene, TriangleTest test, const bvh::BuildOptions& options) {
  return bvh::make_bvh_accel_isa(scene, test, options, bvh::active_isa());
}

std::unique_ptr<Accel> make_bvh_accel(const Geometry& scene, TriangleTest test) {
  bvh::BuildOptions options;
  return make_bvh_accel(scene, test, options);
}

}  // namespace pt
