// Unit tests of the home-written BVH: the invariants of the binary and the wide tree, the
// watertight triangle test, and small scenes whose hits are known.
#include <doctest/doctest.h>

#include "bvh_test_scenes.h"
#include "core/accel/bvh_build.h"
#include "core/geometry/intersect.h"

using namespace pt;

namespace {

void check_bvh2(const bvh::Bvh2& tree, const std::vector<bvh::PrimRef>& refs) {
  REQUIRE(!tree.nodes.empty());
  std::vector<int> seen_tri, seen_sphere;
  size_t tris = 0, spheres = 0;
  for (const auto& r : refs) (r.kind == bvh::PrimKind::kTriangle ? tris : spheres)++;
  seen_tri.assign(tris, 0);
  seen_sphere.assign(spheres, 0);
  size_t leaves = 0, violations = 0;
  for (size_t i = 0; i < tree.nodes.size(); ++i) {
    const bvh::Node2& n = tree.nodes[i];
    if (n.leaf()) {
      ++leaves;
      bvh::PrimKind kind = tree.prims[n.offset].kind;
      for (uint32_t k = 0; k < n.count; ++k) {
        const bvh::PrimRef& p = tree.prims[n.offset + k];
        BBox b;
        b.lo = p.lo;
        b.hi = p.hi;
        if (!n.box.contains(b) || p.kind != kind) ++violations;
        (p.kind == bvh::PrimKind::kTriangle ? seen_tri : seen_sphere)[p.index]++;
      }
    } else {
      // Depth-first: the left child follows its parent, the right one comes after the left subtree.
      REQUIRE(n.offset > i + 1);
      REQUIRE(n.offset < tree.nodes.size());
      if (!n.box.contains(tree.nodes[i + 1].box) || !n.box.contains(tree.nodes[n.offset].box)) ++violations;
    }
  }
  CHECK(violations == 0);
  CHECK(leaves == (tree.nodes.size() + 1) / 2);  // a full binary tree
  for (int s : seen_tri) REQUIRE(s == 1);
  for (int s : seen_sphere) REQUIRE(s == 1);
}

// Walks the wide tree from the root: every child box contains what it refers to, every block of the
// array belongs to exactly one node or pack, every primitive is in exactly one leaf.
void check_wide(const bvh::WideBvh& w, const Geometry& scene) {
  REQUIRE(!w.blocks.empty());
  std::vector<int> seen_tri(scene.mesh().triangle_count(), 0), seen_sphere(scene.spheres().size(), 0);
  std::vector<int> owner(w.blocks.size(), 0);
  size_t violations = 0, nodes = 0, packs = 0;
  auto claim = [&](uint32_t first, uint32_t count) {
    REQUIRE(first + count <= w.blocks.size());
    for (uint32_t b = first; b < first + count; ++b) owner[b]++;
  };
  std::vector<uint32_t> todo = {0};
  while (!todo.empty()) {
    uint32_t at = todo.back();
    todo.pop_back();
    claim(at, bvh::kNodeBlocks);
    ++nodes;
    const bvh::WideNode& node = w.node(at);
    for (int c = 0; c < bvh::kWidth; ++c) {
      uint32_t ref = node.child[c];
      if (ref == bvh::kEmptyChild) continue;
      BBox box = node.child_box(c);
      if (!bvh::is_leaf(ref)) {
        REQUIRE(ref > at);  // depth-first: children after their parent
        const bvh::WideNode& child = w.node(ref);
        for (int g = 0; g < bvh::kWidth; ++g) {
          if (child.child[g] != bvh::kEmptyChild && !box.contains(child.child_box(g))) ++violations;
        }
        todo.push_back(ref);
        continue;
      }
      uint32_t first = bvh::leaf_first(ref), count = bvh::leaf_count(ref);
      REQUIRE(count > 0);
      if (ref & bvh::kSphereBit) {
        for (uint32_t k = 0; k < count; ++k) {
          uint32_t s = w.spheres[first + k];
          seen_sphere[s]++;
          if (!box.contains(scene.spheres()[s].bounds())) ++violations;
        }
        continue;
      }
      claim(first, count * bvh::kPackBlocks);
      packs += count;
      for (uint32_t k = 0; k < count; ++k) {
        const bvh::TriPack& p = w.pack(ref, k);
        for (int lane = 0; lane < 4; ++lane) {
          if (p.prim[lane] == bvh::kNoPrim) continue;
          uint32_t t = p.prim[lane];
          seen_tri[t]++;
          for (int corner = 0; corner < 3; ++corner) {
            Vec3f v = scene.mesh().vertex(t, corner);
            Vec3f stored{p.v[3 * corner][lane], p.v[3 * corner + 1][lane], p.v[3 * corner + 2][lane]};
            if (!(v == stored)) ++violations;
            BBox pb;
            pb.expand(v);
            if (!box.contains(pb)) ++violations;
          }
        }
      }
    }
  }
  CHECK(violations == 0);
  CHECK(nodes == w.nodes);
  CHECK(packs == w.packs);
  for (int o : owner) REQUIRE(o == 1);
  for (int s : seen_tri) REQUIRE(s == 1);
  for (int s : seen_sphere) REQUIRE(s == 1);
}

}  // namespace

