// Random packs of up to eight triangles and a ray aimed at one of them, shared by the kernel tests
// (test_unit_bvh_kernels.cpp) and the pair tests (test_unit_bvh_pairs.cpp, which includes it under
// its AVX2 target). Each test file gets its own copy (an unnamed namespace).
#pragma once
#include <bit>
#include <cstdint>

#include "core/accel/bvh_build.h"
#include "core/geometry/ray.h"
#include "core/math/rng.h"

namespace {

using pt::Pcg32;
using pt::Ray;
using pt::Vec3f;
namespace bvh = pt::bvh;

bool same_bits(float a, float b) { return std::bit_cast<uint32_t>(a) == std::bit_cast<uint32_t>(b); }

// Packs in PackLayout::kVertices with `lanes` triangles (the rest empty), near each other, some tiny
// and some degenerate, and a ray aimed near one of them (or, every fifth, exactly at a corner).
struct PackCase {
  alignas(32) bvh::TriPack packs[2]{};
  Vec3f corners[8][3];
  int lanes = 0;
  Ray ray;
};

PackCase make_case(Pcg32& rng, int it, int max_lanes) {
  auto uniform = [&] { return Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * 2.0f - Vec3f(1.0f); };
  PackCase c;
  c.lanes = 1 + static_cast<int>(rng.next_u32() % static_cast<uint32_t>(max_lanes));
  for (int k = 0; k < 8; ++k) {
    bvh::TriPack& p = c.packs[k / 4];
    p.prim[k % 4] = k < c.lanes ? static_cast<uint32_t>(k) : bvh::kNoPrim;
    if (k >= c.lanes) continue;
    Vec3f centre = uniform() * 0.5f;
    for (int corner = 0; corner < 3; ++corner) c.corners[k][corner] = centre + uniform() * (it % 3 == 0 ? 0.05f : 0.6f);
    if (it % 11 == 0) c.corners[k][2] = c.corners[k][0];  // a degenerate one now and then
    for (int corner = 0; corner < 3; ++corner)
      for (int a = 0; a < 3; ++a) p.v[3 * corner + a][k % 4] = c.corners[k][corner][a];
  }
  c.ray.o = uniform() * 3.0f;
  int aim = static_cast<int>(rng.next_u32() % static_cast<uint32_t>(c.lanes));
  Vec3f target = it % 5 == 0 ? c.corners[aim][it % 3]
                             : (c.corners[aim][0] + c.corners[aim][1] + c.corners[aim][2]) / 3.0f + uniform() * 0.05f;
  c.ray.d = normalize(target - c.ray.o);
  if (it % 2) c.ray.tmax = 2.5f;
  return c;
}

}  // namespace
