// Closed-form checks of the spot and directional lights (core/scene/lights/) through the `direct`
// integrator: a diffuse plane lit by one light, one pixel looking straight down at a known point.
// A delta light chosen with certainty has no variance, so the tolerance is float rounding; with
// several lights, the film's own variance of the mean bounds the error.
#include <doctest/doctest.h>

#include <cmath>

#include "core/scene/scene.h"
#include "integrators/integrator.h"
#include "renderer/render/job.h"
#include "scene_helpers.h"

using namespace pt;
using namespace pt::test;

namespace {

constexpr double kRoundoff = 1e-4;
constexpr double kPiD = 3.141592653589793;

// The plane z = 0 (front face +z) of albedo rho, seen by a camera with a very narrow field of view
// looking straight down at `target`; the caller adds the lights.
SceneBuilder plane(float rho, Vec3f target) {
  SceneBuilder scene;
  uint32_t m = add_material(scene, diffuse(Spectrum(rho)));
  float s = 100.0f;
  add_quad(scene, {-s, -s, 0}, {s, -s, 0}, {s, s, 0}, {-s, s, 0}, m);
  set_view(scene, target + Vec3f(0, 0, 6), target, 0.001f, 1, 1);
  scene.camera->up = {0, 1, 0};
  return scene;
}

Spectrum render_pixel(SceneBuilder&& builder, int spp) {
  std::shared_ptr<const Scene> scene = finish(std::move(builder));
  JobOptions o;
  o.integrator = IntegratorKind::kDirect;
  o.strategy = Strategy::kLight;
  o.spp = spp;
  o.seed = 3;
  Job job = prepare_job(scene, o);
  return render(job).film.mean(0, 0);
}

// KHR_lights_punctual's spot falloff, written out here from the extension's text, in double.
double gltf_falloff(double cos_angle, double inner, double outer) {
  double scale = 1.0 / std::max(0.001, std::cos(inner) - std::cos(outer));
  double offset = -std::cos(outer) * scale;
  double t = std::clamp(cos_angle * scale + offset, 0.0, 1.0);
  return t * t;
}

}  // namespace

TEST_CASE("spot light over a diffuse plane: rho/pi I falloff(angle) cos/d^2, black outside the cone") {
  const float rho = 0.5f, intensity = 12.0f, h = 2.0f;
  const double inner = 20 * kPiD / 180, outer = 40 * kPiD / 180;
  int inside = 0, ramp = 0, dark = 0;
  // From the axis out: within the inner cone, on the ramp between the cones, beyond the outer cone.
  for (float r : {0.0f, 0.3f, 0.9f, 1.2f, 1.5f, 1.9f, 3.0f}) {
    SceneBuilder scene = plane(rho, {r * 0.6f, r * 0.8f, 0});
    scene.spot_lights.emplace_back(Vec3f(0, 0, h), Vec3f(0, 0, -3), Spectrum(intensity), static_cast<float>(inner),
                                   static_cast<float>(outer));
    double d2 = double(h) * h + double(r) * r, cos_t = h / std::sqrt(d2);
    double falloff = gltf_falloff(cos_t, inner, outer);
    double expected = rho / kPiD * intensity * falloff * cos_t / d2;
    CAPTURE(r);
    CAPTURE(falloff);
    Spectrum got = render_pixel(std::move(scene), 4);
    if (falloff == 0) {
      CHECK(is_black(got));
      ++dark;
    } else {
      CHECK(got.y == doctest::Approx(expected).epsilon(kRoundoff));
      falloff == 1 ? ++inside : ++ramp;
    }
  }
  // The radii cover all three regions.
  CHECK(inside >= 2);
  CHECK(ramp >= 2);
  CHECK(dark >= 2);
}

TEST_CASE("spot light power: the falloff integrated over the sphere, against quadrature") {
  for (auto [inner_deg, outer_deg] : {std::pair{0.0, 45.0}, {20.0, 40.0}, {0.0, 90.0}, {30.0, 30.02}, {0.0, 0.5}}) {
    const double inner = inner_deg * kPiD / 180, outer = outer_deg * kPiD / 180;
    SpotLight spot({0, 0, 0}, {0, 1, 0}, Spectrum(2.0f), static_cast<float>(inner), static_cast<float>(outer));
    // dw = 2 pi dc over c = cos(angle to the axis), by the midpoint rule.
    const int n = 2000000;
    double sum = 0;
    for (int i = 0; i < n; ++i) {
      double c = -1.0 + 2.0 * (i + 0.5) / n;
      sum += spot.falloff(static_cast<float>(c));
    }
    double expected = 2.0 * kPiD * (2.0 / n) * sum * 2.0;  // luminance of (2, 2, 2) is 2
    CAPTURE(inner_deg);
    CAPTURE(outer_deg);
    CHECK(spot.power() == doctest::Approx(expected).epsilon(2e-3));
  }
}

