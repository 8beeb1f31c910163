// The image depends on (seed, pixel, sample index) only: never on the thread count or the tiling,
// and always on the seed.
#include <doctest/doctest.h>

#include <cstring>

#include "core/accel/accel.h"
#include "core/scene/loader.h"
#include "integrators/integrator.h"
#include "renderer/render/job.h"

using namespace pt;

namespace {

RenderResult render_with(const std::shared_ptr<const Scene>& scene, const std::string& integrator_name,
                         SamplerKind sampler, int threads, uint64_t seed, int tile_size = 16) {
  JobOptions o;
  o.integrator = kIntegratorNames.parse(integrator_name);
  o.shadow_rays = 2;
  o.resolution = "48x40";
  o.spp = 4;
  o.seed = seed;
  o.sampler = sampler;
  RenderControl control;
  control.threads = threads;
  control.tile_size = tile_size;
  return render(prepare_job(scene, o), control);
}

// Bitwise comparison of everything the film stores that reaches the output: mean, variance, count.
bool bit_identical(const Film& a, const Film& b) {
  if (a.width() != b.width() || a.height() != b.height()) return false;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) {
      Spectrum ma = a.mean(x, y), mb = b.mean(x, y);
      Spectrum va = a.variance_of_mean(x, y), vb = b.variance_of_mean(x, y);
      if (std::memcmp(&ma, &mb, sizeof ma) != 0 || std::memcmp(&va, &vb, sizeof va) != 0) return false;
      if (a.count(x, y) != b.count(x, y)) return false;
    }
  }
  return true;
}

int differing_pixels(const Film& a, const Film& b) {
  int n = 0;
  for (int y = 0; y < a.height(); ++y) {
    for (int x = 0; x < a.width(); ++x) n += !(a.mean(x, y) == b.mean(x, y));
  }
  return n;
}

}  // namespace

TEST_CASE("renders are bit-identical for any thread count and tiling, and change with the seed") {
  // The Cornell box (area light, soft shadows) and the sphere scene (spheres, point light,
  // texture, mirror and glass) between them exercise every random decision the direct and path
  // integrators make.
  for (const char* name : {"cornell-box", "spheres"}) {
    auto scene = std::make_shared<const Scene>(read_scene(std::string(PT_SOURCE_DIR) + "/scenes/" + name));
    for (const char* integrator : {"direct", "path"}) {
      for (SamplerKind sampler : {SamplerKind::kSobol, SamplerKind::kIndependent}) {
        CAPTURE(name);
        CAPTURE(integrator);
        CAPTURE(static_cast<int>(sampler));
        RenderResult one = render_with(scene, integrator, sampler, 1, 3);
        RenderResult two = render_with(scene, integrator, sampler, 2, 3);
        RenderResult tiled = render_with(scene, integrator, sampler, 2, 3, 7);
        CHECK(bit_identical(one.film, two.film));
        CHECK(bit_identical(one.film, tiled.film));
        CHECK(one.rays == two.rays);
        RenderResult other_seed = render_with(scene, integrator, sampler, 2, 4);
        CHECK_FALSE(bit_identical(one.film, other_seed.film));
        // Not a handful of pixels: the noise as a whole must move.
        CHECK(differing_pixels(one.film, other_seed.film) > one.film.width() * one.film.height() / 4);
      }
    }
  }
}
