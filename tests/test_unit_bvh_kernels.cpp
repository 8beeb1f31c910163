// The BVH's SIMD triangle kernels against the scalar tests they mirror: the watertight test on four
// lanes (one pack) gives the bits of intersect_triangle_watertight (eight lanes against four:
// test_unit_bvh_pairs.cpp); and every instruction set's copy of the traversal (bvh_isa.h) that
// this CPU runs finds the same hits.
#include <doctest/doctest.h>

#include <bit>

#include "bvh_test_scenes.h"
#include "core/accel/bvh_isa.h"
#include "core/accel/bvh_kernels.h"
#include "core/geometry/instance.h"
#include "core/geometry/intersect.h"
#include "core/math/rng.h"

using namespace pt;

namespace {

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

TEST_CASE("pack test: the SIMD watertight test gives the scalar one's bits, lane by lane") {
  Pcg32 rng(9, 9);
  size_t hits = 0, differ = 0;
  for (int it = 0; it < 20000; ++it) {
    PackCase c = make_case(rng, it, 4);
    WatertightRay wt(c.ray.d);
    bvh::PackHits h;
    uint32_t mask =
        bvh::intersect_lanes_wt<bvh::Lanes4>(c.packs[0], bvh::WatertightLanes<bvh::Lanes4>(c.ray, wt), c.ray.tmax, h);
    for (int lane = 0; lane < 4; ++lane) {
      float t = 0, u = 0, v = 0;
      bool hit = lane < c.lanes && intersect_triangle_watertight(c.ray, wt, c.corners[lane][0], c.corners[lane][1],
                                                                 c.corners[lane][2], t, u, v);
      bool lane_hit = (mask >> lane) & 1;
      if (hit != lane_hit ||
          (hit && !(same_bits(t, h.t[lane]) && same_bits(u, h.u[lane]) && same_bits(v, h.v[lane])))) {
        ++differ;
      }
      hits += hit;
    }
  }
  INFO(hits << " hits");
  CHECK(hits > 5000);
  CHECK(differ == 0);
}


TEST_CASE("bvh: every instruction set's kernels that this CPU runs give the same hits, bit for bit") {
  // One tree (the options fixed, so the same for every kernel), the scan-like mesh in its room.
  Geometry scene = test::scan_geometry(4, 200);
  auto rays = test::random_rays(scene, 1 << 17, 41);
  for (size_t float_tree : {size_t(0), SIZE_MAX}) {  // quantised nodes, then float ones
    bvh::BuildOptions options;
    options.max_leaf = 16;
    options.pack_pair_cost = 1.2f;
    options.float_tree_prims = float_tree;
    auto reference = bvh::make_bvh_accel_isa(scene, TriangleTest::kWatertight, options, bvh::Isa::kSse42);
    int kernels = 0;
    for (bvh::Isa isa : bvh::kIsas) {
      if (!bvh::isa_supported(isa)) continue;
      ++kernels;
      auto accel = bvh::make_bvh_accel_isa(scene, TriangleTest::kWatertight, options, isa);
      size_t differ = 0, hits = 0;
      for (const Ray& ray : rays) {
        auto a = reference->intersect(ray), b = accel->intersect(ray);
        if (bool(a) != bool(b) || reference->occluded(ray) != accel->occluded(ray)) {
          ++differ;
        } else if (a) {
          ++hits;
          if (a->prim != b->prim || !same_bits(a->t, b->t) || !same_bits(a->u, b->u) || !same_bits(a->v, b->v))
            ++differ;
        }
      }
      INFO(bvh::isa_name(isa) << ": " << hits << " hits");
      CHECK(hits > rays.size() / 10);
      CHECK(differ == 0);
    }
    CHECK(kernels >= 1);
  }
  CHECK(bvh::isa_supported(bvh::active_isa()));
}

TEST_CASE("bvh: every instruction set's two-level BVH that this CPU runs gives the same hits, bit for bit") {
  // A displaced icosphere placed 300 times, turned and scaled, over a world-space floor.
  Mesh blob;
  add_displaced_icosphere(blob, 3, Vec3f(0.2f, 0, 0), 1.0f, 0.15f, 0);
  Pcg32 rng(43, 7);
  std::vector<Instance> instances;
  for (int k = 0; k < 300; ++k) {
    Vec3f at = Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * 40.0f - Vec3f(20.0f);
    Transform t = Transform::translate(at) * Transform::rotate_axis(1, 360 * rng.next_float()) *
                  Transform::scale(Vec3f(0.5f + rng.next_float()));
    instances.push_back({0u, t, t.inverse()});
  }
  Geometry floor = test::triangle_soup(200, 44);
  Geometry scene(Mesh(floor.mesh()), {}, {blob}, std::move(instances));
  auto rays = test::random_rays(scene, 1 << 16, 45);
  auto reference = bvh::make_two_level_accel_isa(scene, TriangleTest::kWatertight, bvh::Isa::kSse42);
  for (bvh::Isa isa : bvh::kIsas) {
    if (!bvh::isa_supported(isa)) continue;
    auto accel = bvh::make_two_level_accel_isa(scene, TriangleTest::kWatertight, isa);
    size_t differ = 0, hits = 0;
    for (const Ray& ray : rays) {
      auto a = reference->intersect(ray), b = accel->intersect(ray);
      if (bool(a) != bool(b) || reference->occluded(ray) != accel->occluded(ray)) {
        ++differ;
      } else if (a) {
        ++hits;
        if (a->prim != b->prim || a->inst != b->inst || !same_bits(a->t, b->t)) ++differ;
      }
    }
    INFO(bvh::isa_name(isa) << ": " << hits << " hits");
    CHECK(hits > rays.size() / 20);
    CHECK(differ == 0);
  }
}