TEST_CASE("directional light over a diffuse plane: rho/pi E cos, none from below, shadowed by an occluder") {
  const float rho = 0.7f;
  const Spectrum E{3.0f, 2.0f, 1.0f};
  for (float degrees : {0.0f, 30.0f, 75.0f}) {
    float a = degrees * static_cast<float>(kPiD) / 180.0f;
    SceneBuilder scene = plane(rho, {0.3f, -0.2f, 0});
    scene.directional_lights.push_back({normalize(Vec3f(std::sin(a), 0, -std::cos(a))), E});
    CAPTURE(degrees);
    Spectrum got = render_pixel(std::move(scene), 4);
    for (int c = 0; c < 3; ++c) CHECK(got[c] == doctest::Approx(rho / kPiD * E[c] * std::cos(a)).epsilon(kRoundoff));
  }
  // Light travelling upward reaches only the plane's back face, which the camera does not see.
  SceneBuilder below = plane(rho, {0, 0, 0});
  below.directional_lights.push_back({Vec3f(0, 0, 1), E});
  CHECK(is_black(render_pixel(std::move(below), 4)));
  // A small quad high above the target, in the light's path, casts its shadow: a directional
  // light's shadow ray goes on to infinity.
  SceneBuilder shadowed = plane(rho, {0, 0, 0});
  shadowed.directional_lights.push_back({Vec3f(0, 0, -1), E});
  uint32_t m = add_material(shadowed, diffuse(Spectrum(0.5f)));
  add_quad(shadowed, {-0.5f, -0.5f, 50}, {0.5f, -0.5f, 50}, {0.5f, 0.5f, 50}, {-0.5f, 0.5f, 50}, m);
  shadowed.camera->position = {0.0f, 0.1f, 6};  // below the quad, looking at the target past its edge
  CHECK(is_black(render_pixel(std::move(shadowed), 4)));
}

TEST_CASE("point, spot and directional lights together: the light choice is unbiased") {
  // The pixel's value is the sum of each light's closed form; choosing one light per sample by
  // power gives each sample c_i / p_i, so the mean is within a few standard errors of the sum.
  const float rho = 0.6f;
  const Vec3f target{0.4f, 0.1f, 0};
  SceneBuilder scene = plane(rho, target);
  scene.point_lights.push_back({Vec3f(1, 0, 3), Spectrum(20.0f)});
  scene.spot_lights.emplace_back(Vec3f(-1, 0.5f, 2), target - Vec3f(-1, 0.5f, 2), Spectrum(30.0f), 0.1f, 0.4f);
  scene.directional_lights.push_back({normalize(Vec3f(0, 1, -2)), Spectrum(1.5f)});
  auto term = [&](Vec3f light, double intensity) {
    Vec3f d = light - target;
    double d2 = length_squared(d);
    return rho / kPiD * intensity * (d.z / std::sqrt(d2)) / d2;
  };
  double expected = term({1, 0, 3}, 20.0) + term({-1, 0.5f, 2}, 30.0) + rho / kPiD * 1.5 * (2.0 / std::sqrt(5.0));
  std::shared_ptr<const Scene> built = finish(std::move(scene));
  JobOptions o;
  o.integrator = IntegratorKind::kDirect;
  o.strategy = Strategy::kLight;
  o.spp = 4096;
  o.sampler = SamplerKind::kIndependent;
  Job job = prepare_job(built, o);
  RenderResult r = render(job);
  double mean = r.film.mean(0, 0).y, se = std::sqrt(r.film.variance_of_mean(0, 0).y);
  CAPTURE(mean);
  CAPTURE(se);
  CHECK(se > 0);  // three lights: the choice does vary
  CHECK(std::abs(mean - expected) < 5 * se);
}
