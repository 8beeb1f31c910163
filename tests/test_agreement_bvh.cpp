// Agreement: the home-written BVH and Embree return the same closest hits and occlusion answers
// on large random ray sets over real meshes, and render the same images.
#include <doctest/doctest.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <atomic>
#include <cmath>
#include <cstdio>

#include "bvh_test_scenes.h"
#include "core/accel/bvh_accel.h"
#include "core/accel/bvh_build.h"
#include "core/scene/loader.h"
#include "core/scene/studio.h"
#include "renderer/render/job.h"

using namespace pt;

namespace {

struct Disagreement {
  std::atomic<size_t> hit_miss{0}, prim{0}, t{0}, uv{0}, occluded{0}, hits{0};
};

// Edge and vertex hits may legitimately go to either neighbour (or, without watertightness, to
// neither), so a handful of primitive and hit/miss differences per million rays is allowed and
// reported; t must agree to 1e-4 relative whenever both found the same primitive. A hit a tiny
// distance from the origin (below 1e-3 of the scene's size) is compared as if it were at that
// distance: there the rounding of the coordinates themselves (an ulp of a 500-unit Cornell box is
// 3e-5) is larger than 1e-4 of t, for either backend.
// Barycentrics of a hit at a grazing angle are ill-conditioned (their rounding error grows like
// 1 / cos of the angle of incidence), so the two backends' u, v are compared only beyond 3 degrees
// from grazing; t and the primitive are compared for every hit.
bool grazing(const Geometry& scene, const Ray& ray, uint32_t prim) {
  Vec3f n = scene.mesh().geometric_normal(prim);
  return std::abs(dot(ray.d, n)) < 0.05f * length(ray.d) * length(n);
}

void check_agreement(const char* what, const Geometry& scene, const std::vector<Ray>& rays, TriangleTest test,
                     const bvh::BuildOptions& build = {}) {
  AccelOptions eo;
  eo.backend = Backend::kEmbree;
  auto embree = make_accel(scene, eo);
  auto bvh = make_bvh_accel(scene, test, build);
  Disagreement d;
  const float t_floor = 1e-3f * length(scene.bounds().extent());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 4096), [&](const tbb::blocked_range<size_t>& r) {
    size_t hit_miss = 0, prim = 0, t = 0, uv = 0, occ = 0, hits = 0;
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Ray& ray = rays[i];
      auto a = embree->intersect(ray), b = bvh->intersect(ray);
      if (bool(a) != bool(b)) {
        ++hit_miss;
      } else if (a) {
        ++hits;
        if (a->geom != b->geom || a->prim != b->prim) {
          ++prim;
        } else {
          if (std::abs(a->t - b->t) > 1e-4f * std::max({a->t, b->t, t_floor})) ++t;
          if (a->geom == kGeomTriangles && (std::abs(a->u - b->u) > 1e-3f || std::abs(a->v - b->v) > 1e-3f) &&
              !grazing(scene, ray, a->prim)) {
            ++uv;
          }
        }
      }
      if (embree->occluded(ray) != bvh->occluded(ray)) ++occ;
    }
    d.hit_miss += hit_miss;
    d.prim += prim;
    d.t += t;
    d.uv += uv;
    d.occluded += occ;
    d.hits += hits;
  });
  size_t n = rays.size();
  std::printf("%-38s %-10s %8zu rays, %8zu hits: %zu hit/miss, %zu primitive, %zu t, %zu uv, %zu occlusion differ\n",
              what, test == TriangleTest::kWatertight ? "watertight" : "mt", n, d.hits.load(), d.hit_miss.load(),
              d.prim.load(), d.t.load(), d.uv.load(), d.occluded.load());
  INFO(what);
  CHECK(d.hits.load() > n / 20);  // the ray set exercises the geometry
  size_t handful = std::max<size_t>(10, n / 20000);
  CHECK(d.hit_miss.load() <= handful);
  CHECK(d.prim.load() <= handful);
  CHECK(d.t.load() == 0);
  CHECK(d.uv.load() == 0);
  CHECK(d.occluded.load() <= handful);
}

}  // namespace

TEST_CASE("agreement: closed icosphere") {
  Geometry scene = test::icosphere_geometry(5, 0.0f);
  auto rays = test::random_rays(scene, 1 << 20, 11);
  check_agreement("icosphere (20k)", scene, rays, TriangleTest::kMollerTrumbore);
  check_agreement("icosphere (20k)", scene, rays, TriangleTest::kWatertight);
}

TEST_CASE("agreement: random triangle soup with spheres") {
  Geometry scene = test::triangle_soup(200000, 5, 200);
  auto rays = test::random_rays(scene, 1 << 20, 12);
  check_agreement("soup (200k) + 200 spheres", scene, rays, TriangleTest::kMollerTrumbore);
}

