// Light transport checks: furnaces with known answers for the `path` integrator, BSDF consistency
// (reciprocity, energy, sampling weight vs numerical integral, Fresnel computed independently),
// agreement of the three `direct` strategies, and Russian roulette leaving the mean unchanged.
//
// Tolerances are never tuned to pass. Statistical checks are z-tests whose variance is the film's
// own per-pixel estimate (or the sample variance of the test's own samples); the sigma bound comes
// from a significance level: per-pixel bounds are Šidák-corrected so that the whole family of
// pixels and channels of one check rejects a true hypothesis with probability kFamilyAlpha, and an
// image-wide mean (the sharpest test for a bias) is checked at kMeanSigmas. Deterministic checks use
// float-rounding bounds. Every render uses fixed seeds, so a failure is reproducible, not random.
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

// --- scene building (tests/scene_helpers.h has the rest) ---------------------------------------

Material glossy(float kd, float ks, float exponent) {
  Material m;
  m.model = Glossy{Spectrum(kd), -1, Spectrum(ks), exponent};
  return m;
}

// --- rendering and film checks ----------------------------------------------------------------

using Pixels = std::vector<std::pair<int, int>>;

Pixels all_pixels(const Scene& scene) {
  Pixels out;
  for (int y = 0; y < scene.settings().height; ++y) {
    for (int x = 0; x < scene.settings().width; ++x) out.emplace_back(x, y);
  }
  return out;
}

// Per-pixel z-tests of a film against expected radiance, with the film's variance of the mean; then
// the image-wide mean of the differences against its standard error (pixels are independent).
void check_film_matches(const Film& film, const Pixels& pixels, Spectrum expected, const std::string& what) {
  const double z_pixel = stats::z_bound(stats::sidak(kFamilyAlpha, 3 * static_cast<int>(pixels.size())));
  for (int c = 0; c < 3; ++c) {
    double e = expected[c];
    int failures = 0;
    double worst = 0, sum_diff = 0, sum_var = 0;
    for (auto [x, y] : pixels) {
      double v = film.mean(x, y)[c], var = film.variance_of_mean(x, y)[c];
      double excess = std::abs(v - e) - kRoundoff * std::abs(e);
      double z = excess > 0 ? excess / std::sqrt(std::max(var, 1e-300)) : 0.0;
      worst = std::max(worst, z);
      failures += z > z_pixel;
      sum_diff += v - e;
      sum_var += var;
    }
    double n = static_cast<double>(pixels.size());
    double mean_diff = sum_diff / n, se = std::sqrt(sum_var) / n;
    INFO(what << ", channel " << c << ": expected " << e << ", image mean " << e + mean_diff << " +- " << se
              << " (z = " << mean_diff / std::max(se, 1e-300) << "), worst pixel |z| " << worst << " (bound "
              << z_pixel << ") over " << pixels.size() << " pixels");
    CHECK(failures == 0);
    CHECK(std::abs(mean_diff) <= kMeanSigmas * se + kRoundoff * std::abs(e));
  }
}


double image_mean(const Film& f, int c) {
  double sum = 0;
  for (int y = 0; y < f.height(); ++y) {
    for (int x = 0; x < f.width(); ++x) sum += f.mean(x, y)[c];
  }
  return sum / (double(f.width()) * f.height());
}

// --- scenes -----------------------------------------------------------------------------------

