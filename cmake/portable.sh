#!/usr/bin/env bash
# The portable build (README, .ci/run): -DPT_NATIVE=OFF (the default since issue 26, stated here so
# that it holds whatever a build/ was configured with) in build-portable/, baseline x86-64 code
# everywhere except the BVH's kernels, which are compiled for SSE4.2, AVX2 and AVX-512 and chosen at
# start-up (core/accel/bvh_isa.h). A native build compiles every copy for the build machine; this
# one checks that they compile under their #pragma targets alone, and runs the BVH unit tests (every
# copy this CPU runs, hit for hit) and the agreement with Embree (closed meshes, far from the
# origin, degenerate triangles, the studio ground; issues 15 and 26).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
werror=OFF
[ "${CI:-}" = true ] && werror=ON
cmake -S . -B build-portable -DCMAKE_BUILD_TYPE=Release -DPT_NATIVE=OFF -DPT_WERROR="$werror"
cmake --build build-portable -j "$(nproc)" --target test_unit_bvh test_unit_bvh_kernels test_unit_bvh_pairs test_agreement_bvh
build-portable/tests/test_unit_bvh
build-portable/tests/test_unit_bvh_kernels
build-portable/tests/test_unit_bvh_pairs
build-portable/tests/test_agreement_bvh
