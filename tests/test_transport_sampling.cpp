// Light transport checks of the sampling choices: Russian roulette placement, lights sampled
// through flat mirrors and mirror spheres and by solid angle, a constant sky left to BSDF sampling, splitting at the
// first hit, adaptive sampling and --target-error. Each compares two estimators of the same image
// with the z-tests of film_checks.h (see test_transport_paths.cpp for how tolerances are set).
#include <doctest/doctest.h>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>
#include "core/accel/accel.h"
#include "core/geometry/intersect.h"
#include "core/math/rng.h"
#include "core/material/material.h"
#include "core/scene/scene.h"
#include "integrators/integrator.h"
#include "core/scene/loader.h"
#include "renderer/measure/analytic.h"
#include "renderer/measure/converge.h"
#include "renderer/commands/cli_options.h"
#include "renderer/render/job.h"
#include "film_checks.h"
#include "scene_helpers.h"
#include "sphere_pixels.h"
#include "stats.h"
#include "temp_dir.h"

using namespace pt;
using namespace pt::test;

namespace {

// A closed 4 x 3 x 4 room: diffuse walls, the +x wall a flat mirror, a small ceiling light. Light
// reaches the floor and walls through the mirror, which only BSDF sampling finds without mirror
// light sampling.
constexpr const char* kMirrorRoomObj = R"(mtllib room.mtl
v -2 0 -2
v 2 0 -2
v 2 0 2
v -2 0 2
v -2 3 -2
v 2 3 -2
v 2 3 2
v -2 3 2
v -0.4 2.999 -0.4
v 0.4 2.999 -0.4
v 0.4 2.999 0.4
v -0.4 2.999 0.4
usemtl white
f 1 4 3 2
f 5 6 7 8
f 1 2 6 5
f 4 8 7 3
usemtl red
f 1 5 8 4
usemtl mirror
f 2 3 7 6
usemtl light
f 9 10 11 12
)";
constexpr const char* kMirrorRoomMtl = R"(newmtl white
Kd 0.7 0.7 0.7
newmtl red
Kd 0.7 0.2 0.15
newmtl mirror
Kd 0 0 0
Ks 0.9 0.9 0.9
illum 3
newmtl light
Kd 0 0 0
Ke 12 11 10
)";

ScenePtr mirror_room(const TempDir& dir, const std::string& mirror_sampling, const std::string& light_sampling = "auto") {
  dir.write("room.obj", kMirrorRoomObj);
  dir.write("room.mtl", kMirrorRoomMtl);
  std::string json = dir.write("scene.json", R"({
    "camera": {"position": [-1.5, 1.6, 1.8], "look_at": [1, 1, -1], "up": [0, 1, 0], "fov": 70},
    "objects": [{"file": "room.obj"}],
    "render": {"resolution": [32, 32], "integrator": "path", "max_depth": 5}})");
  SceneBuilder b = read_scene(json);
  b.settings.choices.mirror_sampling = kMirrorSamplingNames.parse(mirror_sampling);
  b.settings.choices.light_sampling = kLightSamplingNames.parse(light_sampling);
  return finish(std::move(b));
}

double summed_variance(const Film& f) {
  double v = 0;
  for (int y = 0; y < f.height(); ++y)
    for (int x = 0; x < f.width(); ++x) v += f.variance_of_mean(x, y).y;
  return v;
}

// Renders of a scene with mirror sampling off and on agree (z-tests per 4x4 block), the sampling
// lowers the variance by a fifth at least, and at max depth 2, where x -> mirror -> light is the last
// chain both NEE and BSDF sampling reach, the images still agree: the two strategies' weights sum to
// one. Without mirror sampling the light in the mirror is a rare BSDF hit at that depth: 8x8 blocks
// hold enough of those hits for the normal approximation (see check_films_agree). Seeds seed to
// seed + 3.
void check_mirror_sampling(const ScenePtr& without, const ScenePtr& with, uint64_t seed, const std::string& what) {
  IntegratorOptions io;
  io.max_depth = 5;
  RenderResult a = render_with(without, "path", io, 1024, seed);
  RenderResult b = render_with(with, "path", io, 1024, seed + 1);
  check_films_agree(a.film, b.film, 4, what + " off vs on");
  double va = summed_variance(a.film), vb = summed_variance(b.film);
  INFO("summed variance of the mean (green): off " << va << ", on " << vb);
  CHECK(vb < 0.8 * va);
  io.max_depth = 2;
  check_films_agree(render_with(without, "path", io, 2048, seed + 2).film,
                    render_with(with, "path", io, 2048, seed + 3).film, 8, what + " off vs on, max depth 2");
}

}  // namespace

