// The BVH's SIMD triangle kernels against the scalar tests they mirror: the watertight test on four
// lanes (one pack) gives the bits of intersect_triangle_watertight (eight lanes against four:
// test_unit_bvh_pairs.cpp); and every instruction set's copy of the traversal (bvh_isa.h) that
// this CPU runs finds the same hits.
#include <doctest/doctest.h>

#include <bit>
#include <cmath>
#include <string>

#include "bvh_test_scenes.h"
#include "core/accel/bvh_isa.h"
#include "core/accel/bvh_kernels.h"
#include "core/geometry/instance.h"
#include "core/geometry/intersect.h"
#include "core/math/rng.h"

using namespace pt;

#include "tri_pack_case.h"

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


// The SIMD test's early exit checks t's range without a division (range_lower, range_upper in
// bvh_kernels.h), by bounds that must let through every lane the exact check accepts. So tmin and
// tmax are put at each hit's t and one float either side of it, where the scalar test's answer
// turns; at 0, and at tiny and huge values, which the bounds treat apart.
TEST_CASE("pack test: the range check without a division keeps every lane the scalar test accepts at tmin and tmax") {
  Pcg32 rng(21, 5);
  size_t cases = 0, accepted = 0, rejected = 0, differ = 0;
  auto compare = [&](const PackCase& c, const Ray& ray) {
    WatertightRay wt(ray.d);
    bvh::PackHits h;
    uint32_t mask = bvh::intersect_lanes_wt<bvh::Lanes4>(c.packs[0], bvh::WatertightLanes<bvh::Lanes4>(ray, wt), ray.tmax, h);
    for (int lane = 0; lane < c.lanes && lane < 4; ++lane) {
      float t = 0, u = 0, v = 0;
      bool hit = intersect_triangle_watertight(ray, wt, c.corners[lane][0], c.corners[lane][1], c.corners[lane][2], t, u, v);
      if (hit != (((mask >> lane) & 1) != 0) || (hit && !same_bits(t, h.t[lane]))) ++differ;
      (hit ? accepted : rejected) += 1;
    }
    ++cases;
  };
  for (int it = 0; it < 20000; ++it) {
    PackCase c = make_case(rng, it, 4);
    c.ray.tmin = 0.0f;
    c.ray.tmax = kInf;
    WatertightRay wt(c.ray.d);
    for (int lane = 0; lane < c.lanes && lane < 4; ++lane) {
      float t = 0, u = 0, v = 0;
      if (!intersect_triangle_watertight(c.ray, wt, c.corners[lane][0], c.corners[lane][1], c.corners[lane][2], t, u, v))
        continue;
      for (float at : {std::nextafter(t, 0.0f), t, std::nextafter(t, kInf)}) {
        Ray r = c.ray;
        r.tmax = at;
        compare(c, r);
        r = c.ray;
        r.tmin = at;
        compare(c, r);
      }
    }
    for (float tmin : {-1.0f, -0x1p-130f, 0x1p-130f, 0x1p-101f, 0x1p-99f}) {
      Ray r = c.ray;
      r.tmin = tmin;
      compare(c, r);
    }
    for (float tmax : {0x1p-130f, 1e-30f, 1e30f, 3e38f}) {
      Ray r = c.ray;
      r.tmax = tmax;
      compare(c, r);
    }
  }
  INFO(cases << " cases: " << accepted << " lanes accepted, " << rejected << " rejected");
  CHECK(accepted > 20000);
  CHECK(rejected > 20000);
  CHECK(differ == 0);
}

TEST_CASE("bvh: every instruction set's kernels that this CPU runs give the same hits, bit for bit") {
  // One tree (the options fixed, so the same for every kernel), the scan-like mesh in its room.
  Geometry scene = test::scan_geometry(4, 200);
  auto rays = test::random_rays(scene, 1 << 17, 41);
  for (TriangleTest test : {TriangleTest::kWatertight, TriangleTest::kMollerTrumbore})
  for (size_t float_tree : {size_t(0), SIZE_MAX}) {  // quantised nodes, then float ones
    bvh::BuildOptions options;
    options.max_leaf = 16;
    options.pack_pair_cost = 1.2f;
    options.float_tree_prims = float_tree;
    auto reference = bvh::make_bvh_accel_isa(scene, test, options, bvh::Isa::kSse42);
    int kernels = 0;
    for (bvh::Isa isa : bvh::kIsas) {
      if (!bvh::isa_supported(isa)) continue;
      ++kernels;
      auto accel = bvh::make_bvh_accel_isa(scene, test, options, isa);
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
      INFO(bvh::isa_name(isa) << (test == TriangleTest::kWatertight ? ", watertight: " : ", mt: ") << hits << " hits, "
                              << differ << " differ");
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

// A direction component of -0 is a zero like +0: the same line, so the same hits. The slab test
// picks each axis's near plane by the component's sign bit, the sign its reciprocal (-1e30) has;
// picked by `d < 0`, false for -0, every such ray missed every box (a negated direction holds -0
// where it held +0).
TEST_CASE("bvh: a zero direction component of either sign gives the same hits, in every copy") {
  Geometry scene = test::scan_geometry(4, 120);
  BBox b = scene.bounds();
  Pcg32 rng(3, 8);
  std::vector<Ray> rays;
  for (int i = 0; i < 3000; ++i) {
    int axis = i % 3;
    Ray ray;
    ray.o = b.lo + Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * b.extent();
    ray.d = Vec3f(0.0f);
    ray.d[axis] = (i / 3) % 2 ? 1.0f : -1.0f;  // along an axis, the other two components +0
    rays.push_back(ray);
  }
  for (size_t float_tree : {size_t(0), SIZE_MAX}) {
    bvh::BuildOptions options;
    options.float_tree_prims = float_tree;
    for (bvh::Isa isa : bvh::kIsas) {
      if (!bvh::isa_supported(isa)) continue;
      auto accel = bvh::make_bvh_accel_isa(scene, TriangleTest::kWatertight, options, isa);
      size_t hits = 0, differ = 0;
      for (const Ray& ray : rays) {
        auto a = accel->intersect(ray);
        bool occluded = accel->occluded(ray);
        hits += bool(a);
        for (int signs = 1; signs < 4; ++signs) {  // -0 in one or both of the zero components
          Ray r = ray;
          int axis = r.d.x != 0.0f ? 0 : (r.d.y != 0.0f ? 1 : 2);
          if (signs & 1) r.d[(axis + 1) % 3] = -0.0f;
          if (signs & 2) r.d[(axis + 2) % 3] = -0.0f;
          auto h = accel->intersect(r);
          if (bool(h) != bool(a) || accel->occluded(r) != occluded || (a && (h->prim != a->prim || !same_bits(h->t, a->t))))
            ++differ;
        }
      }
      std::string what = std::string(bvh::isa_name(isa)) + (float_tree ? ", float nodes" : ", quantised nodes");
      INFO(what << ": " << hits << " hits of " << rays.size());
      CHECK(hits > rays.size() / 2);  // the room is closed: rays from inside hit its walls or the mesh
      CHECK(differ == 0);
    }
  }
}