TEST_CASE("bvh invariants: boxes contain children, each primitive in exactly one leaf") {
  for (size_t n : {size_t(1), size_t(2), size_t(7), size_t(1000), size_t(150000)}) {
    CAPTURE(n);
    Geometry scene = test::triangle_soup(n, 3 + n, n >= 1000 ? 50 : 1);
    auto refs = bvh::make_prim_refs(scene);
    bvh::Bvh2 tree = bvh::build_bvh2(refs);
    check_bvh2(tree, refs);
    check_wide(bvh::collapse_to_wide(tree, scene), scene);
  }
  Geometry dense = test::icosphere_geometry(6, 0.15f);
  auto refs = bvh::make_prim_refs(dense);
  bvh::Bvh2 tree = bvh::build_bvh2(refs);
  check_bvh2(tree, refs);
  check_wide(bvh::collapse_to_wide(tree, dense), dense);
}

TEST_CASE("bvh invariants: identical primitives (no centroid spread) still build a bounded tree") {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  for (int i = 0; i < 5000; ++i) {
    mesh.indices.insert(mesh.indices.end(), {0, 1, 2});
    mesh.material.push_back(0);
  }
  Geometry scene(std::move(mesh), {});
  auto refs = bvh::make_prim_refs(scene);
  bvh::Bvh2 tree = bvh::build_bvh2(refs);
  check_bvh2(tree, refs);
  bvh::WideBvh w = bvh::collapse_to_wide(tree, scene);
  check_wide(w, scene);
  CHECK(w.depth <= 20);
  AccelOptions o;
  o.backend = Backend::kBvh;
  auto accel = make_accel(scene, o);
  Ray r;
  r.o = {0.25f, 0.25f, 1.0f};
  r.d = {0, 0, -1};
  auto hit = accel->intersect(r);
  REQUIRE(hit);
  CHECK(hit->t == doctest::Approx(1.0f));
}

TEST_CASE("watertight test matches Möller-Trumbore away from edges") {
  Pcg32 rng(1, 1);
  auto uniform = [&] { return Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * 2.0f - Vec3f(1.0f); };
  int agree = 0, hits = 0, total = 20000;
  for (int i = 0; i < total; ++i) {
    Vec3f p0 = uniform(), p1 = uniform(), p2 = uniform();
    Ray r;
    r.o = uniform() * 3.0f;
    Vec3f target = p0 * 0.2f + p1 * 0.3f + p2 * 0.5f + uniform() * 0.3f;
    r.d = normalize(target - r.o);
    float t1 = 0, u1 = 0, v1 = 0, t2 = 0, u2 = 0, v2 = 0;
    bool a = intersect_triangle_mt(r, p0, p1, p2, t1, u1, v1);
    bool b = intersect_triangle_watertight(r, p0, p1, p2, t2, u2, v2);
    if (a != b) continue;  // only at an edge, to rounding
    ++agree;
    if (!a) continue;
    ++hits;
    CHECK(t1 == doctest::Approx(t2).epsilon(1e-4));
    CHECK(u1 == doctest::Approx(u2).epsilon(1e-3));
    CHECK(v1 == doctest::Approx(v2).epsilon(1e-3));
    // The barycentrics reproduce the hit point.
    Vec3f p = p0 * (1 - u2 - v2) + p1 * u2 + p2 * v2;
    CHECK(length(p - (r.o + r.d * t2)) < 1e-4f * (1 + t2));
  }
  CHECK(agree >= total - 5);
  CHECK(hits > total / 4);
}