TEST_CASE("Russian roulette at the next hit, before the bounce, and off estimate the same image") {
  TempDir dir;
  ScenePtr scene = mirror_room(dir, "off");
  IntegratorOptions off;
  off.max_depth = 5;
  off.rr_depth = 0;
  IntegratorOptions next_hit = off, before = off;
  next_hit.rr_depth = before.rr_depth = 1;  // from the first bounce: the strongest setting
  next_hit.rr = RussianRoulette::kNextHit;
  before.rr = RussianRoulette::kBeforeBounce;
  RenderResult a = render_with(scene, "path", off, 1024, 1301);
  RenderResult b = render_with(scene, "path", next_hit, 1024, 1302);
  RenderResult c = render_with(scene, "path", before, 1024, 1303);
  check_films_agree(a.film, b.film, 4, "RR off vs RR at the next hit");
  check_films_agree(a.film, c.film, 4, "RR off vs RR before the bounce");
  INFO("rays: off " << a.rays << ", next hit " << b.rays << ", before bounce " << c.rays);
  CHECK(b.rays < a.rays);
  // Light found only by the bounce ray (here: the light in the mirror) is no longer thrown away
  // before it is seen, so the next-hit placement has the lower variance.
  CHECK(summed_variance(b.film) < summed_variance(c.film));
}

TEST_CASE("--rr auto: at the next hit where some light only a bounce ray finds, before the bounce elsewhere") {
  TempDir dir;
  JobOptions o;
  auto rr_of = [&](const ScenePtr& scene) { return test::make_job(scene, o).integrator_options.rr; };
  // A mirror wall (whatever mirror light sampling does, the light seen in it via a specular bounce
  // is counted at full weight).
  CHECK(rr_of(mirror_room(dir, "off")) == RussianRoulette::kNextHit);
  CHECK(rr_of(mirror_room(dir, "auto")) == RussianRoulette::kNextHit);
  // The same room with a diffuse wall instead: every light a bounce ray can hit is light-sampled.
  std::string mtl = kMirrorRoomMtl;
  for (size_t at; (at = mtl.find("illum 3")) != std::string::npos;) mtl.replace(at, 7, "illum 2");
  TempDir diffuse_dir;
  diffuse_dir.write("room.obj", kMirrorRoomObj);
  diffuse_dir.write("room.mtl", mtl);
  std::string json = diffuse_dir.write("scene.json", R"({"objects": [{"file": "room.obj"}], "render": {"integrator": "path"}})");
  ScenePtr diffuse = finish(read_scene(json));
  REQUIRE(!diffuse->bounce_only_light());
  CHECK(rr_of(diffuse) == RussianRoulette::kBeforeBounce);
  // A constant sky left to BSDF sampling; light-sampled, it is MIS-weighted again.
  dir.write("ground.obj", "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nf 1 2 3 4\n");
  std::string sky = dir.write("sky.json", R"({"objects": [{"file": "ground.obj"}], "environment": {"radiance": 1},
    "render": {"integrator": "path"}})");
  CHECK(rr_of(finish(read_scene(sky))) == RussianRoulette::kNextHit);
  SceneBuilder lit = read_scene(sky);
  lit.settings.choices.sky_sampling = SkySampling::kLight;
  CHECK(rr_of(finish(std::move(lit))) == RussianRoulette::kBeforeBounce);
  // A choice on the command line is kept.
  o.rr = RussianRoulette::kNextHit;
  CHECK(rr_of(diffuse) == RussianRoulette::kNextHit);
}

TEST_CASE("light sampling through a flat mirror: same image as without, lower variance") {
  TempDir dir;
  ScenePtr without = mirror_room(dir, "off");
  ScenePtr with = mirror_room(dir, "auto");
  REQUIRE(without->mirror_planes().empty());
  REQUIRE(with->mirror_planes().size() == 1);  // the mirror's two triangles are one plane
  check_mirror_sampling(without, with, 1311, "mirror light sampling");
}

