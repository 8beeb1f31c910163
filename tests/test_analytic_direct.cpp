// Closed-form checks of the `direct` integrator on scenes built in code. Every tolerance is either
// a statistical bound (k standard deviations of the mean, from a per-sample variance known in closed
// form or estimated by the film) or a float-rounding bound for estimators that have no variance.
#include <doctest/doctest.h>

#include <cmath>

#include "core/accel/accel.h"
#include "core/geometry/intersect.h"
#include "core/scene/scene.h"
#include "integrators/integrator.h"
#include "renderer/render/job.h"
#include "scene_helpers.h"
#include "sphere_pixels.h"

using namespace pt;
using namespace pt::test;

namespace {

// A generous bound on float rounding along camera ray -> hit -> shading -> light: estimators with
// no randomness must match the closed form to this relative precision.
constexpr double kRoundoff = 1e-4;
// Standard deviations allowed. With ~10^3 pixels tested per case a 5-sigma bound fails by chance
// with probability ~10^-3 per case (renders are deterministic, so a failure is not intermittent).
constexpr double kSigmas = 5.0;

const SamplerKind kSamplers[] = {SamplerKind::kSobol, SamplerKind::kIndependent};
const char* sampler_name(SamplerKind k) { return k == SamplerKind::kSobol ? "sobol" : "independent"; }

using ScenePtr = std::shared_ptr<const Scene>;

struct Rendered {
  RenderResult result;
  int width, height;
};

Rendered render_scene(const ScenePtr& scene, SamplerKind sampler, int spp, Strategy strategy = Strategy::kMis,
                      int shadow_rays = 1) {
  JobOptions o;
  o.integrator = IntegratorKind::kDirect;
  o.strategy = strategy;
  o.shadow_rays = shadow_rays;
  o.spp = spp;
  o.seed = 7;
  o.sampler = sampler;
  Job job = prepare_job(scene, o);
  return {render(job), job.render.width, job.render.height};
}

// The plane z = 0 (front face +z), albedo rho, a point light of intensity I at (0, 0, h), and a
// camera with a very narrow field of view looking straight down at `target` on the plane, so the
// one pixel sees (to far below float precision) the single point `target`.
ScenePtr plane_under_point_light(float rho, float intensity, float h, Vec3f target, float camera_z = 0) {
  SceneBuilder scene;
  uint32_t m = add_material(scene, diffuse(Spectrum(rho)));
  float s = 100.0f;
  add_quad(scene, {-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}, m);
  PointLight light;
  light.position = {0, 0, h};
  light.intensity = Spectrum(intensity);
  scene.point_lights.push_back(light);
  Camera cam;
  cam.position = target + Vec3f(0, 0, camera_z != 0 ? camera_z : 3 * h);
  cam.look_at = target;
  cam.up = {0, 1, 0};
  cam.vfov_degrees = 0.001f;
  scene.camera = cam;
  scene.settings.width = scene.settings.height = 1;
  return finish(std::move(scene));
}

}  // namespace

TEST_CASE("point light over a diffuse plane: the pixel looking straight down sees rho/pi I/h^2") {
  const float rho = 0.6f, intensity = 25.0f, h = 2.0f;
  ScenePtr scene = plane_under_point_light(rho, intensity, h, {0, 0, 0});
  for (SamplerKind sampler : kSamplers) {
    for (Strategy strategy : {Strategy::kLight, Strategy::kMis}) {
      CAPTURE(sampler_name(sampler));
      CAPTURE(kStrategyNames.name(strategy));
      Rendered r = render_scene(scene, sampler, 16, strategy);
      // A point light is sampled with certainty: the estimator has no variance, only rounding.
      double expected = rho / kPi * intensity / (h * h);
      double got = r.result.film.mean(0, 0).y;
      CHECK(got == doctest::Approx(expected).epsilon(kRoundoff));
      CHECK(r.result.film.count(0, 0) == 16);
    }
  }
}

