// Instanced geometry: Embree's instances and the two-level BVH find the same hits (rays taken into
// each instance's space), both agree with the same instances baked into world space, and so do the
// surfaces, lights, mirror planes and images made from them.
#include <doctest/doctest.h>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdio>
#include <set>

#include "bvh_test_scenes.h"
#include "core/accel/accel.h"
#include "core/geometry/instance.h"
#include "renderer/tools/gen_dense.h"
#include "renderer/render/job.h"
#include "scene_helpers.h"

using namespace pt;

namespace {

Transform random_placement(Pcg32& rng, float extent) {
  Vec3f s{0.5f + rng.next_float(), 0.5f + rng.next_float(), 0.5f + rng.next_float()};
  if (rng.next_float() < 0.25f) s.x = -s.x;  // mirrored copies: the winding must stay front-facing
  Vec3f r{360 * rng.next_float(), 360 * rng.next_float(), 360 * rng.next_float()};
  Vec3f t = Vec3f(rng.next_float(), rng.next_float(), rng.next_float()) * extent - Vec3f(0.5f * extent);
  return Transform::translate(t) * Transform::rotate_axis(2, r.z) * Transform::rotate_axis(1, r.y) *
         Transform::rotate_axis(0, r.x) * Transform::scale(s);
}

// Two object meshes (a displaced icosphere and a thin slab) placed 150 and 60 times, a world-space
// floor and a few spheres; and the same with every instance baked into the world mesh, with the
// index of each instance's first triangle there.
struct Scenes {
  Geometry instanced, flat;
  std::vector<size_t> first_flat;  // per instance
};

Mesh slab_mesh() {
  SceneBuilder b;
  test::add_box(b, {-1, -0.05f, -0.5f}, {1, 0.05f, 0.5f}, 0, false);
  return b.mesh;
}

Scenes make_scenes(bool world_geometry) {
  Mesh blob;
  add_displaced_icosphere(blob, 3, Vec3f(0.2f, 0, 0), 1.0f, 0.15f, 0);
  std::vector<Mesh> meshes = {blob, slab_mesh()};
  Pcg32 rng(41, 5);
  std::vector<Instance> instances;
  for (int k = 0; k < 210; ++k) {
    Transform t = random_placement(rng, 40.0f);
    instances.push_back({k < 150 ? 0u : 1u, t, t.inverse()});
  }
  Mesh world;
  std::vector<Sphere> spheres;
  if (world_geometry) {
    SceneBuilder b;
    test::add_quad(b, {-30, -22, -30}, {-30, -22, 30}, {30, -22, 30}, {30, -22, -30}, 0);
    world = b.mesh;
    for (int k = 0; k < 4; ++k) spheres.push_back(Sphere{Vec3f(-15.0f + 10 * k, 0, 0), 2.0f, 0});
  }
  Scenes s;
  Mesh flat = world;
  for (const Instance& i : instances) {
    s.first_flat.push_back(flat.triangle_count());
    append_transformed(flat, meshes[i.mesh], i.to_world);
  }
  s.flat = Geometry(std::move(flat), spheres);
  s.instanced = Geometry(std::move(world), spheres, std::move(meshes), std::move(instances));
  return s;
}

struct Counts {
  std::atomic<size_t> hits{0}, hit_miss{0}, prim{0}, t{0}, uv{0}, occluded{0};
};

// The closest hit as a triangle of the flattened scene (world triangles and spheres keep theirs).
uint64_t flat_id(const Scenes& s, const Hit& h) {
  uint64_t prim = h.inst == kNoInstance ? h.prim : s.first_flat[h.inst] + h.prim;
  return (uint64_t(h.geom) << 40) | prim;
}

// Within 3 degrees of grazing, t and the barycentrics are ill-conditioned (their rounding grows like
// 1 / cos), and Embree takes the ray into an instance with an inverse of its own: compared only beyond.
bool grazing(const Scenes& s, const Ray& ray, const Hit& h) {
  if (h.geom != kGeomTriangles) return false;
  Vec3f n = h.inst == kNoInstance ? s.instanced.mesh().geometric_normal(h.prim)
                                  : s.instanced.instances()[h.inst].to_world.normal(s.instanced.instance_mesh(h.inst).geometric_normal(h.prim));
  return std::abs(dot(ray.d, n)) < 0.05f * length(ray.d) * length(n);
}

// Counts where `b` disagrees with `a` on rays: hit or miss, the primitive (as a flattened triangle),
// t (1e-4 relative), barycentrics (only between two instanced backends: baking reverses a mirrored
// copy's corners) and occlusion.
void compare(const Scenes& s, const Accel& a, const Accel& b, bool b_flat, const std::vector<Ray>& rays, Counts& c) {
  // t is compared as if at least 1e-2 of the scene's size: Embree inverts an instance's transform
  // itself, in float, so the two backends' object-space origins differ by the rounding of origins
  // up to 60 units out (ulp 4e-6) times the inverse's scale (up to 2), about 1e-5 in t, which is
  // 1e-4 of t only from t = 0.1 (the scene is 70 across).
  const float t_floor = 1e-2f * length(s.flat.bounds().extent());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, rays.size(), 2048), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      const Ray& ray = rays[i];
      auto ha = a.intersect(ray), hb = b.intersect(ray);
      if (bool(ha) != bool(hb)) {
        ++c.hit_miss;
      } else if (ha) {
        ++c.hits;
        uint64_t ida = flat_id(s, *ha), idb = b_flat ? (uint64_t(hb->geom) << 40) | hb->prim : flat_id(s, *hb);
        if (ida != idb) {
          ++c.prim;
        } else {
          if (std::abs(ha->t - hb->t) > 1e-4f * std::max({ha->t, hb->t, t_floor}) && !grazing(s, ray, *ha)) ++c.t;
          if (!b_flat && (std::abs(ha->u - hb->u) > 1e-3f || std::abs(ha->v - hb->v) > 1e-3f)) ++c.uv;
        }
      }
      if (a.occluded(ray) != b.occluded(ray)) ++c.occluded;
    }
  });
}