// The mirror room with a mirror sphere on the floor and a small emitting sphere: the sphere's caustic
// on the floor and walls, of the quad light and of the lamp sphere, is what BSDF sampling alone finds
// by chance.
ScenePtr sphere_room(const TempDir& dir, const std::string& mirror_sampling) {
  dir.write("room.obj", kMirrorRoomObj);
  dir.write("room.mtl", kMirrorRoomMtl);
  std::string json = dir.write("spheres.json", R"({
    "camera": {"position": [-1.6, 1.4, 1.8], "look_at": [0.6, 0.2, -0.6], "up": [0, 1, 0], "fov": 70},
    "materials": {"ball": {"type": "mirror", "specular": 0.95}, "lamp": {"albedo": 0, "emission": [40, 36, 30]}},
    "objects": [{"file": "room.obj"}],
    "spheres": [{"center": [0.6, 0.6, -0.6], "radius": 0.6, "material": "ball"},
                {"center": [-1.2, 2.3, 1.1], "radius": 0.12, "material": "lamp"}],
    "render": {"resolution": [32, 32], "integrator": "path", "max_depth": 5}})");
  SceneBuilder b = read_scene(json);
  b.settings.choices.mirror_sampling = kMirrorSamplingNames.parse(mirror_sampling);
  return finish(std::move(b));
}

TEST_CASE("light sampling through a mirror sphere: same image as without, lower variance") {
  TempDir dir;
  ScenePtr without = sphere_room(dir, "off");
  ScenePtr with = sphere_room(dir, "auto");
  REQUIRE(without->mirror_count() == 0);
  REQUIRE(with->mirror_spheres().size() == 1);  // the lamp sphere is no mirror
  REQUIRE(with->mirror_planes().size() == 1);
  check_mirror_sampling(without, with, 1411, "mirror sampling (plane and sphere)");
}

TEST_CASE("triangle lights by solid angle, by area and auto: the same image; less variance under a near light") {
  TempDir dir;
  IntegratorOptions io;
  io.max_depth = 5;
  RenderResult area = render_with(mirror_room(dir, "off", "area"), "path", io, 512, 1321);
  RenderResult solid = render_with(mirror_room(dir, "off", "solid-angle"), "path", io, 512, 1322);
  RenderResult automatic = render_with(mirror_room(dir, "auto", "auto"), "path", io, 512, 1323);
  check_films_agree(area.film, solid.film, 4, "triangle lights by area vs by solid angle");
  check_films_agree(area.film, automatic.film, 4, "by area (mirror sampling off) vs auto (mirror sampling on)");
  // Direct light from a 2 x 2 emitter 0.25 above a floor, on the floor below it (the camera looks
  // straight down from under the emitter): cos / d^2 varies across the light by a factor of
  // hundreds, which solid-angle sampling does not pay for.
  dir.write("near.mtl", "newmtl floor\nKd 0.7 0.7 0.7\nnewmtl lamp\nKd 0 0 0\nKe 4 4 4\n");
  dir.write("near.obj", "mtllib near.mtl\nv -3 0 -3\nv -3 0 3\nv 3 0 3\nv 3 0 -3\nv -1 0.25 -1\nv 1 0.25 -1\nv 1 0.25 1\nv -1 0.25 1\n"
                        "usemtl floor\nf 1 2 3 4\nusemtl lamp\nf 5 6 7 8\n");
  std::string json = dir.write("near.json", R"({
    "camera": {"position": [0.4, 0.2, 0.3], "look_at": [0.4, 0, 0.3], "up": [0, 0, 1], "fov": 90},
    "objects": [{"file": "near.obj"}],
    "render": {"resolution": [32, 32], "integrator": "path", "max_depth": 1}})");
  auto near_scene = [&](const char* mode) {
    SceneBuilder b = read_scene(json);
    b.settings.choices.light_sampling = kLightSamplingNames.parse(mode);
    return finish(std::move(b));
  };
  // Light samples alone (direct lighting, --strategy light), and MIS with BSDF samples as the path
  // tracer renders: there the BSDF's cosine samples already find much of a near light.
  for (Strategy strategy : {Strategy::kLight, Strategy::kMis}) {
    io.max_depth = 1;
    io.strategy = strategy;
    RenderResult area_r = render_with(near_scene("area"), "direct", io, 256, 1324);
    RenderResult solid_r = render_with(near_scene("solid-angle"), "direct", io, 256, 1325);
    const std::string what = std::string("under a near light, ") + kStrategyNames.name(strategy) + ": by area vs by solid angle";
    check_films_agree(area_r.film, solid_r.film, 4, what);
    double va = summed_variance(area_r.film), vs = summed_variance(solid_r.film);
    INFO(what << ": summed variance of the mean (green) " << va << " vs " << vs);
    CHECK(vs < (strategy == Strategy::kLight ? 0.5 : 0.8) * va);
  }
}