TEST_CASE("agreement: Cornell box") {
  Scene scene = load_scene(PT_SOURCE_DIR "/scenes/cornell-box/scene.json");
  auto rays = test::random_rays(scene.geometry(), 1 << 20, 13);
  check_agreement("cornell box", scene.geometry(), rays, TriangleTest::kMollerTrumbore);
  check_agreement("cornell box", scene.geometry(), rays, TriangleTest::kWatertight);
}

TEST_CASE("agreement: benchmark mesh (level 7, 328k triangles)") {
  Geometry scene = test::icosphere_geometry(7, 0.15f);
  auto rays = test::random_rays(scene, 1 << 20, 14);
  check_agreement("dense (328k)", scene, rays, TriangleTest::kMollerTrumbore);
}

namespace {

bvh::BuildOptions with_spatial_splits() {
  bvh::BuildOptions o;
  o.spatial_split_budget = 0.5f;
  return o;
}

}  // namespace

TEST_CASE("agreement: scan-like mesh in a closed room, with and without spatial splits") {
  Geometry scene = test::scan_geometry(6, 400);
  auto rays = test::random_rays(scene, 1 << 20, 15);
  check_agreement("scan in room", scene, rays, TriangleTest::kMollerTrumbore);
  check_agreement("scan in room", scene, rays, TriangleTest::kWatertight);
  check_agreement("scan in room, spatial splits", scene, rays, TriangleTest::kMollerTrumbore, with_spatial_splits());
}

TEST_CASE("agreement: far from the origin") {
  // The displaced icosphere 1e4 to 5e4 units out (coordinates then have ulps of 1e-3 to 4e-3).
  Mesh mesh;
  add_displaced_icosphere(mesh, 5, Vec3f(1e4f, -3e4f, 5e4f), 30.0f, 0.15f, 0);
  Geometry scene(std::move(mesh), {});
  auto rays = test::random_rays(scene, 1 << 19, 16);
  check_agreement("icosphere at 5e4", scene, rays, TriangleTest::kMollerTrumbore);
  check_agreement("icosphere at 5e4", scene, rays, TriangleTest::kWatertight);
  check_agreement("icosphere at 5e4, spatial splits", scene, rays, TriangleTest::kMollerTrumbore, with_spatial_splits());
}

TEST_CASE("agreement: degenerate triangles among ordinary ones") {
  // A soup where every third triangle is degenerate: collinear corners, two equal corners, all three
  // equal, or a zero-length edge along an axis. No backend may report them (they have no area),
  // and they must not hide the others.
  Mesh mesh = test::triangle_soup(60000, 21).mesh();
  Pcg32 rng(22, 22);
  for (size_t t = 0; t < mesh.triangle_count(); t += 3) {
    Vec3f a = mesh.vertex(t, 0), b = mesh.vertex(t, 1);
    uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    Vec3f c;
    switch (t / 3 % 4) {
      case 0: c = a + (b - a) * rng.next_float(); break;  // collinear
      case 1: c = b; break;
      case 2: b = a, c = a; break;
      default: b = Vec3f(a.x, a.y, a.z), c = Vec3f(a.x + 0.05f, a.y, a.z); break;
    }
    mesh.positions.insert(mesh.positions.end(), {a, b, c});
    for (int k = 0; k < 3; ++k) mesh.indices[3 * t + k] = base + k;
  }
  Geometry scene(std::move(mesh), {});
  auto rays = test::random_rays(scene, 1 << 19, 23);
  check_agreement("soup with degenerates", scene, rays, TriangleTest::kMollerTrumbore);
  check_agreement("soup with degenerates", scene, rays, TriangleTest::kWatertight);
  check_agreement("soup with degenerates, spatial splits", scene, rays, TriangleTest::kMollerTrumbore,
                  with_spatial_splits());
}