void check_counts(const char* what, const Counts& c, size_t n) {
  std::printf("%-44s %8zu rays, %8zu hits: %zu hit/miss, %zu primitive, %zu t, %zu uv, %zu occlusion differ\n", what, n,
              c.hits.load(), c.hit_miss.load(), c.prim.load(), c.t.load(), c.uv.load(), c.occluded.load());
  INFO(what);
  CHECK(c.hits.load() > n / 40);  // a sparse field: a few percent of the random rays hit
  // Edge and vertex hits may go to either neighbour, as in test_agreement_bvh.cpp.
  size_t handful = std::max<size_t>(10, n / 20000);
  CHECK(c.hit_miss.load() <= handful);
  CHECK(c.prim.load() <= handful);
  CHECK(c.t.load() == 0);
  CHECK(c.uv.load() == 0);
  CHECK(c.occluded.load() <= handful);
}

}  // namespace

TEST_CASE("instances: Embree, the two-level BVH and the baked scene find the same hits") {
  for (bool world : {true, false}) {
    Scenes s = make_scenes(world);
    auto rays = test::random_rays(s.instanced, 1 << 18, world ? 61 : 62);
    AccelOptions eo;
    auto embree = make_accel(s.instanced, eo);
    auto embree_flat = make_accel(s.flat, eo);
    for (TriangleTest test : {TriangleTest::kMollerTrumbore, TriangleTest::kWatertight}) {
      AccelOptions bo;
      bo.backend = Backend::kBvh;
      bo.triangle_test = test;
      auto bvh = make_accel(s.instanced, bo);
      CHECK(bvh->name().find("two levels") != std::string::npos);
      Counts c;
      compare(s, *embree, *bvh, false, rays, c);
      check_counts(world ? "instances + world: embree vs bvh" : "instances only: embree vs bvh", c, rays.size());
    }
    Counts c;
    compare(s, *embree, *embree_flat, true, rays, c);
    check_counts(world ? "instances + world: instanced vs baked" : "instances only: instanced vs baked", c, rays.size());
    // Every instance is reached by some ray: the hits name instances, not just the first.
    std::vector<char> seen(s.instanced.instances().size(), 0);
    for (const Ray& ray : rays) {
      if (auto h = embree->intersect(ray); h && h->inst != kNoInstance) seen[h->inst] = 1;
    }
    CHECK(std::count(seen.begin(), seen.end(), 1) > static_cast<long>(seen.size() * 9 / 10));
    CHECK(embree->stats().primitives == s.flat.mesh().triangle_count() + s.flat.spheres().size());
  }
}

