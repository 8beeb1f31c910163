// The eight-lane kernels (a pair of packs per test, TriPair) against the four-lane ones (one pack),
// bit for bit, for Möller-Trumbore and the watertight test. They are AVX2 code, and builds are
// portable by default (no -march=native): so they are compiled here under the AVX2 target, as
// bvh_accel_avx2.cpp compiles them, and run only on a CPU that has AVX2.
#include <doctest/doctest.h>
#include <immintrin.h>

#include <bit>
#include <cstdint>

#include "core/accel/accel.h"
#include "core/accel/bvh_build.h"
#include "core/accel/bvh_isa.h"
#include "core/geometry/intersect.h"
#include "core/math/rng.h"

using namespace pt;

namespace {

struct PairCounts {
  size_t hits = 0, high_hits = 0, differ = 0;
};
PairCounts mt_pairs();  // under the AVX2 target, below
PairCounts wt_pairs();
size_t setup_differences(size_t& directions);

void check(const PairCounts& c) {
  INFO(c.hits << " hits, " << c.high_hits << " in the second pack");
  CHECK(c.hits > 5000);
  CHECK(c.high_hits > 1000);
  CHECK(c.differ == 0);
}

}  // namespace

TEST_CASE("pack test: two packs in one eight-lane Möller-Trumbore test give the bits of one pack at a time") {
  if (!bvh::isa_supported(bvh::Isa::kAvx2)) {
    MESSAGE("this CPU has no AVX2: the eight-lane kernels are not run");
    return;
  }
  check(mt_pairs());
}

TEST_CASE("pack test: two packs in one eight-lane watertight test give the bits of one pack at a time") {
  if (!bvh::isa_supported(bvh::Isa::kAvx2)) {
    MESSAGE("this CPU has no AVX2: the eight-lane kernels are not run");
    return;
  }
  check(wt_pairs());
}

TEST_CASE("pack test: the eight-lane set-up from the ray gives WatertightRay's axes, shear and origin") {
  if (!bvh::isa_supported(bvh::Isa::kAvx2)) {
    MESSAGE("this CPU has no AVX2: the eight-lane kernels are not run");
    return;
  }
  size_t directions = 0;
  size_t differ = setup_differences(directions);
  INFO(directions << " directions");
  CHECK(directions > 100000);
  CHECK(differ == 0);
}

#pragma GCC target("avx2,fma,bmi,bmi2,lzcnt,popcnt")
#define PT_BVH_ISA pairtest
#define PT_BVH_AVX2 1
#include "core/accel/bvh_kernels.h"
#include "tri_pack_case.h"

