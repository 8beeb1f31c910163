// Extra camera views in the pixels at an emitter's edge (renderer/render/emitter_edges.h): the same
// image as without them, less variance in those pixels, the same bits for any thread count, for
// region parts merged and for a resumed render, and no change where the camera sees no emitter.
// Images are compared with the z-tests of film_checks.h.
#include <doctest/doctest.h>

#include <cstring>
#include <string>

#include "film_checks.h"
#include "renderer/commands/cli_options.h"
#include "renderer/render/emitter_edges.h"
#include "renderer/render/job.h"
#include "scene_helpers.h"

using namespace pt;
using namespace pt::test;

namespace {

// A grey room lit by a small bright sphere (radiance 60) and a small bright quad (radiance 40, on
// the back wall), both seen directly, each a few pixels wide at 32x32; `look_away` turns the camera
// to the floor in a corner, where it sees neither.
ScenePtr lamp_room(bool look_away = false) {
  SceneBuilder b;
  uint32_t grey = add_material(b, diffuse(Spectrum(0.6f)));
  uint32_t sphere_lamp = add_material(b, diffuse(Spectrum(0.0f), Spectrum(60.0f, 55.0f, 50.0f)));
  uint32_t quad_lamp = add_material(b, diffuse(Spectrum(0.0f), Spectrum(30.0f, 40.0f, 45.0f)));
  add_box(b, {-2, 0, -2}, {2, 3, 2}, grey, true);
  add_sphere(b, {-0.6f, 1.9f, -0.8f}, 0.12f, sphere_lamp);
  // On the back wall (z = -2), facing +z.
  add_quad(b, {0.4f, 1.0f, -1.999f}, {0.75f, 1.0f, -1.999f}, {0.75f, 1.4f, -1.999f}, {0.4f, 1.4f, -1.999f}, quad_lamp);
  if (look_away) {
    set_view(b, {1.5f, 2.5f, 1.5f}, {1.8f, 0.0f, 1.8f}, 40, 32, 32);
  } else {
    set_view(b, {0, 1.5f, 1.9f}, {0, 1.4f, -2}, 60, 32, 32);
  }
  b.settings.integrator = IntegratorKind::kPath;
  b.settings.max_depth = 3;
  return finish(std::move(b));
}

// The grey room with one lamp a fifth of a pixel wide (a sphere of radius 0.015 at 3.6 m, radiance
// 2000), which rays through the pixels' centres miss; `hidden` puts a panel between it and the camera.
ScenePtr tiny_lamp(bool hidden) {
  SceneBuilder b;
  uint32_t grey = add_material(b, diffuse(Spectrum(0.6f)));
  uint32_t lamp = add_material(b, diffuse(Spectrum(0.0f), Spectrum(2000.0f)));
  add_box(b, {-2, 0, -2}, {2, 3, 2}, grey, true);
  add_sphere(b, {0.31f, 1.63f, -1.7f}, 0.015f, lamp);
  if (hidden) add_quad(b, {-0.5f, 1.0f, 0.0f}, {1.0f, 1.0f, 0.0f}, {1.0f, 2.2f, 0.0f}, {-0.5f, 2.2f, 0.0f}, grey);
  set_view(b, {0, 1.5f, 1.9f}, {0, 1.4f, -2}, 60, 32, 32);
  b.settings.integrator = IntegratorKind::kPath;
  b.settings.max_depth = 3;
  return finish(std::move(b));
}

Job lamp_job(const ScenePtr& scene, int views, int spp, uint64_t seed, SamplerKind sampler,
             const std::optional<std::string>& part = {}) {
  JobOptions o;
  o.spp = spp;
  o.seed = seed;
  o.sampler = sampler;
  o.emitter_edges = views;
  o.part = part;
  return make_job(scene, o);
}

RenderResult render_threads(const Job& job, int threads, const Film* resume = nullptr) {
  RenderControl control;
  control.threads = threads;
  control.resume = resume;
  RenderResult r = render(job, control);
  REQUIRE(r.nonfinite == 0);
  return r;
}

bool same_sums(const Film& a, const Film& b) {
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      const Film::Pixel &p = a.pixel(x, y), &q = b.pixel(x, y);
      if (p.count != q.count || std::memcmp(p.sum, q.sum, sizeof p.sum) != 0 ||
          std::memcmp(p.sum_sq, q.sum_sq, sizeof p.sum_sq) != 0) {
        return false;
      }
    }
  }
  return true;
}