namespace {

// A SceneBuilder with a floor, an emitting quad placed `lights` times facing down, a mirror placed
// twice, and a blob with normals and uvs placed three times; `bake` puts every placement into the
// world mesh instead (resolve_instances would keep them instanced).
SceneBuilder lit_builder(bool bake) {
  SceneBuilder b;
  b.source = "test";
  uint32_t grey = test::add_material(b, test::diffuse(Spectrum(0.6f)));
  uint32_t lamp = test::add_material(b, test::diffuse(Spectrum(0.0f), Spectrum(4.0f, 3.0f, 2.0f)));
  Material mirror;
  mirror.model = Mirror{Spectrum(0.9f)};
  uint32_t shiny = test::add_material(b, mirror);
  test::add_quad(b, {-4, 0, -4}, {-4, 0, 4}, {4, 0, 4}, {4, 0, -4}, grey);
  SceneBuilder parts;
  test::add_quad(parts, {-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 0, 0.5f}, {-0.5f, 0, 0.5f}, lamp);  // faces -y
  Mesh lamp_mesh = parts.mesh;
  parts.mesh = Mesh();
  test::add_quad(parts, {0, 0, -1}, {0, 0, 1}, {0, 2, 1}, {0, 2, -1}, shiny);
  Mesh mirror_mesh = parts.mesh;
  Mesh blob;
  add_displaced_icosphere(blob, 3, Vec3f(0.0f), 0.5f, 0.1f, grey);
  blob.corner_normals.resize(blob.indices.size());
  blob.corner_uvs.resize(blob.indices.size());
  for (size_t c = 0; c < blob.indices.size(); ++c) {
    Vec3f p = blob.positions[blob.indices[c]];
    blob.corner_normals[c] = normalize(p);
    blob.corner_uvs[c] = {p.x + 0.5f, p.y + 0.5f};
  }
  std::vector<std::pair<Mesh*, Transform>> placed = {
      {&lamp_mesh, Transform::translate({-1.5f, 3, 0})},
      {&lamp_mesh, Transform::translate({1.5f, 3.5f, 0.5f}) * Transform::rotate_axis(1, 30) * Transform::scale({1.5f, 1, 0.8f})},
      {&mirror_mesh, Transform::translate({-3, 0, 0})},
      {&mirror_mesh, Transform::translate({3, 0, 0}) * Transform::scale({-1, 1, 1})},
      {&blob, Transform::translate({0, 0.5f, 0})},
      {&blob, Transform::translate({-1.5f, 0.4f, 1.5f}) * Transform::rotate_axis(0, 70) * Transform::scale({0.8f, 1.2f, 0.8f})},
      {&blob, Transform::translate({1.5f, 0.5f, -1.5f}) * Transform::scale({-1, 1, 1})},
  };
  if (bake) {
    for (auto& [mesh, t] : placed) append_transformed(b.mesh, *mesh, t);
  } else {
    uint32_t ids[3] = {b.add_mesh(lamp_mesh), b.add_mesh(mirror_mesh), b.add_mesh(blob)};
    for (auto& [mesh, t] : placed) b.add_instance(ids[mesh == &lamp_mesh ? 0 : mesh == &mirror_mesh ? 1 : 2], t);
  }
  test::set_view(b, {0, 4, 9}, {0, 0.5f, 0}, 45, 64, 64);
  return b;
}

}  // namespace

