#!/usr/bin/env bash
# The portable build (README, .ci/run): -DPT_NATIVE=OFF in build-portable/, where the BVH has no
# AVX2, so its nodes take the scalar box test, its leaves the four-lane packs and its tree no pack
# pairs (core/accel/bvh_*). The native build tests those kernels against the AVX2 ones, but only
# this build runs whole traversals through them: the BVH unit tests and the agreement with Embree
# (closed meshes, far from the origin, degenerate triangles; issue 15).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
werror=OFF
[ "${CI:-}" = true ] && werror=ON
cmake -S . -B build-portable -DCMAKE_BUILD_TYPE=Release -DPT_NATIVE=OFF -DPT_WERROR="$werror"
cmake --build build-portable -j "$(nproc)" --target test_unit_bvh test_agreement_bvh
build-portable/tests/test_unit_bvh
build-portable/tests/test_agreement_bvh
