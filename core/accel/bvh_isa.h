// Which copy of the BVH's traversal kernels runs: one binary for every x86-64 CPU. The kernels are
// compiled for SSE4.2, AVX2 (with FMA) and AVX-512 (bvh_accel_sse42.cpp, _avx2.cpp, _avx512.cpp);
// the best one the CPU supports is chosen at start-up (__builtin_cpu_supports), or the one named
// by the environment variable PT_BVH_ISA (sse4.2, avx2, avx512) if the CPU supports it.
#pragma once
#include <memory>
#include <string>

#include "core/accel/accel.h"

namespace pt::bvh {

struct BuildOptions;

enum class Isa { kSse42, kAvx2, kAvx512 };
inline constexpr Isa kIsas[] = {Isa::kSse42, Isa::kAvx2, Isa::kAvx512};

const char* isa_name(Isa isa);
bool isa_supported(Isa isa);  // by this CPU
Isa active_isa();             // the one make_bvh_accel uses
// With AVX2 or better a leaf's packs are tested two at a time (BuildOptions' defaults follow).
inline bool isa_pairs_packs(Isa isa) { return isa != Isa::kSse42; }

// The BVH with the given instruction set's kernels (which the CPU must support).
std::unique_ptr<Accel> make_bvh_accel_isa(const Geometry& geometry, TriangleTest test, const BuildOptions& options, Isa isa);

std::unique_ptr<Accel> make_accel_sse42(const Geometry& geometry, TriangleTest test, const BuildOptions& options);
std::unique_ptr<Accel> make_accel_avx2(const Geometry& geometry, TriangleTest test, const BuildOptions& options);
std::unique_ptr<Accel> make_accel_avx512(const Geometry& geometry, TriangleTest test, const BuildOptions& options);
// The experimental copy (bvh_accel_experiment.cpp; AVX-512), or null in a build without it
// (-DPT_BVH_EXPERIMENT=OFF, the default).
bool experiment_kernels_built();
std::unique_ptr<Accel> make_accel_experiment(const Geometry& geometry, TriangleTest test, const BuildOptions& options);
// A scene with instances: two levels (bvh_two_level.h).
std::unique_ptr<Accel> make_two_level_accel_isa(const Geometry& geometry, TriangleTest test, Isa isa);
std::unique_ptr<Accel> make_two_level_accel_sse42(const Geometry& geometry, TriangleTest test);
std::unique_ptr<Accel> make_two_level_accel_avx2(const Geometry& geometry, TriangleTest test);
std::unique_ptr<Accel> make_two_level_accel_avx512(const Geometry& geometry, TriangleTest test);

}  // namespace pt::bvh