TEST_CASE("a constant sky is left to BSDF sampling: same image as light-sampling it, fewer rays") {
  TempDir dir;
  dir.write("ground.obj", "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nf 1 2 3 4\n");
  std::string json = dir.write("scene.json", R"({
    "camera": {"position": [0, 1.5, 3], "look_at": [0, 0.4, 0], "up": [0, 1, 0], "fov": 50},
    "materials": {"ground": {"albedo": 0.5}, "ball": {"albedo": 0.7}},
    "objects": [{"file": "ground.obj", "material": "ground"}],
    "spheres": [{"center": [0, 0.5, 0], "radius": 0.5, "material": "ball"}],
    "environment": {"radiance": 1},
    "render": {"resolution": [32, 32], "integrator": "path", "max_depth": 6}})");
  ScenePtr bsdf = finish(read_scene(json));
  SceneBuilder lit = read_scene(json);
  lit.settings.choices.sky_sampling = SkySampling::kLight;
  ScenePtr light = finish(std::move(lit));
  CHECK_FALSE(bsdf->environment_sampled());
  CHECK(light->environment_sampled());
  IntegratorOptions io;
  io.max_depth = 6;
  RenderResult a = render_with(bsdf, "path", io, 512, 1321);
  RenderResult b = render_with(light, "path", io, 512, 1322);
  check_films_agree(a.film, b.film, 1, "constant sky: BSDF sampling only vs light sampled");
  INFO("rays: BSDF only " << a.rays << ", light sampled " << b.rays);
  CHECK(a.rays < 0.85 * b.rays);
}

namespace {
// Ground and a ball under a constant sky (the kind of scene --splits auto splits), 32 x 32.
ScenePtr sky_ball(const TempDir& dir, const std::string& extra_objects = "") {
  dir.write("ground.obj", "v -5 0 -5\nv -5 0 5\nv 5 0 5\nv 5 0 -5\nf 1 2 3 4\n");
  std::string json = dir.write("scene.json", R"({
    "camera": {"position": [0, 1.5, 3], "look_at": [0, 0.4, 0], "up": [0, 1, 0], "fov": 50},
    "materials": {"ground": {"albedo": 0.5}, "ball": {"albedo": 0.7}},
    "objects": [{"file": "ground.obj", "material": "ground"})" + extra_objects + R"(],
    "spheres": [{"center": [0, 0.5, 0], "radius": 0.5, "material": "ball"}],
    "environment": {"radiance": 1},
    "render": {"resolution": [32, 32], "integrator": "path", "max_depth": 6}})");
  return finish(read_scene(json));
}
}  // namespace

TEST_CASE("splitting at the first hit: the same image, less variance per camera sample, any thread count") {
  TempDir dir;
  ScenePtr scene = sky_ball(dir);
  IntegratorOptions one;
  one.max_depth = 6;
  IntegratorOptions eight = one;
  eight.splits = 8;
  RenderResult a = render_with(scene, "path", one, 512, 1341);
  RenderResult b = render_with(scene, "path", eight, 512, 1342);
  check_films_agree(a.film, b.film, 1, "no splitting vs 8 continuations per camera sample");
  double va = summed_variance(a.film), vb = summed_variance(b.film);
  INFO("summed variance of the mean: 1 continuation " << va << ", 8 continuations " << vb << "; rays " << a.rays
                                                       << " vs " << b.rays);
  // Under a sky most of the variance is in what the continuations gather: 8 of them at least halve
  // it (the rest is the pixel footprint and the first hit; measured 0.27 of it with roulette on the
  // throughput, 0.30 with its square root).
  CHECK(vb < 0.5 * va);
  CHECK(b.rays > 3 * a.rays);
  // The continuations' Sobol points are blocks of one sequence (Sampler::split): still unbiased.
  check_films_agree(a.film, render_with(scene, "path", eight, 64, 1343, SamplerKind::kSobol).film, 1,
                    "no splitting vs 8 continuations, Sobol");
  // Each continuation's numbers depend only on (seed, pixel, sample, k): not on the thread count.
  JobOptions o;
  o.integrator = IntegratorKind::kPath;
  o.spp = 16;
  o.seed = 1344;
  Job job = test::make_job(scene, o, eight);
  RenderControl control;
  control.threads = 2;
  RenderResult two = render(job, control);
  control.threads = 1;
  RenderResult single = render(job, control);
  bool same = true;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) same = same && two.film.mean(x, y) == single.film.mean(x, y);
  CHECK(same);
}

