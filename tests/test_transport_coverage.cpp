// Partial coverage (MTL d, JSON opacity) against a closed form, for camera, bounce and shadow rays,
// every direct-lighting strategy and the path tracer, on both backends.
//
// A diffuse patch of albedo rho sits at the centre of a black (albedo 0) sphere of coverage c in
// a constant white environment (radiance 1); the camera looks at the patch from outside the
// sphere. Every direction from the patch meets the shell once before the sky, so the patch
// receives (1 - c) and reflects rho (1 - c); the camera ray crosses the shell once on its way in,
// so each pixel on the patch is rho (1 - c)^2 exactly. Light sampling sees the shell only through
// shadow rays, BSDF sampling only through bounce rays: a wrong transmittance on either side biases
// its strategy, and MIS shows it too.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "renderer/render/job.h"
#include "scene_helpers.h"
#include "stats.h"

using namespace pt;
using namespace pt::test;

namespace {

constexpr float kRho = 0.5f;
constexpr float kCoverage = 0.6f;
constexpr int kSize = 16;

std::shared_ptr<const Scene> shell_scene() {
  SceneBuilder scene;
  uint32_t patch = add_material(scene, diffuse(Spectrum(kRho)));
  Material shell = diffuse(Spectrum(0.0f));
  shell.opacity = kCoverage;
  uint32_t black = add_material(scene, shell);
  add_quad(scene, {-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}, patch);
  add_sphere(scene, {0, 0, 0}, 3.0f, black);
  scene.environment = Environment(Spectrum(1.0f));
  scene.settings.choices.sky_sampling = SkySampling::kLight;  // direct lighting's light strategy sees the sky only so
  // The patch (half-width 0.5 at distance 6) fills a 6-degree field of view with room to spare.
  set_view(scene, {0, 0, 6}, {0, 0, 0}, 6.0f, kSize, kSize);
  return finish(std::move(scene));
}

// The image-wide mean against the closed form, at 4 standard errors of the film's own variance.
void check_mean(const RenderResult& r, double expected, const std::string& what) {
  REQUIRE(r.nonfinite == 0);
  double sum = 0, var = 0, n = double(kSize) * kSize;
  for (int y = 0; y < kSize; ++y) {
    for (int x = 0; x < kSize; ++x) {
      sum += r.film.mean(x, y).y;
      var += r.film.variance_of_mean(x, y).y;
    }
  }
  double mean = sum / n, se = std::sqrt(var) / n;
  INFO(what << ": mean " << mean << " +- " << se << ", expected " << expected << " (z = " << (mean - expected) / se << ")");
  CHECK(std::abs(mean - expected) <= 4.0 * se);
  CHECK(se < 0.02 * expected);  // sharp enough to see a shell counted twice or not at all
}

}  // namespace

TEST_CASE("partial coverage: camera, bounce and shadow rays through a shell of coverage c give rho (1 - c)^2") {
  auto scene = shell_scene();
  REQUIRE(scene->has_partial_coverage());
  const double expected = kRho * (1.0 - kCoverage) * (1.0 - kCoverage);
  struct Config {
    const char* integrator;
    const char* strategy;
  } configs[] = {{"direct", "light"}, {"direct", "bsdf"}, {"direct", "mis"}, {"path", "mis"}};
  for (const char* backend : {"embree", "bvh"}) {
    for (const Config& c : configs) {
      std::string what = std::string(backend) + " " + c.integrator + " " + c.strategy;
      CAPTURE(what);
      JobOptions o;
      o.integrator = kIntegratorNames.parse(c.integrator);
      o.strategy = kStrategyNames.parse(c.strategy);
      o.accel.backend = kBackendNames.parse(backend);
      o.spp = 256;
      o.seed = 7;
      o.sampler = SamplerKind::kIndependent;
      RenderControl control;
      control.threads = 2;
      check_mean(render(prepare_job(scene, o), control), expected, what);
    }
  }
}

TEST_CASE("partial coverage: a shadow ray through a sheet carries exactly 1 - c") {
  // A floor lit by a point light straight above, through a black sheet of coverage c halfway up:
  // direct lighting with light sampling is deterministic per sample point, and equals the
  // unshadowed value times (1 - c). A pinhole view straight down, so each pixel's samples see
  // nearly the same point: the ratio of the two renders is (1 - c) in every pixel.
  auto make = [](bool sheet) {
    SceneBuilder scene;
    uint32_t floor = add_material(scene, diffuse(Spectrum(0.8f)));
    add_quad(scene, {-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, floor);
    if (sheet) {
      Material m = diffuse(Spectrum(0.0f));
      m.opacity = kCoverage;
      uint32_t black = add_material(scene, m);
      add_quad(scene, {-5, 1, 5}, {5, 1, 5}, {5, 1, -5}, {-5, 1, -5}, black);
    }
    PointLight light;
    light.position = {0, 2, 0};
    light.intensity = Spectrum(4.0f);
    scene.point_lights.push_back(light);
    set_view(scene, {0, 0.5f, 0}, {0, 0, 0}, 60.0f, 8, 8);
    scene.camera->up = {0, 0, -1};
    return finish(std::move(scene));
  };
  // The camera sits below the sheet, so camera rays never cross it.
  auto light_sampled = [](const std::shared_ptr<const Scene>& scene) {
    JobOptions o;
    o.strategy = Strategy::kLight;
    o.spp = 4;
    return render(prepare_job(scene, o));
  };
  RenderResult open = light_sampled(make(false)), covered = light_sampled(make(true));
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      REQUIRE(open.film.mean(x, y).y > 0);
      CHECK(covered.film.mean(x, y).y / open.film.mean(x, y).y == doctest::Approx(1.0 - kCoverage).epsilon(1e-5));
    }
  }
}
