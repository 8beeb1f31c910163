// Rough transmission through the integrators: light reaching a transmissive metallic-roughness
// surface from below it (core/material/rough_dielectric.h). Light samples below the geometric
// surface are taken for a transmissive BSDF (integrators/integrator.cpp, sample_one_light); BSDF
// sampling finds the same light through the refracted lobe. Estimates that use one strategy,
// the other, or both under MIS must agree: a light sampler that refused the light below (as it
// did for every BSDF before) would leave the light-sampled image black where the light shows
// through, and the MIS one darker.
#include <doctest/doctest.h>

#include "core/material/material.h"
#include "film_checks.h"
#include "scene_helpers.h"

using namespace pt;
using namespace pt::test;

namespace {

Material rough_glass(float roughness, float transmission, float metallic, Spectrum base) {
  Material m;
  MetallicRoughness mr;
  mr.base_color = base;
  mr.metallic = metallic;
  mr.roughness = roughness;
  mr.transmission = transmission;
  m.model = mr;
  return m;
}

}  // namespace

TEST_CASE("rough transmission, direct light: a light below a rough glass pane, by light samples, by BSDF samples and by MIS, agree") {
  SceneBuilder builder;
  uint32_t pane = add_material(builder, rough_glass(0.4f, 0.8f, 0.1f, {1.0f, 0.8f, 0.6f}));
  uint32_t lamp = add_material(builder, diffuse(Spectrum(0.0f), Spectrum(4.0f)));
  // The pane at y = 0 facing up, the lamp as large 0.6 below it, facing up too: it lights the pane's
  // underside, which the camera above sees only through the refracted lobe.
  add_quad(builder, {-2, 0, -2}, {-2, 0, 2}, {2, 0, 2}, {2, 0, -2}, pane);
  add_quad(builder, {-2, -0.6f, -2}, {-2, -0.6f, 2}, {2, -0.6f, 2}, {2, -0.6f, -2}, lamp);
  builder.environment = Environment(Spectrum(0.0f));
  set_view(builder, {0.0f, 3.0f, 2.5f}, {0.0f, 0.0f, 0.0f}, 20.0f, 48, 36);
  ScenePtr scene = finish(std::move(builder));
  IntegratorOptions light, bsdf, mis;
  light.strategy = Strategy::kLight;
  bsdf.strategy = Strategy::kBsdf;
  mis.strategy = Strategy::kMis;
  RenderResult a = render_with(scene, "direct", light, 256, 1);
  RenderResult b = render_with(scene, "direct", bsdf, 256, 2);
  RenderResult c = render_with(scene, "direct", mis, 256, 3);
  // The light shows through: the image is not black.
  double sum = 0;
  for (int y = 0; y < a.film.height(); ++y) {
    for (int x = 0; x < a.film.width(); ++x) sum += a.film.mean(x, y)[1];
  }
  CHECK(sum / (a.film.width() * a.film.height()) > 0.05);
  // The lamp spans the view: with a small lamp, pixels that see only the far tail of the lobe
  // (radiance ~1e-5) get a BSDF-sampled hit about once in 1e5 samples, so their squares read
  // variance 0 while light samples see a little (tried: 11 such 4 x 4 squares failed though the
  // image means agreed at z = 0.5).
  check_films_agree(a.film, b.film, 4, "light samples vs BSDF samples");
  check_films_agree(c.film, b.film, 4, "MIS vs BSDF samples");
}

TEST_CASE("rough transmission, paths: rough glass spheres under a constant sky, the sky light-sampled or found by BSDF samples, agree") {
  auto make = [](const char* sky) {
    SceneBuilder builder;
    add_sphere(builder, {-1.2f, 0.0f, 0.0f}, 1.0f, add_material(builder, rough_glass(0.3f, 1.0f, 0.0f, Spectrum(1.0f))));
    add_sphere(builder, {1.2f, 0.0f, 0.0f}, 1.0f, add_material(builder, rough_glass(0.7f, 0.7f, 0.2f, {0.9f, 0.6f, 0.4f})));
    builder.environment = Environment(Spectrum(1.0f));
    builder.settings.choices.sky_sampling = kSkySamplingNames.parse(sky);
    set_view(builder, {0.0f, 0.5f, 7.0f}, {0.0f, 0.0f, 0.0f}, 35.0f, 48, 24);
    return finish(std::move(builder));
  };
  IntegratorOptions io;
  io.max_depth = 32;
  ScenePtr sampled = make("light"), found = make("bsdf");
  CHECK(sampled->environment_sampled());
  CHECK_FALSE(found->environment_sampled());
  RenderResult runs[2] = {render_with(sampled, "path", io, 256, 10), render_with(found, "path", io, 256, 11)};
  check_films_agree(runs[0].film, runs[1].film, 4, "sky light-sampled vs BSDF-sampled");
}