TEST_CASE("the path integrator carries nothing from one render to the next on the same thread") {
  // PathIntegrator::Li reuses one pair of shading points per thread (path.cpp), trusting
  // make_shading_point to set every field before it is read. So a render gives the same bits before
  // and after another scene (mirrors, an area light, other materials) rendered on the same thread.
  TempDir dir, other_dir;
  ScenePtr scene = sky_ball(dir), other = mirror_room(other_dir, "auto");
  IntegratorOptions io;
  io.max_depth = 6;
  io.splits = 4;
  JobOptions o;
  o.integrator = IntegratorKind::kPath;
  o.spp = 8;
  o.seed = 1345;
  RenderControl control;
  control.threads = 1;
  Job job = test::make_job(scene, o, io);
  RenderResult before = render(job, control);
  RenderResult between = render(test::make_job(other, o, io), control);
  REQUIRE(between.film.min_count() == 8u);
  RenderResult after = render(job, control);
  int differing = 0;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x) differing += before.film.mean(x, y) == after.film.mean(x, y) ? 0 : 1;
  CHECK(differing == 0);
}

TEST_CASE("--splits auto: continuations where a sky alone lights the scene, none where surfaces emit") {
  TempDir dir;
  JobOptions o;
  auto splits_of = [&](const ScenePtr& scene) { return test::make_job(scene, o).integrator_options.splits; };
  CHECK(splits_of(sky_ball(dir)) == kAutoSplits);
  CHECK(splits_of(mirror_room(dir, "auto")) == 1);
  // The same sky with an emitting quad in it: a room-like light, not split.
  dir.write("lamp.obj", "mtllib lamp.mtl\nusemtl lamp\nv -1 2 -1\nv 1 2 -1\nv 1 2 1\nv -1 2 1\nf 1 2 3 4\n");
  dir.write("lamp.mtl", "newmtl lamp\nKd 0 0 0\nKe 5 5 5\n");
  CHECK(splits_of(sky_ball(dir, R"(, {"file": "lamp.obj"})")) == 1);
  // The command line wins, and a bad count is refused naming the option.
  o.splits = parse_splits("3");
  CHECK(splits_of(mirror_room(dir, "auto")) == 3);
  CHECK(parse_splits("auto") == kSplitsAuto);
  CHECK_FALSE(parse_splits("0").has_value());
  CHECK_FALSE(parse_splits("65").has_value());
  CHECK_FALSE(parse_splits("8x").has_value());
}

// The mirror room (32x32, path, depth 5, independent samples) rendered uniformly at `spp` with
// `seed`, and adaptively with the cap `spp`, seed + 1 and `threshold`, on 2 threads.
struct UniformAndAdaptive {
  Job job;  // the adaptive render's
  RenderResult uniform, adaptive;
};
UniformAndAdaptive render_uniform_and_adaptive(const TempDir& dir, int spp, uint64_t seed, double threshold) {
  ScenePtr scene = mirror_room(dir, "auto");
  IntegratorOptions io;
  io.max_depth = 5;
  JobOptions o;
  o.integrator = IntegratorKind::kPath;
  o.spp = spp;
  o.seed = seed;
  o.sampler = SamplerKind::kIndependent;
  RenderControl control;
  control.threads = 2;
  UniformAndAdaptive r;
  r.uniform = render(test::make_job(scene, o, io), control);
  o.seed = seed + 1;
  o.adaptive = true;
  o.adaptive_threshold = threshold;
  r.job = test::make_job(scene, o, io);
  r.adaptive = render(r.job, control);
  return r;
}