// Three albedo-1 diffuse spheres almost touching each other and a closed albedo-1 box just below
// them, in a constant environment L: every surface sees the others (many bounces in the gaps), and
// every object is closed, so L is the exact answer everywhere.
// `sky_sampling` as RenderSettings::sky_sampling: "light" makes the estimate noisy (MIS between the
// environment as a light and BSDF samples), "auto" leaves the constant sky to BSDF sampling alone.
ScenePtr white_furnace(Spectrum L, const std::string& sky_sampling = "light") {
  SceneBuilder scene;
  scene.settings.choices.sky_sampling = kSkySamplingNames.parse(sky_sampling);
  uint32_t white = add_material(scene, diffuse(Spectrum(1.0f)));
  add_sphere(scene, {0.0f, 0.0f, 0.0f}, 1.0f, white);
  add_sphere(scene, {2.05f, 0.0f, 0.0f}, 1.0f, white);
  add_sphere(scene, {1.0f, 1.75f, 0.0f}, 0.8f, white);
  add_box(scene, {-1.5f, -1.6f, -1.5f}, {3.5f, -1.02f, 1.5f}, white, false);
  scene.environment = Environment(L);
  set_view(scene, {1.0f, 1.2f, 7.0f}, {1.0f, 0.2f, 0.0f}, 50.0f, 24, 24);
  return finish(std::move(scene));
}

// The inside of a closed box whose walls all emit Le (toward the inside) and reflect with albedo
// rho: radiance is the same everywhere, L = Le + rho L, so L = Le / (1 - rho); a path tracer cut at
// max_depth bounces gives the partial sum Le (1 - rho^(d+1)) / (1 - rho).
ScenePtr emissive_box(Spectrum rho, Spectrum Le) {
  SceneBuilder scene;
  uint32_t wall = add_material(scene, diffuse(rho, Le));
  add_box(scene, {-1, -1, -1}, {1, 1, 1}, wall, true);
  set_view(scene, {0.2f, -0.1f, 0.5f}, {-0.3f, 0.2f, -1.0f}, 80.0f, 16, 16);
  return finish(std::move(scene));
}

Spectrum box_radiance(Spectrum rho, Spectrum Le, int max_depth) {
  Spectrum out;
  for (int c = 0; c < 3; ++c) {
    double r = rho[c];
    out[c] = static_cast<float>(Le[c] * (1.0 - std::pow(r, max_depth + 1)) / (1.0 - r));
  }
  return out;
}

// A glossy floor and a sharper glossy sphere, lit by a small bright sphere light and a large dim
// quad light, neither seen directly by the camera (so the image's noise is that of the lighting
// estimators, not of the camera rays' hit-or-miss on a light). Light sampling suits the small light,
// BSDF sampling the large one and the sharp highlights: the strategies have very different noise but
// must share a mean.
ScenePtr two_lights_glossy() {
  SceneBuilder scene;
  uint32_t floor = add_material(scene, glossy(0.2f, 0.7f, 60.0f));
  uint32_t ball = add_material(scene, glossy(0.1f, 0.85f, 200.0f));
  uint32_t small = add_material(scene, diffuse(Spectrum(0.0f), Spectrum(36.0f, 30.0f, 24.0f)));
  uint32_t large = add_material(scene, diffuse(Spectrum(0.0f), Spectrum(0.6f, 0.7f, 0.9f)));
  float s = 3.0f;
  add_quad(scene, {-s, 0, s}, {s, 0, s}, {s, 0, -s}, {-s, 0, -s}, floor);  // faces +y
  add_sphere(scene, {-0.6f, 0.5f, 0.0f}, 0.5f, ball);
  add_sphere(scene, {0.8f, 2.5f, -0.6f}, 0.4f, small);
  float l = 2.5f, h = 4.0f;
  add_quad(scene, {-l, h, -l}, {l, h, -l}, {l, h, l}, {-l, h, l}, large);  // faces -y
  set_view(scene, {0.0f, 3.0f, 3.4f}, {0.0f, 0.2f, -0.2f}, 45.0f, 16, 16);
  return finish(std::move(scene));
}

// True when no camera ray through a pixel corner or centre hits an emitter.
bool lights_out_of_view(const Scene& scene) {
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  int w = scene.settings().width, h = scene.settings().height;
  Camera::Basis basis = scene.camera()->basis(float(w) / h);
  for (int y = 0; y <= 2 * h; ++y) {
    for (int x = 0; x <= 2 * w; ++x) {
      Ray ray = Camera::ray(basis, {0.5f * x / w, 0.5f * y / h});
      ray.tmin = 0;
      ray.tmax = kInf;
      std::optional<Hit> hit = accel->intersect(ray);
      if (hit && scene.materials()[scene.interaction(ray, *hit).material].is_emissive()) return false;
    }
  }
  return true;
}

}  // namespace