namespace {

PairCounts mt_pairs() {
  size_t differ = 0, hits = 0, high_hits = 0;
  Pcg32 rng(8, 8);
  auto uniform = [&] { return Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * 2.0f - Vec3f(1.0f); };
  for (int it = 0; it < 20000; ++it) {
    alignas(32) bvh::TriPack packs[2]{};  // paired below, as in a leaf
    Vec3f centres[8];
    int lanes = 5 + static_cast<int>(rng.next_u32() % 4);  // the second pack partly filled
    for (int k = 0; k < 8; ++k) {
      bvh::TriPack& p = packs[k / 4];
      p.prim[k % 4] = k < lanes ? static_cast<uint32_t>(k) : bvh::kNoPrim;
      if (k >= lanes) continue;
      Vec3f c = uniform() * 0.5f;
      centres[k] = c;
      Vec3f corners[3];
      for (int corner = 0; corner < 3; ++corner) corners[corner] = c + uniform() * (it % 3 == 0 ? 0.05f : 0.6f);
      if (it % 11 == 0) corners[2] = corners[0];  // a degenerate one now and then
      Vec3f rows[3] = {corners[0], corners[1] - corners[0], corners[2] - corners[0]};
      for (int row = 0; row < 3; ++row)
        for (int a = 0; a < 3; ++a) p.v[3 * row + a][k % 4] = rows[row][a];
    }
    Ray ray;
    ray.o = uniform() * 3.0f;
    ray.d = normalize(centres[rng.next_u32() % static_cast<uint32_t>(lanes)] + uniform() * 0.05f - ray.o);
    float tmax = it % 2 ? kInf : 2.5f;
    bvh::LaneHits<8> pair;
    const bvh::TriPair both = bvh::pair_of(packs[0], packs[1]);
    uint32_t m8 = bvh::intersect_pack_pair_mt(both, ray, tmax, pair);
    for (int k = 0; k < 2; ++k) {
      bvh::PackHits one;
      uint32_t m4 = bvh::intersect_pack_mt(packs[k], ray, tmax, one);
      if (m4 != ((m8 >> (4 * k)) & 15u)) ++differ;
      for (uint32_t m = m4 & (m8 >> (4 * k)); m; m &= m - 1) {
        int lane = std::countr_zero(m);
        ++hits;
        high_hits += k;
        if (std::bit_cast<uint32_t>(one.t[lane]) != std::bit_cast<uint32_t>(pair.t[4 * k + lane]) ||
            std::bit_cast<uint32_t>(one.u[lane]) != std::bit_cast<uint32_t>(pair.u[4 * k + lane]) ||
            std::bit_cast<uint32_t>(one.v[lane]) != std::bit_cast<uint32_t>(pair.v[4 * k + lane])) {
          ++differ;
        }
      }
    }
  }
  return {hits, high_hits, differ};
}

PairCounts wt_pairs() {
  size_t hits = 0, high_hits = 0, differ = 0;
  Pcg32 rng(10, 10);
  for (int it = 0; it < 20000; ++it) {
    PackCase c = make_case(rng, it, 8);
    if (c.lanes < 5) c = make_case(rng, it, 8);  // mostly a second pack in use
    WatertightRay wt(c.ray.d);
    bvh::LaneHits<8> pair;
    const bvh::TriPair both = bvh::pair_of(c.packs[0], c.packs[1]);
    uint32_t m8 = bvh::intersect_pack_pair_wt(both, bvh::WatertightLanes<bvh::Lanes8>(c.ray), c.ray.tmax, pair);
    for (int k = 0; k < 2; ++k) {
      bvh::PackHits one;
      uint32_t m4 = bvh::intersect_lanes_wt<bvh::Lanes4>(c.packs[k], bvh::WatertightLanes<bvh::Lanes4>(c.ray, wt),
                                                         c.ray.tmax, one);
      if (m4 != ((m8 >> (4 * k)) & 15u)) ++differ;
      for (uint32_t m = m4 & (m8 >> (4 * k)); m; m &= m - 1) {
        int lane = std::countr_zero(m);
        ++hits;
        high_hits += k;
        if (!(same_bits(one.t[lane], pair.t[4 * k + lane]) && same_bits(one.u[lane], pair.u[4 * k + lane]) &&
              same_bits(one.v[lane], pair.v[4 * k + lane]))) {
          ++differ;
        }
      }
    }
  }
  return {hits, high_hits, differ};
}

// Every combination of ties, zeros of both signs and signs among the three components (each from a
// small set of values), then random directions; the values traversal reads, bit for bit, in every
// lane.
size_t setup_differences(size_t& directions) {
  size_t differ = 0;
  auto lanes_equal = [](__m256 v, float x) {
    alignas(32) float f[8];
    _mm256_store_ps(f, v);
    for (float g : f)
      if (!same_bits(g, x)) return false;
    return true;
  };
  auto check = [&](const Vec3f& o, const Vec3f& d) {
    Ray r;
    r.o = o;
    r.d = d;
    r.tmin = 0.25f;
    WatertightRay w(d);
    bvh::WatertightLanes<bvh::Lanes8> l(r);
    const float oa[3] = {o.x, o.y, o.z};
    bool same = l.kx == w.kx && l.ky == w.ky && l.kz == w.kz && lanes_equal(l.sx, w.sx) && lanes_equal(l.sy, w.sy) &&
                lanes_equal(l.sz, w.sz) && lanes_equal(l.s2, w.s2) && lanes_equal(l.ox, oa[w.kx]) &&
                lanes_equal(l.oy, oa[w.ky]) && lanes_equal(l.oz, oa[w.kz]) && same_bits(l.tmin, r.tmin) && l.ray == &r;
    differ += !same;
    ++directions;
  };
  const float values[] = {0.0f, -0.0f, 1.0f, -1.0f, 0.5f, -0.5f, 3.0f, -3.0f, 1e-30f, -1e-30f, 1e30f};
  Vec3f o(1.5f, -2.25f, 7.0f);
  for (float x : values)
    for (float y : values)
      for (float z : values) check(o, Vec3f(x, y, z));
  Pcg32 rng(12, 12);
  auto uniform = [&] { return Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * 2.0f - Vec3f(1.0f); };
  for (int i = 0; i < 200000; ++i) check(uniform() * 100.0f, normalize(uniform()));
  return differ;
}

}  // namespace