EmitterEdges edges_of(const Job& job, const PartRegion& region = {}) {
  uint64_t rays = 0;
  EmitterEdges edges(*job.scene, *job.accel, job.render.camera, job.render.width, job.render.height, job.render.seed,
                     job.render.sampler, region, rays);
  CHECK(rays >= static_cast<uint64_t>(job.render.width) * job.render.height);  // and one per small emitter
  return edges;
}

}  // namespace

TEST_CASE("emitter edges: the pixels found are the lamps' edges, not their insides nor the walls") {
  ScenePtr scene = lamp_room();
  Job job = lamp_job(scene, 8, 1, 1, SamplerKind::kSobol);
  EmitterEdges edges = edges_of(job);
  // Each lamp is a few pixels across: its edge and the ring around it, a small part of the image.
  INFO("pixels with views: " << edges.count());
  CHECK(edges.count() >= 8);
  CHECK(edges.count() <= 120);
  // The camera looking at a corner of the floor sees no emitter: no pixel gets views.
  Job away = lamp_job(lamp_room(true), 8, 1, 1, SamplerKind::kSobol);
  CHECK(edges_of(away).count() == 0);
}

TEST_CASE("emitter edges: the same image as without, less variance where an emitter's edge is seen") {
  ScenePtr scene = lamp_room();
  for (SamplerKind sampler : {SamplerKind::kIndependent, SamplerKind::kSobol}) {
    INFO("sampler " << kSamplerNames.name(sampler));
    RenderResult off = render_threads(lamp_job(scene, 0, 512, 1401, sampler), 2);
    Job on_job = lamp_job(scene, 8, 512, 1402, sampler);
    RenderResult on = render_threads(on_job, 2);
    check_films_agree(off.film, on.film, 2, "emitter edges off vs 8 views");
    // Where the views are, the variance of the first hit's emission is most of a pixel's: 8 views
    // divide it by 8 (independent) or more (Sobol blocks).
    EmitterEdges edges = edges_of(on_job);
    double v_off = 0, v_on = 0, v_rest_off = 0, v_rest_on = 0;
    for (int y = 0; y < 32; ++y) {
      for (int x = 0; x < 32; ++x) {
        bool edge = edges.contains(static_cast<uint64_t>(y) * 32 + x);
        (edge ? v_off : v_rest_off) += off.film.variance_of_mean(x, y).y;
        (edge ? v_on : v_rest_on) += on.film.variance_of_mean(x, y).y;
      }
    }
    INFO("summed variance of the mean at the edges: off " << v_off << ", on " << v_on << "; elsewhere " << v_rest_off
                                                          << " vs " << v_rest_on << "; rays " << off.rays << " vs "
                                                          << on.rays);
    CHECK(v_on < 0.25 * v_off);
    // Elsewhere nothing changes but the seed.
    CHECK(v_rest_on < 1.5 * v_rest_off);
    CHECK(v_rest_on > 0.67 * v_rest_off);
    CHECK(on.rays > off.rays);
  }
}

TEST_CASE("emitter edges: direct lighting counts the views too") {
  ScenePtr scene = lamp_room();
  JobOptions o;
  o.integrator = IntegratorKind::kDirect;
  o.spp = 512;
  o.sampler = SamplerKind::kIndependent;
  o.emitter_edges = 0;
  o.seed = 1411;
  RenderResult off = render_threads(make_job(scene, o), 2);
  o.emitter_edges = 8;
  o.seed = 1412;
  RenderResult on = render_threads(make_job(scene, o), 2);
  check_films_agree(off.film, on.film, 2, "direct lighting, emitter edges off vs 8 views");
}

TEST_CASE("emitter edges: the same bits for any thread count, merged region parts and a resumed render") {
  ScenePtr scene = lamp_room();
  Job whole = lamp_job(scene, 8, 16, 1421, SamplerKind::kSobol);
  RenderResult two = render_threads(whole, 2);
  CHECK(same_sums(two.film, render_threads(whole, 1).film));
  // Region parts: the 16x16 tiles of a 32x32 image, the lamps' edges across part borders.
  Film merged(32, 32);
  for (int k = 0; k < 2; ++k)
    merged.merge(render_threads(lamp_job(scene, 8, 16, 1421, SamplerKind::kSobol, std::to_string(k) + "/2"), 2).film);
  CHECK(same_sums(merged, two.film));
  // Resumed from 6 samples per pixel: the views' pixels are found again, the same ones.
  RenderResult first = render_threads(lamp_job(scene, 8, 6, 1421, SamplerKind::kSobol), 2);
  CHECK(same_sums(render_threads(whole, 2, &first.film).film, two.film));
}

