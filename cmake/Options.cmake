# Build options: warnings, warnings-as-errors (on in CI), sanitizers.
option(PT_BUILD_TESTS "Build the doctest suites" ON)
option(PT_WERROR "Treat warnings as errors" OFF)
option(PT_SANITIZE "Build with AddressSanitizer and UndefinedBehaviorSanitizer" OFF)
# Off by default: one binary for every x86-64 CPU. The BVH's kernels are compiled for SSE4.2, AVX2
# and AVX-512 anyway and chosen at start-up (core/accel/bvh_isa.h), Embree chooses its own, and
# -march=native bought nothing measurable elsewhere (docs/bvh.md, "Instruction sets").
option(PT_NATIVE "Tune for the build machine (-march=native)" OFF)
# A fourth copy of the BVH's kernels with PT_BVH_EXP = 1, for `pt bench rays --bvh-variant
# kernels=experiment` (docs/bvh.md, "Measuring a build setting or a change to the traversal").
# Not for release builds.
option(PT_BVH_EXPERIMENT "Also build the BVH's experimental kernels (core/accel/bvh_accel_experiment.cpp)" OFF)

add_library(pt_options INTERFACE)
target_compile_options(pt_options INTERFACE -Wall -Wextra)
# No fused multiply-adds the source does not write: GCC contracts a * b + c wherever it inlines, so
# that an image's last bits would depend on inlining decisions, and a change that moves code could
# not be checked bit for bit against the image before it. Kernels that want an FMA say so (std::fma).
target_compile_options(pt_options INTERFACE -ffp-contract=off)
if(PT_WERROR)
  target_compile_options(pt_options INTERFACE -Werror)
endif()
if(PT_NATIVE)
  target_compile_options(pt_options INTERFACE -march=native)
endif()
if(PT_SANITIZE)
  target_compile_options(pt_options INTERFACE -fsanitize=address,undefined -fno-omit-frame-pointer
                                              -fno-sanitize-recover=undefined)
  target_link_options(pt_options INTERFACE -fsanitize=address,undefined)
endif()
