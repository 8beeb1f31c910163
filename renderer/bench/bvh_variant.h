// `pt bench rays --bvh-variant SPEC`: BVH build settings other than the defaults, or another copy
// of the traversal kernels, written "key=value,key=value", so that two trees (or two kernels on one
// tree) can be timed in one process on the same rays (between two processes the same code scatters
// by up to 0.2 on a row on the reference machine, more than most changes move it).
#pragma once
#include <memory>
#include <string>
#include <string_view>

#include "core/accel/accel.h"
#include "core/accel/bvh_build.h"
#include "core/accel/bvh_isa.h"

namespace pt {

// Which copy of the traversal kernels a variant runs: the one chosen at start-up, another
// instruction set's (bvh_isa.h), or the experimental copy (bvh_accel_experiment.cpp).
enum class VariantKernels { kActive, kIsa, kExperiment };

struct BvhVariant {
  bvh::BuildOptions options;
  VariantKernels kernels = VariantKernels::kActive;
  bvh::Isa isa = bvh::Isa::kSse42;  // with VariantKernels::kIsa
};

// The defaults with SPEC's settings applied; throws Error naming the bad key or value. The keys:
// those of bvh_variant_build_keys() (fields of bvh::BuildOptions), and kernels (sse4.2, avx2,
// avx512 or experiment; the CPU must run them, and experiment needs a build with it).
BvhVariant parse_bvh_variant(std::string_view spec);

// The build settings' keys, comma-separated, for the option's help.
std::string bvh_variant_build_keys();

// The variant's BVH over `geometry`.
std::unique_ptr<Accel> make_variant_accel(const Geometry& geometry, TriangleTest test, const BvhVariant& variant);

// The settings' names and values, for the table's legend.
std::string describe_bvh_variant(std::string_view spec);

}  // namespace pt