TEST_CASE("instances: lights and mirror planes per (instance, triangle); surfaces as if baked") {
  auto inst = test::finish(lit_builder(false));
  auto flat = test::finish(lit_builder(true));
  REQUIRE(inst->geometry().instances().size() == 7);
  CHECK(inst->mesh().triangle_count() == 2);  // the floor only
  // One light per instance and triangle: two quads of two triangles, with the baked scene's power.
  auto triangle_lights = [](const Scene& s) {
    size_t n = 0;
    double power = 0;
    for (const TriangleLight& l : s.light_set().triangles().lights()) ++n, power += l.power();
    return std::make_pair(n, power);
  };
  CHECK(triangle_lights(*inst).first == 4);
  CHECK(triangle_lights(*flat).first == 4);
  CHECK(triangle_lights(*inst).second == doctest::Approx(triangle_lights(*flat).second).epsilon(1e-5));
  std::set<uint32_t> light_instances;
  for (const TriangleLight& l : inst->light_set().triangles().lights()) light_instances.insert(l.instance);
  CHECK(light_instances == std::set<uint32_t>{0, 1});
  // Two mirror planes (x = -3 and x = 3), each found through its instance.
  REQUIRE(inst->mirror_planes().size() == 2);
  CHECK(inst->mirror_plane_of(kGeomTriangles, 0, 2) != inst->mirror_plane_of(kGeomTriangles, 1, 3));
  CHECK(inst->mirror_plane_of(kGeomTriangles, 0, 2) >= 0);
  CHECK(inst->mirror_plane_of(kGeomTriangles, 0, 0) == -1);  // a lamp
  CHECK(inst->mirror_plane_of(kGeomTriangles, 0, kNoInstance) == -1);  // the floor

  // Camera rays and rays toward light samples: the same surfaces in both scenes, and light samples
  // whose density light_pdf reproduces from the surface the ray finds (what MIS relies on).
  AccelOptions eo;
  auto ai = make_accel(inst->geometry(), eo);
  auto af = make_accel(flat->geometry(), eo);
  Pcg32 rng(9, 9);
  size_t compared = 0, light_hits = 0;
  for (int k = 0; k < 20000; ++k) {
    Ray ray{{0, 4, 9}, normalize(Vec3f(rng.next_float() * 8 - 4, rng.next_float() * 4 - 3.5f, -9))};
    auto hi = ai->intersect(ray), hf = af->intersect(ray);
    REQUIRE(bool(hi) == bool(hf));
    if (!hi) continue;
    SurfaceInteraction si = inst->interaction(ray, *hi), sf = flat->interaction(ray, *hf);
    if (si.material != sf.material) continue;  // an edge between two surfaces
    ++compared;
    CHECK(length(si.p - sf.p) < 1e-4f);
    CHECK(dot(si.ng, sf.ng) > 0.9999f);
    CHECK(dot(si.ns, sf.ns) > 0.999f);
    // uvs only on the blobs: baking pads the uvs of meshes without them with zeros, where a mesh
    // of its own without uvs gives the barycentrics.
    if (hi->inst >= 4 && hi->inst != kNoInstance) CHECK(std::abs(si.uv.x - sf.uv.x) + std::abs(si.uv.y - sf.uv.y) < 1e-3f);
    // Light samples from here, traced: the emitter found, and the density both ways.
    LightSample ls;
    if (!inst->sample_light(si.p, Vec3f(0.0f), rng.next_float(), {rng.next_float(), rng.next_float()}, ls) || ls.delta) continue;
    Ray shadow{offset_ray_origin(si.p, dot(ls.wi, si.ng) > 0 ? si.ng : -si.ng), ls.wi};
    auto hl = ai->intersect(shadow);
    if (!hl || hl->inst > 1) continue;  // something in the way, or the sky
    SurfaceInteraction sl = inst->interaction(shadow, *hl);
    if (!(dot(sl.ng, -ls.wi) > 0.05f)) continue;
    ++light_hits;
    CHECK(inst->light_pdf(si.p, Vec3f(0.0f), sl) == doctest::Approx(ls.pdf).epsilon(2e-3));
  }
  CHECK(compared > 2000);
  CHECK(light_hits > 1000);
}

TEST_CASE("instances: images of the instanced and the baked scene agree on both backends") {
  auto inst = test::finish(lit_builder(false));
  auto flat = test::finish(lit_builder(true));
  auto run = [](const std::shared_ptr<const Scene>& scene, Backend backend, IntegratorKind integrator, int spp) {
    JobOptions o;
    o.accel.backend = backend;
    o.integrator = integrator;
    o.spp = spp;
    o.seed = 3;
    return render(test::make_job(scene, o)).film;
  };
  for (Backend backend : {Backend::kEmbree, Backend::kBvh}) {
    // First-hit images: the same camera rays find the same surfaces.
    for (IntegratorKind integrator : {IntegratorKind::kNormals, IntegratorKind::kAlbedo}) {
      Film a = run(flat, Backend::kEmbree, integrator, 2), b = run(inst, backend, integrator, 2);
      int differing = 0;
      for (int y = 0; y < 64; ++y) {
        for (int x = 0; x < 64; ++x) differing += max_component(vabs(a.mean(x, y) - b.mean(x, y))) > 1e-3f;
      }
      INFO(kBackendNames.name(backend) << " " << kIntegratorNames.name(integrator));
      CHECK(differing <= 64 * 64 / 100);
    }
    // Path traced: the means over the image agree to within their noise.
    Film a = run(flat, Backend::kEmbree, IntegratorKind::kPath, 16), b = run(inst, backend, IntegratorKind::kPath, 16);
    double sa = 0, sb = 0, var = 0;
    for (int y = 0; y < 64; ++y) {
      for (int x = 0; x < 64; ++x) {
        sa += luminance(a.mean(x, y));
        sb += luminance(b.mean(x, y));
        double d = luminance(a.mean(x, y)) - luminance(b.mean(x, y));
        var += d * d;
      }
    }
    INFO(kBackendNames.name(backend) << ": baked " << sa << ", instanced " << sb);
    CHECK(sa > 20);  // lit
    // The difference of the two sums is a sum of 4096 independent-ish pixel differences.
    CHECK(std::abs(sa - sb) <= 4.0 * std::sqrt(var) + 1e-3 * sa);
  }
}