TEST_CASE("watertight test has no cracks through shared edges and vertices") {
  // A fan of triangles around the origin in the z = 0 plane; rays aimed exactly at the shared
  // vertex and at points on the shared edges must hit at least one of the triangles.
  const int kFan = 7;
  std::vector<Vec3f> rim;
  for (int i = 0; i < kFan; ++i) {
    float a = 2 * kPi * i / kFan;
    rim.push_back({std::cos(a) * 1.3f, std::sin(a) * 0.7f, 0.0f});
  }
  Vec3f centre(0.0f);
  int misses_wt = 0, rays = 0;
  Pcg32 rng(2, 2);
  for (int k = 0; k < 4000; ++k) {
    int edge = k % kFan;
    float s = k < 100 ? 0.0f : rng.next_float();
    Vec3f target = centre + (rim[edge] - centre) * s;
    Ray r;
    r.o = Vec3f(rng.next_float() - 0.5f, rng.next_float() - 0.5f, 1.0f + rng.next_float()) * 3.0f;
    r.d = normalize(target - r.o);
    ++rays;
    bool hit = false;
    for (int i = 0; i < kFan && !hit; ++i) {
      float t, u, v;
      hit = intersect_triangle_watertight(r, centre, rim[i], rim[(i + 1) % kFan], t, u, v);
    }
    if (!hit) ++misses_wt;
  }
  CHECK(misses_wt == 0);
}

TEST_CASE("bvh: known hits on a sphere and a triangle, geometry ids and barycentrics") {
  Mesh mesh;
  mesh.positions = {{-1, -1, 0}, {1, -1, 0}, {-1, 1, 0}};
  mesh.indices = {0, 1, 2};
  mesh.material = {0};
  Sphere s;
  s.center = {0, 0, 3};
  s.radius = 0.5f;
  Geometry scene(std::move(mesh), {s});
  for (TriangleTest test : {TriangleTest::kMollerTrumbore, TriangleTest::kWatertight}) {
    AccelOptions o;
    o.backend = Backend::kBvh;
    o.triangle_test = test;
    auto accel = make_accel(scene, o);
    CHECK(accel->stats().primitives == 2);
    Ray r;
    r.o = {-0.5f, -0.5f, 10.0f};
    r.d = {0, 0, -1};
    auto hit = accel->intersect(r);
    REQUIRE(hit);
    CHECK(hit->geom == kGeomTriangles);
    CHECK(hit->prim == 0);
    CHECK(hit->t == doctest::Approx(10.0f));
    CHECK(hit->u == doctest::Approx(0.25f));  // (-0.5, -0.5) = 0.5 p0 + 0.25 p1 + 0.25 p2
    CHECK(hit->v == doctest::Approx(0.25f));
    r.o = {0.0f, 0.0f, 10.0f};
    hit = accel->intersect(r);
    REQUIRE(hit);
    CHECK(hit->geom == kGeomSpheres);
    CHECK(hit->prim == 0);
    CHECK(hit->t == doctest::Approx(6.5f));
    CHECK(accel->occluded(r));
    r.tmax = 6.0f;
    CHECK(!accel->occluded(r));
    CHECK(!accel->intersect(r));
    r.d = {0, 0, 1};
    r.tmax = kInf;
    CHECK(!accel->intersect(r));
    CHECK(!accel->occluded(r));
  }
}