TEST_CASE("adaptive sampling: unbiased, fewer samples, the same image for any thread count") {
  TempDir dir;
  auto [job, uniform, adaptive] = render_uniform_and_adaptive(dir, 1024, 1331, 0.03);
  INFO("adaptive: " << adaptive.film.min_count() << " to " << adaptive.film.max_count() << " samples per pixel");
  CHECK(adaptive.film.min_count() < adaptive.film.max_count());
  CHECK(adaptive.film.min_count() >= static_cast<uint32_t>(job.render.adaptive_min_spp));
  check_films_agree(uniform.film, adaptive.film, 4, "uniform vs adaptive sampling");
  RenderControl control;
  control.threads = 1;
  RenderResult one = render(job, control);
  bool same = true;
  for (int y = 0; y < 32; ++y)
    for (int x = 0; x < 32; ++x)
      same = same && one.film.count(x, y) == adaptive.film.count(x, y) && one.film.mean(x, y) == adaptive.film.mean(x, y);
  CHECK(same);
}

TEST_CASE("adaptive sampling gives a pixel samples in proportion to its neighbourhood's deviation") {
  // With a threshold no pixel reaches, only the share rule (renderer/render/render.cpp) decides: pixels
  // whose neighbourhood's samples deviate more must get more samples, and the image must stay the
  // uniform render's within error bars. Stopping at a threshold alone gives every pixel the cap here.
  TempDir dir;
  auto [job, uniform, adaptive] = render_uniform_and_adaptive(dir, 256, 1335, 1e-6);
  // Each pixel's deviation per sample from the uniform render, weighed as the rule weighs it.
  std::vector<std::pair<double, uint32_t>> pixels;
  uint64_t samples = 0;
  for (int y = 0; y < 32; ++y) {
    for (int x = 0; x < 32; ++x) {
      const Spectrum m = uniform.film.mean(x, y), v = uniform.film.variance_of_mean(x, y);
      double u = 0;
      for (int c = 0; c < 3; ++c) u += v[c] * uniform.film.count(x, y) / (std::abs(m[c]) + 1e-2);
      pixels.emplace_back(std::sqrt(u / 3), adaptive.film.count(x, y));
      samples += adaptive.film.count(x, y);
    }
  }
  std::sort(pixels.begin(), pixels.end());
  const size_t quarter = pixels.size() / 4;
  double quiet = 0, noisy = 0;
  for (size_t i = 0; i < quarter; ++i) {
    quiet += pixels[i].second;
    noisy += pixels[pixels.size() - 1 - i].second;
  }
  INFO("mean samples: quietest quarter " << quiet / quarter << ", noisiest quarter " << noisy / quarter << ", all "
                                         << static_cast<double>(samples) / pixels.size());
  // Threshold stopping alone gives both quarters the cap (ratio 1, no sample saved); measured with
  // the share rule: 1.46 and 80% of the cap.
  CHECK(noisy > 1.2 * quiet);
  CHECK(samples < 32u * 32u * 256u * 9 / 10);
  check_films_agree(uniform.film, adaptive.film, 4, "uniform vs adaptive sampling by share");
}

TEST_CASE("target error: the render stops within a factor of 2 of the target, measured against the closed form") {
  JobOptions o;
  o.scene_path = std::string(PT_SOURCE_DIR) + "/scenes/analytic/rect-light";
  Job job = prepare_job(o);
  Image ref = analytic_reference(job);
  for (double target : {0.05, 0.02, 0.01}) {
    for (SamplerKind sampler : {SamplerKind::kSobol, SamplerKind::kIndependent}) {
      job.render.spp = 1 << 16;
      job.render.seed = 1341;
      job.render.sampler = sampler;
      job.render.target_error = target;
      job.render.adaptive = true;
      job.render.adaptive_threshold = target / 2;  // as prepare_job sets it
      RenderResult r = render(job, RenderControl{});
      double truth = std::sqrt(image_error(r.film, ref).rel_mse);
      INFO("target " << target << " " << kSamplerNames.name(sampler) << ": estimated " << r.estimated_error << ", true "
                     << truth << ", " << r.film.min_count() << " to " << r.film.max_count() << " spp");
      CHECK(r.reached_target);
      CHECK(truth <= 2 * target);
      CHECK(truth >= 0.5 * target);
    }
  }
}