// ================================================================================================
// 1. Furnaces
// ================================================================================================

TEST_CASE("white furnace: closed albedo-1 diffuse objects in a constant environment render L everywhere (path)") {
  // With albedo 1 the throughput stays 1, so Russian roulette (on from depth 3) never ends a path;
  // paths end by escaping. max_depth 64 makes the truncated part (paths still trapped after 64
  // bounces between surfaces that each see mostly the environment) negligible; max_depth 4 fails.
  // With the Sobol sampler the film's sample variance overstates the error of the mean (the
  // points are stratified), so the same bounds are conservative there.
  const Spectrum L{1.0f, 0.6f, 0.3f};
  ScenePtr scene = white_furnace(L);
  IntegratorOptions io;
  io.max_depth = 64;
  io.rr_depth = 3;
  for (SamplerKind sampler : {SamplerKind::kIndependent, SamplerKind::kSobol}) {
    std::string sampler_name = sampler == SamplerKind::kSobol ? "sobol" : "independent";
    CAPTURE(sampler_name);
    RenderResult r = render_with(scene, "path", io, 256, 101, sampler);
    // The film's variance must be non-zero on the objects, or the z-tests would test nothing.
    int noisy = 0;
    for (auto [x, y] : all_pixels(*scene)) noisy += r.film.variance_of_mean(x, y).x > 0;
    CHECK(noisy > 200);
    check_film_matches(r.film, all_pixels(*scene), L, "albedo-1 furnace");
  }
  // With the constant sky left to BSDF sampling (the default), every path that escapes carries
  // exactly L and none is cut by Russian roulette at albedo 1: the image is L to rounding.
  ScenePtr exact = white_furnace(L, "auto");
  REQUIRE_FALSE(exact->environment_sampled());
  // Exact only for paths that escape: one path of 64 x 576 trapped for 64 bounces in the gaps
  // (it happens at seed 102) is a whole sample missing, so here the depth is practically unbounded.
  io.max_depth = 1024;
  RenderResult r = render_with(exact, "path", io, 64, 102);
  double worst = 0;
  for (auto [x, y] : all_pixels(*exact))
    for (int c = 0; c < 3; ++c) worst = std::max(worst, double(std::abs(r.film.mean(x, y)[c] - L[c]) / L[c]));
  INFO("largest relative deviation from L: " << worst);
  CHECK(worst < kRoundoff);
}

TEST_CASE("furnace: a convex albedo-0.5 sphere renders 0.5 L with direct and with path") {
  // A convex object never sees itself: one bounce is the whole answer, rho L, for both integrators.
  const Spectrum L{2.0f, 1.0f, 0.5f};
  const float rho = 0.5f;
  SceneBuilder builder;
  add_sphere(builder, {0.1f, -0.2f, 0.0f}, 1.2f, add_material(builder, diffuse(Spectrum(rho))));
  builder.environment = Environment(L);
  set_view(builder, {0.5f, 1.0f, 6.0f}, {0.1f, -0.2f, 0.0f}, 30.0f, 24, 24);
  ScenePtr scene = finish(std::move(builder));
  // Nothing else in the scene can cover these pixels: there is nothing in front of the sphere.
  Pixels on = pixels_on_sphere(*scene, 0, scene->settings().width, scene->settings().height);
  REQUIRE(on.size() > 150);
  IntegratorOptions io;
  io.max_depth = 64;
  io.rr_depth = 3;
  for (std::string integrator : {"direct", "path"}) {
    CAPTURE(integrator);
    RenderResult r = render_with(scene, integrator, io, 256, 202);
    check_film_matches(r.film, on, L * rho, integrator + ", albedo 0.5 sphere");
  }
}