TEST_CASE("emitter edges: where the camera sees no emitter the image is the same bits as without") {
  ScenePtr scene = lamp_room(true);
  RenderResult off = render_threads(lamp_job(scene, 0, 8, 1431, SamplerKind::kSobol), 2);
  RenderResult on = render_threads(lamp_job(scene, 8, 8, 1431, SamplerKind::kSobol), 2);
  CHECK(same_sums(off.film, on.film));
}

TEST_CASE("emitter edges auto: on where a surface emits, for direct and path; off otherwise; named when forced") {
  JobOptions o;
  Job job = make_job(lamp_room(), o);
  CHECK(job.render.emitter_edges == kAutoEmitterEdges);
  bool named = false;
  for (const std::string& line : job.sampling_choices) named = named || line.rfind("emitter edges: 8 extra", 0) == 0;
  CHECK(named);
  CHECK(settings_summary(job.settings).find("emitter_edges") == std::string::npos);
  o.integrator = IntegratorKind::kNormals;
  CHECK(make_job(lamp_room(), o).render.emitter_edges == 0);
  o.integrator = IntegratorKind::kDirect;
  o.emitter_edges = 0;
  Job off = make_job(lamp_room(), o);
  CHECK(off.render.emitter_edges == 0);
  CHECK(settings_summary(off.settings).find("emitter_edges=off") != std::string::npos);
  // A scene lit by its sky alone has no emitter to see.
  SceneBuilder b;
  add_quad(b, {-1, 0, -1}, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, add_material(b, diffuse(Spectrum(0.5f))));
  set_view(b, {0, 2, 3}, {0, 0, 0}, 40, 16, 16);
  b.environment = Environment(Spectrum(1.0f));
  CHECK(make_job(finish(std::move(b)), JobOptions{}).render.emitter_edges == 0);
  // The option's words.
  CHECK(parse_emitter_edges("auto") == kEmitterEdgesAuto);
  CHECK(parse_emitter_edges("off") == 0);
  CHECK(parse_emitter_edges("0") == 0);
  CHECK(parse_emitter_edges("64") == 64);
  CHECK_FALSE(parse_emitter_edges("65"));
  CHECK_FALSE(parse_emitter_edges("-1"));
  CHECK_FALSE(parse_emitter_edges("8x"));
}

TEST_CASE("emitter edges: the Cornell box and the hexagonal room converge to the same image with and without") {
  for (const char* name : {"cornell-box", "hex-room"}) {
    CAPTURE(name);
    JobOptions o;
    o.scene_path = std::string(PT_SOURCE_DIR) + "/scenes/" + name;
    o.resolution = "48x48";
    o.sampler = SamplerKind::kIndependent;
    o.integrator = IntegratorKind::kPath;
    o.max_depth = 4;
    o.spp = 256;
    std::shared_ptr<const Scene> scene = load_job_scene(o);
    o.emitter_edges = 0;
    o.seed = 1441;
    Job off_job = make_job(scene, o);
    o.emitter_edges = kEmitterEdgesAuto;
    o.seed = 1442;
    Job on_job = make_job(scene, o);
    REQUIRE(on_job.render.emitter_edges == kAutoEmitterEdges);
    CHECK(edges_of(on_job).count() > 0);  // both see their light
    check_films_agree(render_threads(off_job, 2).film, render_threads(on_job, 2).film, 4,
                      std::string(name) + ": emitter edges off vs auto");
  }
}

TEST_CASE("emitter edges: a lamp smaller than a pixel gets views around it, unless hidden; the same image") {
  ScenePtr scene = tiny_lamp(false);
  Job on_job = lamp_job(scene, 8, 1024, 1452, SamplerKind::kIndependent);
  EmitterEdges edges = edges_of(on_job);
  // The pixels under its box's image and a ring around them: a 3x3 to 4x4 block.
  CHECK(edges.count() >= 9);
  CHECK(edges.count() <= 16);
  CHECK(edges_of(lamp_job(tiny_lamp(true), 8, 1, 1, SamplerKind::kIndependent)).count() == 0);
  RenderResult off = render_threads(lamp_job(scene, 0, 1024, 1451, SamplerKind::kIndependent), 2);
  RenderResult on = render_threads(on_job, 2);
  check_films_agree(off.film, on.film, 4, "a lamp smaller than a pixel: emitter edges off vs 8 views");
  double v_off = 0, v_on = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      if (!edges.contains(static_cast<uint64_t>(y) * 32 + x)) continue;
      v_off += off.film.variance_of_mean(x, y).y;
      v_on += on.film.variance_of_mean(x, y).y;
    }
  }
  INFO("summed variance of the mean around the lamp: off " << v_off << ", on " << v_on);
  CHECK(v_on < 0.25 * v_off);
}