TEST_CASE("agreement: the studio's large ground under a small dense mesh, rays at its shared edges and vertices") {
  // The default studio (a bare OBJ): ground squares of 4, 100 and 10000 model radii under a mesh of
  // 20k triangles. Rays from camera-like positions (many of them grazing the far rings) aimed at
  // points on the ground's edges, rounded to float, so they pass within an ulp or two of the edge
  // on either side, and at its vertices. Every one must hit: the ground covers everything below.
  SceneBuilder b;
  add_displaced_icosphere(b.mesh, 5, Vec3f(0.3f, 1.2f, -0.4f), 0.8f, 0.15f, b.default_material());
  size_t first_ground = b.mesh.triangle_count();
  add_studio(b, Studio::kSun, UpAxis::kY);
  Geometry scene(std::move(b.mesh), {});
  const Mesh& mesh = scene.mesh();
  REQUIRE(mesh.triangle_count() > first_ground + 10);
  float reach = 0;  // half the size of the outermost square
  Vec3f centre(0.3f, 1.2f, -0.4f);
  for (size_t t = first_ground; t < mesh.triangle_count(); ++t)
    for (int k = 0; k < 3; ++k) reach = std::max(reach, std::abs(mesh.vertex(t, k).x - centre.x));
  std::vector<Ray> rays;
  Pcg32 rng(31, 31);
  for (size_t t = first_ground; t < mesh.triangle_count(); ++t) {
    for (int e = 0; e < 3; ++e) {
      Vec3f a = mesh.vertex(t, e), c = mesh.vertex(t, (e + 1) % 3);
      for (int k = 0; k < 1500; ++k) {
        // Vertices exactly, then points along the edge, most near the model where a camera looks.
        float s = k < 20 ? 0.0f : (k % 2 ? rng.next_float() : std::pow(rng.next_float(), 6.0f));
        Vec3f p = a + (c - a) * s;
        // The outer rim of the last square has nothing beyond it: rays there may miss.
        if (std::max(std::abs(p.x - centre.x), std::abs(p.z - centre.z)) > 0.99f * reach) continue;
        float angle = 2 * kPi * rng.next_float(), distance = 1.5f + 4.0f * rng.next_float();
        Ray r;
        r.o = centre + Vec3f(std::cos(angle) * distance, 0.05f + 2.0f * rng.next_float(), std::sin(angle) * distance);
        r.d = normalize(p - r.o);
        rays.push_back(r);
      }
    }
  }
  REQUIRE(rays.size() > 20000);
  AccelOptions robust;
  robust.embree_robust = true;
  AccelOptions fast;
  auto embree_robust = make_accel(scene, robust), embree = make_accel(scene, fast);
  auto bvh = make_bvh_accel(scene, TriangleTest::kWatertight), bvh_mt = make_bvh_accel(scene, TriangleTest::kMollerTrumbore);
  std::atomic<size_t> misses{0}, occluded_misses{0}, robust_differ{0}, embree_misses{0}, mt_misses{0};
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 1024), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      bool hit = bvh->intersect(rays[i]).has_value();
      misses += !hit;
      occluded_misses += !bvh->occluded(rays[i]);
      robust_differ += hit != embree_robust->intersect(rays[i]).has_value();
      embree_misses += !embree->intersect(rays[i]).has_value();
      mt_misses += !bvh_mt->intersect(rays[i]).has_value();
    }
  });
  std::printf("studio ground edges: %zu rays; misses: bvh %zu (occluded %zu), embree %zu, bvh mt %zu; "
              "bvh and robust embree differ on %zu\n",
              rays.size(), misses.load(), occluded_misses.load(), embree_misses.load(), mt_misses.load(), robust_differ.load());
  CHECK(misses.load() == 0);
  CHECK(occluded_misses.load() == 0);
  CHECK(robust_differ.load() == 0);
}

namespace {

RenderResult render_with(const std::shared_ptr<const Scene>& scene, const char* backend, const std::string& integrator,
                         int spp, uint64_t seed) {
  JobOptions o;
  o.accel.backend = kBackendNames.parse(backend);
  o.integrator = kIntegratorNames.parse(integrator);
  o.resolution = "64x64";
  o.spp = spp;
  o.seed = seed;
  return render(prepare_job(scene, o));
}

}  // namespace

TEST_CASE("agreement: normals and albedo images are equal, direct images statistically equal") {
  auto scene = std::make_shared<const Scene>(read_scene(PT_SOURCE_DIR "/scenes/cornell-box/scene.json"));
  for (const char* integrator : {"normals", "albedo"}) {
    // Same seed: the same camera rays, so any difference is a different hit.
    Film a = render_with(scene, "embree", integrator, 4, 1).film;
    Film b = render_with(scene, "bvh", integrator, 4, 1).film;
    int differing = 0;
    double max_diff = 0;
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        float diff = max_component(vabs(a.mean(x, y) - b.mean(x, y)));
        max_diff = std::max<double>(max_diff, diff);
        if (diff > 1e-4f) ++differing;
      }
    }
    INFO(integrator << ": " << differing << " pixels differ, max " << max_diff);
    CHECK(differing <= 2);  // at most an edge sample or two
  }
  // Different seeds: independent estimates of the same image; per-pixel z-scores of the
  // difference must look like a standard normal's (few beyond 4 sigma, mean near 0).
  Film a = render_with(scene, "embree", "direct", 16, 1).film;
  Film b = render_with(scene, "bvh", "direct", 16, 2).film;
  int outliers = 0, tested = 0;
  double z_sum = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      Spectrum va = a.variance_of_mean(x, y), vb = b.variance_of_mean(x, y);
      for (int c = 0; c < 3; ++c) {
        double var = va[c] + vb[c];
        if (!(var > 1e-12)) continue;
        double z = (a.mean(x, y)[c] - b.mean(x, y)[c]) / std::sqrt(var);
        ++tested;
        z_sum += z;
        if (std::abs(z) > 4) ++outliers;
      }
    }
  }
  INFO("direct: " << outliers << " of " << tested << " channel z-scores beyond 4, mean z " << z_sum / tested);
  CHECK(tested > 1000);
  CHECK(outliers <= tested / 100);
  CHECK(std::abs(z_sum / tested) < 0.1);
}