TEST_CASE("furnace: lossless specular objects (mirror ks = 1, glass) next to an albedo-1 sphere render L") {
  // Glass neither absorbs nor emits: the 1/eta^2 radiance scale on entering is undone on leaving,
  // reflection and total internal reflection carry weight 1. So the answer is still L everywhere,
  // including on the diffuse sphere seen through and in the other objects.
  const Spectrum L{0.8f, 1.0f, 1.2f};
  SceneBuilder builder;
  Material mirror;
  mirror.model = Mirror{Spectrum(1.0f)};
  Material glass;
  glass.model = Dielectric{1.5f};
  add_sphere(builder, {-1.1f, 0.0f, 0.0f}, 1.0f, add_material(builder, glass));
  add_sphere(builder, {1.0f, 0.0f, -0.3f}, 1.0f, add_material(builder, mirror));
  add_sphere(builder, {0.0f, 0.3f, -2.3f}, 1.0f, add_material(builder, diffuse(Spectrum(1.0f))));
  builder.environment = Environment(L);
  set_view(builder, {0.0f, 0.8f, 6.0f}, {0.0f, 0.0f, -0.6f}, 45.0f, 24, 24);
  ScenePtr scene = finish(std::move(builder));
  IntegratorOptions io;
  io.max_depth = 64;
  io.rr_depth = 3;
  RenderResult r = render_with(scene, "path", io, 256, 303);
  check_film_matches(r.film, all_pixels(*scene), L, "mirror + glass + white furnace");
}

TEST_CASE("closed emissive box seen from inside: L = Le (1 - rho^(d+1)) / (1 - rho), with and without RR") {
  // The closed box is the furnace seen from inside: nothing escapes, so it needs emission; every
  // bounce adds rho Le. Coloured rho makes Russian roulette (which looks at the largest channel)
  // reweight the other channels by a factor that is not theirs; the mean must still be exact.
  const Spectrum rho{0.8f, 0.5f, 0.2f}, Le{1.0f, 2.0f, 0.5f};
  ScenePtr scene = emissive_box(rho, Le);
  const Pixels pixels = all_pixels(*scene);

  SUBCASE("max_depth 200 with RR: the infinite sum") {
    IntegratorOptions io;
    io.max_depth = 200;  // 0.8^201 < 1e-19: the truncation is invisible
    io.rr_depth = 3;
    RenderResult r = render_with(scene, "path", io, 512, 404);
    check_film_matches(r.film, pixels, box_radiance(rho, Le, 200), "emissive box, RR on, depth 200");
  }
  SUBCASE("max_depth 6, RR off and RR from the first bounce: the same partial sum") {
    IntegratorOptions off;
    off.max_depth = 6;
    off.rr_depth = 0;  // 0 = never (IntegratorOptions)
    IntegratorOptions on = off;
    on.rr_depth = 1;
    RenderResult a = render_with(scene, "path", off, 512, 505);
    RenderResult b = render_with(scene, "path", on, 512, 506);
    Spectrum expected = box_radiance(rho, Le, 6);
    check_film_matches(a.film, pixels, expected, "emissive box, RR off, depth 6");
    check_film_matches(b.film, pixels, expected, "emissive box, RR on, depth 6");
    check_films_agree(a.film, b.film, 1, "emissive box, RR off vs on");
    // Without RR every path in a closed box runs to max_depth; with it most stop early. If the
    // switch did nothing the comparison above would be vacuous.
    INFO("rays: RR off " << a.rays << ", RR on " << b.rays);
    CHECK(double(b.rays) < 0.75 * double(a.rays));
  }
}

// ================================================================================================
// 2. BSDFs
// ================================================================================================