TEST_CASE("point light over a diffuse plane: off-axis points follow cos(theta)/d^2") {
  // Separates the cosine from the inverse-square law, which the on-axis pixel cannot.
  const float rho = 0.5f, intensity = 10.0f, h = 1.5f;
  for (float r : {0.5f, 1.5f, 4.0f}) {
    ScenePtr scene = plane_under_point_light(rho, intensity, h, {r, 0, 0});
    Rendered out = render_scene(scene, SamplerKind::kSobol, 4, Strategy::kLight);
    double d2 = double(h) * h + double(r) * r;
    double expected = rho / kPi * intensity * (h / std::sqrt(d2)) / d2;
    CAPTURE(r);
    CHECK(out.result.film.mean(0, 0).x == doctest::Approx(expected).epsilon(kRoundoff));
  }
}

TEST_CASE("point light under the plane: the back face is lit (two-sided), the front face is not") {
  const float rho = 0.5f, intensity = 10.0f;
  ScenePtr below = plane_under_point_light(rho, intensity, -1.0f, {0, 0, 0}, -3.0f);
  Rendered r = render_scene(below, SamplerKind::kIndependent, 4, Strategy::kLight);
  CHECK(r.result.film.mean(0, 0).x == doctest::Approx(rho / kPi * intensity).epsilon(kRoundoff));
  // Camera above, light below: no light leaks through the plane.
  ScenePtr through = plane_under_point_light(rho, intensity, -1.0f, {0, 0, 0}, 3.0f);
  r = render_scene(through, SamplerKind::kIndependent, 4, Strategy::kMis);
  CHECK(is_black(r.result.film.mean(0, 0)));
}