namespace {
// A courtyard lit by many lights: 48 small quads on three walls facing in, of powers over two
// decades, a point light, a spot, an emitting sphere and a dim directional light (outside the
// tree), with a box in the middle casting shadows. Rendered with `selection`.
ScenePtr many_lights(const TempDir& dir, LightSelection selection) {
  dir.write("yard.obj",
            "v -4 0 -4\nv -4 0 4\nv 4 0 4\nv 4 0 -4\n"                  // floor
            "v -4 0 -4\nv 4 0 -4\nv 4 4 -4\nv -4 4 -4\n"                // back wall
            "v -1 0 -1\nv 1 0 -1\nv 1 1.5 -1\nv -1 1.5 -1\n"            // the box's front ...
            "v -1 1.5 -1\nv 1 1.5 -1\nv 1 1.5 1\nv -1 1.5 1\n"          // ... and top
            "f 1 2 3 4\nf 5 6 7 8\nf 9 10 11 12\nf 16 15 14 13\n");
  std::string lights;
  Pcg32 rng(29, 3);
  for (int i = 0; i < 48; ++i) {
    int wall = i % 3;  // back (z = -3.95, facing +z), left (x = -3.95, facing +x), right (x = 3.95, facing -x)
    float a = -3.5f + 7.0f * rng.next_float(), y = 0.3f + 3.2f * rng.next_float(), r = 0.2f;
    float level = std::pow(10.0f, 2 * rng.next_float() - 0.5f);
    char corners[256];
    if (wall == 0) {
      std::snprintf(corners, sizeof corners, "[[%g,%g,-3.95],[%g,%g,-3.95],[%g,%g,-3.95],[%g,%g,-3.95]]", a - r, y - r, a + r,
                    y - r, a + r, y + r, a - r, y + r);
    } else if (wall == 1) {
      std::snprintf(corners, sizeof corners, "[[-3.95,%g,%g],[-3.95,%g,%g],[-3.95,%g,%g],[-3.95,%g,%g]]", y - r, a + r, y - r,
                    a - r, y + r, a - r, y + r, a + r);
    } else {
      std::snprintf(corners, sizeof corners, "[[3.95,%g,%g],[3.95,%g,%g],[3.95,%g,%g],[3.95,%g,%g]]", y - r, a - r, y - r,
                    a + r, y + r, a + r, y + r, a - r);
    }
    char light[400];
    std::snprintf(light, sizeof light, R"(, {"type": "quad", "corners": %s, "radiance": [%g, %g, %g]})", corners, level,
                  0.8f * level, 0.6f * level);
    lights += light;
  }
  std::string json = dir.write("scene.json", R"({
    "camera": {"position": [0, 3, 7], "look_at": [0, 0.8, 0], "up": [0, 1, 0], "fov": 60},
    "materials": {"lamp": {"albedo": 0, "emission": [30, 25, 20]}},
    "objects": [{"file": "yard.obj"}],
    "spheres": [{"center": [2.5, 3, 1], "radius": 0.1, "material": "lamp"}],
    "lights": [{"type": "point", "position": [-2, 2.5, 2], "intensity": [3, 3, 3]},
               {"type": "spot", "position": [0, 3.8, 0.5], "direction": [0, -1, -0.3], "intensity": [20, 18, 15],
                "inner_angle": 15, "outer_angle": 30},
               {"type": "directional", "direction": [-1, -2, -1], "irradiance": [0.05, 0.05, 0.08]})" +
                                                lights + R"(],
    "render": {"resolution": [32, 32], "integrator": "path", "max_depth": 3}})");
  SceneBuilder b = read_scene(json);
  b.settings.choices.light_selection = selection;
  return finish(std::move(b));
}
}  // namespace

TEST_CASE("light tree and power selection converge to the same image of many lights") {
  TempDir dir;
  ScenePtr power = many_lights(dir, LightSelection::kPower), tree = many_lights(dir, LightSelection::kTree);
  ScenePtr automatic = many_lights(dir, LightSelection::kAuto);
  CHECK(power->light_set().selection() == LightSelection::kPower);
  CHECK(tree->light_set().selection() == LightSelection::kTree);
  CHECK(automatic->light_set().selection() == LightSelection::kTree);  // 48 quads, a point, a spot, a sphere
  CHECK(tree->light_set().emitters() == 51);
  IntegratorOptions io;
  io.max_depth = 3;
  RenderResult a = render_with(power, "path", io, 512, 1331);
  RenderResult b = render_with(tree, "path", io, 512, 1332);
  check_films_agree(a.film, b.film, 2, "many lights: power vs tree selection");
  // The direct strategies too: light samples alone see the selection's pdf undiluted by BSDF samples.
  io.max_depth = 1;
  io.strategy = Strategy::kLight;
  RenderResult c = render_with(power, "direct", io, 256, 1333);
  RenderResult d = render_with(tree, "direct", io, 256, 1334);
  check_films_agree(c.film, d.film, 2, "many lights, light samples only: power vs tree selection");
}