TEST_CASE("direct lighting: light, BSDF and MIS strategies (and path with max_depth 1) agree") {
  ScenePtr scene = two_lights_glossy();
  REQUIRE(lights_out_of_view(*scene));
  const Pixels pixels = all_pixels(*scene);
  struct Run {
    std::string name;
    RenderResult r;
  };
  std::vector<Run> runs;
  uint64_t seed = 700;
  for (Strategy s : {Strategy::kLight, Strategy::kMis, Strategy::kBsdf}) {
    IntegratorOptions io;
    io.strategy = s;
    // Each single strategy has a heavy tail here: BSDF sampling rarely finds the small light, light
    // sampling rarely lands a sample of the large light in the sphere's sharp lobe. They get 4x the
    // samples and are compared on 4x4 blocks (65536 samples each), so that a block holds enough of
    // the rare large values for its mean to be near normal; at 1024 spp single pixels were not.
    int spp = s == Strategy::kMis ? 1024 : 4096;
    runs.push_back({std::string("direct ") + kStrategyNames.name(s), render_with(scene, "direct", io, spp, ++seed)});
  }
  IntegratorOptions one;
  one.max_depth = 1;  // emission + one bounce: the direct-lighting integral, estimated with MIS
  runs.push_back({"path depth 1", render_with(scene, "path", one, 1024, ++seed)});
  for (const Run& run : runs) {
    std::printf("%-14s image mean %.5f %.5f %.5f\n", run.name.c_str(), image_mean(run.r.film, 0),
                image_mean(run.r.film, 1), image_mean(run.r.film, 2));
  }
  // The two MIS estimators (direct and path cut at one bounce) pixel by pixel; every other pair
  // per 4x4 block; every pair for the whole image.
  check_films_agree(runs[1].r.film, runs[3].r.film, 1, runs[1].name + " vs " + runs[3].name);
  for (size_t i = 0; i < runs.size(); ++i) {
    for (size_t j = i + 1; j < runs.size(); ++j) {
      if (i == 1 && j == 3) continue;
      check_films_agree(runs[i].r.film, runs[j].r.film, 4, runs[i].name + " vs " + runs[j].name);
    }
  }

  // The scene must make the strategies differ in noise, or agreement says little: per sample,
  // BSDF sampling is by far the noisiest here, and MIS beats light sampling (measured: about
  // 1800, 430 and 200).
  auto per_sample_var = [&](const Run& run) {
    double v = 0;
    for (auto [x, y] : pixels) v += run.r.film.variance_of_mean(x, y).y * run.r.film.count(x, y);
    return v;
  };
  double v_light = per_sample_var(runs[0]), v_mis = per_sample_var(runs[1]), v_bsdf = per_sample_var(runs[2]);
  std::printf("summed per-sample pixel variance (green): light %.4g, mis %.4g, bsdf %.4g\n", v_light, v_mis, v_bsdf);
  INFO("summed per-sample pixel variance: light " << v_light << ", mis " << v_mis << ", bsdf " << v_bsdf);
  CHECK(v_bsdf > 2 * v_light);
  CHECK(v_mis < v_light);
}

// ================================================================================================
// 4. Russian roulette
// ================================================================================================

TEST_CASE("Russian roulette leaves the mean unchanged: path with RR off and on, glossy two-light scene") {
  // Same max_depth, so both estimate the same truncated sum; RR from the first bounce is its
  // strongest setting. (The closed emissive box above checks RR against a closed form too.)
  ScenePtr scene = two_lights_glossy();
  IntegratorOptions off;
  off.max_depth = 8;
  off.rr_depth = 0;
  IntegratorOptions on = off;
  on.rr_depth = 1;
  RenderResult a = render_with(scene, "path", off, 2048, 801);
  RenderResult b = render_with(scene, "path", on, 2048, 802);
  check_films_agree(a.film, b.film, 1, "path RR off vs RR on");
  INFO("rays: RR off " << a.rays << ", RR on " << b.rays);
  CHECK(b.rays < a.rays);
}

// ================================================================================================
// 5. Sampling strategies chosen per scene (issue 13): Russian roulette placement, light sampling
//    through flat mirrors, the constant sky left to BSDF sampling, adaptive sampling, target error
// ================================================================================================