TEST_CASE("instances: the light tree holds one emitter per placed lamp, and MIS sees its choices") {
  // A lamp (a quad facing -y: one triangle group) placed twelve times around a ring at different
  // heights and tilts: twelve emitters, so auto chooses the tree; and the same baked.
  auto builder = [](bool bake) {
    SceneBuilder b;
    b.source = "test";
    uint32_t grey = test::add_material(b, test::diffuse(Spectrum(0.6f)));
    uint32_t lamp = test::add_material(b, test::diffuse(Spectrum(0.0f), Spectrum(4.0f, 3.0f, 2.0f)));
    test::add_quad(b, {-6, 0, -6}, {-6, 0, 6}, {6, 0, 6}, {6, 0, -6}, grey);
    SceneBuilder parts;
    test::add_quad(parts, {-0.3f, 0, -0.3f}, {0.3f, 0, -0.3f}, {0.3f, 0, 0.3f}, {-0.3f, 0, 0.3f}, lamp);
    uint32_t id = bake ? 0 : b.add_mesh(parts.mesh);
    for (int k = 0; k < 12; ++k) {
      float a = 0.5236f * k;
      Transform t = Transform::translate({4 * std::cos(a), 2.0f + 0.25f * k, 4 * std::sin(a)}) *
                    Transform::rotate_axis(2, 10.0f * (k % 5)) * Transform::scale({1 + 0.2f * (k % 3), 1, 1});
      if (bake) {
        append_transformed(b.mesh, parts.mesh, t);
      } else {
        b.add_instance(id, t);
      }
    }
    test::set_view(b, {0, 6, 11}, {0, 0.5f, 0}, 50, 64, 64);
    return b;
  };
  auto inst = test::finish(builder(false));
  auto flat = test::finish(builder(true));
  for (const Scene* s : {inst.get(), flat.get()}) {
    CHECK(s->light_set().selection() == LightSelection::kTree);
    CHECK(s->light_set().emitters() == 12);
  }
  std::set<uint32_t> instances;
  for (const TriangleLight& l : inst->light_set().triangles().lights()) instances.insert(l.instance);
  CHECK(instances.size() == 12);
  // Light samples from floor points: the lamp the shadow ray finds has light_pdf's density, and
  // every placed lamp is chosen from somewhere.
  auto accel = make_accel(inst->geometry(), AccelOptions{});
  Pcg32 rng(5, 7);
  std::set<uint32_t> chosen;
  size_t light_hits = 0;
  const Vec3f up{0, 1, 0};
  for (int k = 0; k < 20000; ++k) {
    Vec3f p{rng.next_float() * 10 - 5, 0, rng.next_float() * 10 - 5};
    LightSample ls;
    if (!inst->sample_light(p, up, rng.next_float(), {rng.next_float(), rng.next_float()}, ls)) continue;
    Ray shadow{offset_ray_origin(p, up), ls.wi};
    auto hit = accel->intersect(shadow);
    // The sampled lamp itself, not another in front of it.
    if (!hit || hit->inst == kNoInstance || !(std::abs(hit->t - ls.distance) < 1e-3f * ls.distance)) continue;
    SurfaceInteraction sl = inst->interaction(shadow, *hit);
    if (!(dot(sl.ng, -ls.wi) > 0.05f)) continue;
    ++light_hits;
    chosen.insert(hit->inst);
    CHECK(inst->light_pdf(p, up, sl) == doctest::Approx(ls.pdf).epsilon(2e-3));
  }
  CHECK(light_hits > 5000);
  CHECK(chosen.size() == 12);
  // Path traced, the instanced and the baked scene agree over the image (the trees differ only in
  // the order of the lights).
  auto run = [](const std::shared_ptr<const Scene>& scene) {
    JobOptions o;
    o.integrator = IntegratorKind::kPath;
    o.spp = 16;
    o.seed = 3;
    return render(test::make_job(scene, o)).film;
  };
  Film a = run(flat), b = run(inst);
  double sa = 0, sb = 0, var = 0;
  for (int y = 0; y < 64; ++y) {
    for (int x = 0; x < 64; ++x) {
      sa += luminance(a.mean(x, y));
      sb += luminance(b.mean(x, y));
      double d = luminance(a.mean(x, y)) - luminance(b.mean(x, y));
      var += d * d;
    }
  }
  INFO("baked " << sa << ", instanced " << sb);
  CHECK(sa > 20);
  CHECK(std::abs(sa - sb) <= 4.0 * std::sqrt(var) + 1e-3 * sa);
}

