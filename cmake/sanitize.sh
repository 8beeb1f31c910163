#!/usr/bin/env bash
# The ASan+UBSan pass (README, .ci/run): builds pt and the fuzz test with -DPT_SANITIZE=ON in
# build-asan/ and runs the seeded mutation fuzzer over the example scenes (tests/test_fuzz_scenes.cpp)
# through the sanitized pt (150 mutants, about 1.3 s each: what CI's 30 minutes leave; PT_FUZZ_COUNT
# sets another count). A sanitizer report, a crash or a hang fails it. Reproduce one mutant:
#   PT_FUZZ_SEED=11 PT_FUZZ_FIRST=I PT_FUZZ_COUNT=1 build-asan/tests/test_fuzz_scenes
# Warnings are not errors here: GCC 12 reports false maybe-uninitialized warnings inside
# libstdc++'s <regex> under the sanitizers (the Release build in CI keeps -Werror).
set -euo pipefail
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
cd "$root"
# -O1: the sanitizers' usual level; it compiles in half the time of -O2 and keeps stacks readable.
# PT_BVH_EXPERIMENT: the BVH's experimental kernels (docs/bvh.md), compiled here so that they keep
# compiling (they are the AVX-512 copy unless a change is under way).
cmake -S . -B build-asan -DCMAKE_BUILD_TYPE= -DCMAKE_CXX_FLAGS=-O1 -DPT_SANITIZE=ON -DPT_WERROR=OFF -DPT_BVH_EXPERIMENT=ON \
  -DPT_FUZZ_COUNT="${PT_FUZZ_COUNT:-150}"
cmake --build build-asan -j "$(nproc)" --target pt pt_image_oiio test_fuzz_scenes
build-asan/tests/test_fuzz_scenes