TEST_CASE("an emissive quad seen directly has its radiance, and its back face is black") {
  const Spectrum Le{3.0f, 1.5f, 0.25f};
  for (SamplerKind sampler : kSamplers) {
    CAPTURE(sampler_name(sampler));
    for (bool front : {true, false}) {
      CAPTURE(front);
      SceneBuilder builder;
      // Albedo non-zero on purpose: the quad must not light itself.
      uint32_t m = add_material(builder, diffuse(Spectrum(0.5f), Le));
      // Quad in the plane z = 0 spanning [-1, 1]^2, front face +z.
      add_quad(builder, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, m);
      set_view(builder, {0.3f, -0.2f, front ? 4.0f : -4.0f}, {0.1f, 0.1f, 0.0f}, 45.0f, 48, 40);
      ScenePtr scene = finish(std::move(builder));
      Rendered r = render_scene(scene, sampler, 8);

      // Classify each pixel by whether its whole footprint lies on the quad (all four corner rays
      // hit it; the footprint and the quad are convex) or wholly off it.
      Camera::Basis basis = scene->camera()->basis(float(r.width) / r.height);
      auto corner_hits = [&](int x, int y) {
        int hits = 0;
        for (int dy = 0; dy <= 1; ++dy) {
          for (int dx = 0; dx <= 1; ++dx) {
            Ray ray = Camera::ray(basis, {float(x + dx) / r.width, float(y + dy) / r.height});
            float t, u, v;
            bool a = intersect_triangle_mt(ray, {-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, t, u, v);
            bool b = intersect_triangle_mt(ray, {-1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, t, u, v);
            hits += a || b;
          }
        }
        return hits;
      };
      int inside = 0, outside = 0;
      for (int y = 0; y < r.height; ++y) {
        for (int x = 0; x < r.width; ++x) {
          int hits = corner_hits(x, y);
          Spectrum L = r.result.film.mean(x, y);
          if (hits == 4) {
            ++inside;
            Spectrum expected = front ? Le : Spectrum(0.0f);
            for (int c = 0; c < 3; ++c) CHECK(L[c] == doctest::Approx(expected[c]).epsilon(kRoundoff));
          } else if (hits == 0) {
            ++outside;
            CHECK(is_black(L));  // no environment: nothing else to see
          }
        }
      }
      // The framing must leave plenty of pixels of both kinds, or the test proves nothing.
      CHECK(inside > 200);
      CHECK(outside > 100);
    }
  }
}

namespace {

// A diffuse sphere of albedo rho inside a constant environment L, seen whole by the camera.
ScenePtr sphere_in_environment(float rho, Spectrum L) {
  SceneBuilder scene;
  const Vec3f center{0.2f, -0.1f, 0.3f};
  add_sphere(scene, center, 1.3f, add_material(scene, diffuse(Spectrum(rho))));
  scene.environment = Environment(L);
  scene.settings.choices.sky_sampling = SkySampling::kLight;  // these tests are of the environment as a light
  set_view(scene, {1.0f, 2.0f, 6.0f}, center, 30.0f, 40, 36);
  return finish(std::move(scene));
}


}  // namespace

TEST_CASE("diffuse sphere in a constant environment: light sampling gives rho L with the known variance") {
  // Light sampling picks uniform directions on the sphere (pdf 1/4pi); one sample is
  // X = (rho/pi) L cos * 4pi = 4 rho L cos for cos > 0, else 0. So E[X] = rho L and
  // E[X^2] = 16 rho^2 L^2 E[cos^2; cos > 0] = 16/6 rho^2 L^2, var X = (8/3 - 1) rho^2 L^2.
  const float rho = 0.7f;
  const Spectrum L{1.0f, 0.5f, 2.0f};
  ScenePtr scene = sphere_in_environment(rho, L);
  const int spp = 64, shadow_rays = 2;
  for (SamplerKind sampler : kSamplers) {
    CAPTURE(sampler_name(sampler));
    Rendered r = render_scene(scene, sampler, spp, Strategy::kLight, shadow_rays);
    auto pixels = pixels_on_sphere(*scene, 0, r.width, r.height);
    REQUIRE(pixels.size() > 500);
    const double n = double(spp) * shadow_rays;
    for (int c = 0; c < 3; ++c) {
      CAPTURE(c);
      double expected = double(rho) * L[c];
      double sigma = std::sqrt(5.0 / 3.0) * expected / std::sqrt(n);  // of one pixel's mean
      double sum = 0;
      int failures = 0;
      for (auto [x, y] : pixels) {
        double v = r.result.film.mean(x, y)[c];
        sum += v;
        failures += std::abs(v - expected) > kSigmas * sigma;
      }
      CHECK(failures == 0);
      // The average over all pixels is a much sharper test for bias: independent pixels.
      double mean = sum / pixels.size();
      CHECK(std::abs(mean - expected) <= kSigmas * sigma / std::sqrt(double(pixels.size())));
    }
  }
}

TEST_CASE("diffuse sphere in a constant environment: MIS gives rho L within the film's own error bars") {
  const float rho = 0.45f;
  const Spectrum L{2.0f, 2.0f, 0.5f};
  ScenePtr scene = sphere_in_environment(rho, L);
  for (SamplerKind sampler : kSamplers) {
    CAPTURE(sampler_name(sampler));
    Rendered r = render_scene(scene, sampler, 64, Strategy::kMis);
    auto pixels = pixels_on_sphere(*scene, 0, r.width, r.height);
    REQUIRE(pixels.size() > 500);
    for (int c = 0; c < 3; ++c) {
      CAPTURE(c);
      double expected = double(rho) * L[c];
      int failures = 0;
      double sum = 0, sum_var = 0;
      for (auto [x, y] : pixels) {
        double v = r.result.film.mean(x, y)[c];
        double var = r.result.film.variance_of_mean(x, y)[c];
        sum += v;
        sum_var += var;
        // Floor for the (unlikely) all-equal samples case: rounding, not statistics.
        failures += std::abs(v - expected) > kSigmas * std::sqrt(var) + kRoundoff * expected;
      }
      CHECK(failures == 0);
      double mean = sum / pixels.size();
      CHECK(std::abs(mean - expected) <= kSigmas * std::sqrt(sum_var) / pixels.size() + kRoundoff * expected);
      CHECK(sum_var > 0);  // MIS mixes two strategies: the estimate must actually be noisy
    }
  }
}

TEST_CASE("diffuse sphere in a constant environment: BSDF sampling is exact") {
  // Cosine sampling of a Lambertian BSDF has weight rho; every unoccluded sample sees L, so each
  // sample equals rho L: a zero-variance estimator, checked to rounding.
  const float rho = 0.8f;
  const Spectrum L{0.3f, 1.0f, 3.0f};
  ScenePtr scene = sphere_in_environment(rho, L);
  Rendered r = render_scene(scene, SamplerKind::kIndependent, 4, Strategy::kBsdf);
  auto pixels = pixels_on_sphere(*scene, 0, r.width, r.height);
  REQUIRE(pixels.size() > 500);
  for (auto [x, y] : pixels) {
    Spectrum v = r.result.film.mean(x, y);
    for (int c = 0; c < 3; ++c) CHECK(v[c] == doctest::Approx(rho * L[c]).epsilon(kRoundoff));
  }
}
