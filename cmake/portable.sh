#!/usr/bin/env bash
# The portable build (README, .ci/run): -DPT_NATIVE=OFF, baseline x86-64 code everywhere except the
# BVH's kernels, which are compiled for SSE4.2, AVX2 and AVX-512 and chosen at start-up
# (core/accel/bvh_isa.h). It checks that every copy compiles under its #pragma target alone, and
# runs the BVH unit tests (every copy this CPU runs, hit for hit) and the agreement with Embree
# (closed meshes, far from the origin, degenerate triangles, the studio ground; issues 15 and 26)
# once for each kernel this CPU can run (PT_BVH_ISA), so the lower ones are traced end to end too.
# build/ is used where it is portable already (the default); else the build goes to build-portable/.
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
werror=OFF
[ "${CI:-}" = true ] && werror=ON
dir=build-portable
if [ -f build/CMakeCache.txt ] && grep -q '^PT_NATIVE:BOOL=OFF$' build/CMakeCache.txt; then
  dir=build
else
  cmake -S . -B "$dir" -DCMAKE_BUILD_TYPE=Release -DPT_NATIVE=OFF -DPT_WERROR="$werror"
fi
cmake --build "$dir" -j "$(nproc)" --target test_unit_bvh test_unit_bvh_kernels test_unit_bvh_pairs test_agreement_bvh
"$dir"/tests/test_unit_bvh_kernels
"$dir"/tests/test_unit_bvh_pairs
# The names PT_BVH_ISA takes (isa_name in core/accel/bvh_accel.cpp): pt warns on any other and runs
# the best kernels, which would make a pass test nothing of its own.
for isa in sse4.2 avx2 avx512; do
  case "$isa" in
    avx2) grep -qw avx2 /proc/cpuinfo || continue ;;
    avx512) grep -qw avx512f /proc/cpuinfo || continue ;;
  esac
  echo "portable.sh: the BVH's $isa kernels"
  PT_BVH_ISA="$isa" "$dir"/tests/test_unit_bvh
  PT_BVH_ISA="$isa" "$dir"/tests/test_agreement_bvh
done
