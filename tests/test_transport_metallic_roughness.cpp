// The metallic-roughness material through the path integrator: white furnaces. Spheres of base
// colour 1, metal and dielectric, at roughness 0.05-1, in a constant environment of radiance 1
// left to BSDF sampling: a pixel is the directional albedo at its view direction, estimated from
// sample() weights alone (and, where the spheres see each other, from paths that bounce between
// them, all of albedo 1). The model reflects 1 at every angle to the tables' interpolation error
// (test_unit_metallic_roughness_energy.cpp), so every pixel must be 1 within 1%.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "core/material/material.h"
#include "film_checks.h"
#include "scene_helpers.h"
#include "sphere_pixels.h"
#include "stats.h"

using namespace pt;
using namespace pt::test;

TEST_CASE("white furnace through the path integrator: metal and dielectric spheres of base colour 1 render 1 within 1%") {
  const float kRoughness[] = {0.05f, 0.2f, 0.5f, 0.8f, 1.0f};
  SceneBuilder builder;
  builder.settings.choices.sky_sampling = kSkySamplingNames.parse("auto");
  for (int row = 0; row < 2; ++row) {
    for (int i = 0; i < 5; ++i) {
      Material m;
      m.model = MetallicRoughness{Spectrum(1.0f), row == 0 ? 1.0f : 0.0f, kRoughness[i]};
      add_sphere(builder, {2.2f * (i - 2), row == 0 ? 1.1f : -1.1f, 0.0f}, 1.0f, add_material(builder, m));
    }
  }
  builder.environment = Environment(Spectrum(1.0f));
  set_view(builder, {0.0f, 0.0f, 16.0f}, {0.0f, 0.0f, 0.0f}, 32.0f, 80, 36);
  ScenePtr scene = finish(std::move(builder));
  REQUIRE_FALSE(scene->environment_sampled());
  IntegratorOptions io;
  io.max_depth = 64;
  io.rr_depth = 3;
  const int spp = 256;
  RenderResult r = render_with(scene, "path", io, spp, 404);
  const int w = scene->settings().width, h = scene->settings().height;
  for (size_t s = 0; s < 10; ++s) {
    auto on = pixels_on_sphere(*scene, s, w, h);
    REQUIRE(on.size() > 30);
    // Every pixel within 1% of 1, beyond its own noise (a Sidak bound over all pixels).
    const double z = stats::z_bound(stats::sidak(kFamilyAlpha, 3 * static_cast<int>(on.size()) * 10));
    double worst = 0, sum = 0, var = 0;
    int failures = 0;
    for (auto [x, y] : on) {
      for (int c = 0; c < 3; ++c) {
        double v = r.film.mean(x, y)[c], sd = std::sqrt(r.film.variance_of_mean(x, y)[c]);
        failures += std::abs(v - 1.0) > 0.01 + z * sd;
        worst = std::max(worst, std::abs(v - 1.0));
        sum += v;
        var += sd * sd;
      }
    }
    const double n = 3.0 * on.size(), mean = sum / n, se = std::sqrt(var) / n;
    INFO(std::string(s < 5 ? "metal" : "dielectric") << ", roughness " << kRoughness[s % 5] << ": sphere mean " << mean
                                                     << " +- " << se << ", worst pixel |mean - 1| " << worst);
    CHECK(failures == 0);
    CHECK(std::abs(mean - 1.0) < 0.01 + kMeanSigmas * se);
  }
}