// A ray leaving the surface of an instance far from the world's origin: the BVH takes its origin into
// the mesh's space as the inverse's linear part times (o - the instance's position), rounded at the
// mesh's scale, where to_object applied whole rounds at the world's (150 units out, ulp 1.5e-5) and
// puts an origin 1e-5 above the surface below it. Origins from 2e-5 below to 2e-5 above a tilted,
// rotated, scaled plane; the truth is the side of the plane the float origin is on, in double.
TEST_CASE("instances: the BVH takes a ray leaving a far instance into its space at the mesh's precision") {
  SceneBuilder b;
  test::add_quad(b, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, 0);
  Transform to_world = Transform::translate({150.0f, -120.0f, 130.0f}) * Transform::rotate_axis(0, 37.0f) *
                       Transform::rotate_axis(2, 23.0f) * Transform::rotate_axis(1, 61.0f) * Transform::scale({1.3f, 0.8f, 1.1f});
  std::vector<Instance> instances = {{0, to_world, to_world.inverse()}, {0, to_world, to_world.inverse()}};
  instances[1].to_world = Transform::translate({-150.0f, 0, 0}) * to_world;  // two: an instance, not baked
  instances[1].to_object = instances[1].to_world.inverse();
  Geometry geometry(Mesh{}, {}, {b.mesh}, instances);
  AccelOptions bo;
  bo.backend = Backend::kBvh;
  auto bvh = make_accel(geometry, bo);
  auto embree = make_accel(geometry, AccelOptions{});
  REQUIRE(bvh->name().find("two levels") != std::string::npos);

  // The object's y in double: row 1 of the inverse is cross(c2, c0) / det for columns c of the linear part.
  auto column = [&](int j) { return std::array<double, 3>{to_world.m[0][j], to_world.m[1][j], to_world.m[2][j]}; };
  auto c0 = column(0), c1 = column(1), c2 = column(2);
  std::array<double, 3> row1 = {c2[1] * c0[2] - c2[2] * c0[1], c2[2] * c0[0] - c2[0] * c0[2], c2[0] * c0[1] - c2[1] * c0[0]};
  double det = c1[0] * row1[0] + c1[1] * row1[1] + c1[2] * row1[2];
  Pcg32 rng(7, 3);
  size_t judged = 0, bvh_wrong = 0, bvh_occlusion_wrong = 0, embree_wrong = 0;
  for (int i = 0; i < 20000; ++i) {
    Vec3f p{1.8f * rng.next_float() - 0.9f, 4e-5f * rng.next_float() - 2e-5f, 1.8f * rng.next_float() - 0.9f};
    Vec3f d_obj{rng.next_float() - 0.5f, 0.2f + 0.8f * rng.next_float(), rng.next_float() - 0.5f};  // leaving upward
    Ray ray;
    ray.o = to_world.point(p);
    ray.d = normalize(to_world.vector(d_obj));
    ray.tmin = 0.0f;
    double y = 0;
    for (int k = 0; k < 3; ++k) y += row1[k] * (double(ray.o[k]) - double(to_world.m[k][3]));
    y /= det;
    if (std::abs(y) < 1e-6) continue;  // within a few float roundings at the mesh's scale
    ++judged;
    bool below = y < 0;  // then the ray crosses the plane on its way up
    bvh_wrong += bool(bvh->intersect(ray)) != below;
    bvh_occlusion_wrong += bvh->occluded(ray) != below;
    embree_wrong += bool(embree->intersect(ray)) != below;
  }
  std::printf("rays leaving a far instance: %zu judged; wrong: bvh %zu (occlusion %zu), embree %zu\n", judged, bvh_wrong,
              bvh_occlusion_wrong, embree_wrong);
  CHECK(judged > 18000);
  CHECK(bvh_wrong == 0);
  CHECK(bvh_occlusion_wrong == 0);
}
