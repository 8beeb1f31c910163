// AOVs (renderer/render/aov.h): the first-hit albedo and normal channels are what the albedo and normals
// integrators render, sample for sample; depth is the distance to the first hit; the sample counts
// are the film's; a planted non-finite sample is counted and never reaches the beauty; and asking
// for AOVs leaves the beauty's pixels untouched.
#include <doctest/doctest.h>

#include <cmath>
#include <string>

#include "renderer/render/aov.h"
#include "renderer/render/camera_rays.h"
#include "renderer/render/job.h"
#include "scene_helpers.h"

using namespace pt;
using namespace pt::test;

namespace {

constexpr int kW = 24, kH = 16;

// The camera inside a closed room of two colours, with a textureless sphere of coverage 0.5 in
// front of it (so the first hit depends on the random numbers) and a light: every ray hits.
std::shared_ptr<const Scene> room_scene() {
  SceneBuilder scene;
  uint32_t walls = add_material(scene, diffuse(Spectrum(0.7f, 0.5f, 0.3f)));
  uint32_t floor = add_material(scene, diffuse(Spectrum(0.2f, 0.6f, 0.9f)));
  Material veil = diffuse(Spectrum(0.9f, 0.1f, 0.4f));
  veil.opacity = 0.5f;
  uint32_t half = add_material(scene, veil);
  uint32_t lamp = add_material(scene, diffuse(Spectrum(0.0f), Spectrum(4.0f)));
  add_box(scene, {-2, -1, -3}, {2, 2, 3}, walls, true);
  add_quad(scene, {-2, -0.99f, -3}, {-2, -0.99f, 3}, {2, -0.99f, 3}, {2, -0.99f, -3}, floor);
  add_quad(scene, {-0.5f, 1.98f, -0.5f}, {0.5f, 1.98f, -0.5f}, {0.5f, 1.98f, 0.5f}, {-0.5f, 1.98f, 0.5f}, lamp);
  add_sphere(scene, {0.3f, 0, -1}, 0.6f, half);
  set_view(scene, {0, 0.5f, 2.5f}, {0, 0, -1}, 70.0f, kW, kH);
  return finish(std::move(scene));
}

JobOptions options(const char* integrator, const char* aov) {
  JobOptions o;
  o.integrator = kIntegratorNames.parse(integrator);
  o.spp = 8;
  o.seed = 3;
  if (aov) o.aov = AovSet::parse(aov);
  return o;
}

size_t channel(const Image& image, const std::string& name) {
  for (size_t c = 0; c < image.channels.size(); ++c) {
    if (image.channels[c] == name) return c;
  }
  FAIL("no channel " << name);
  return 0;
}

}  // namespace

TEST_CASE("--aov names: parsed, listed, and refused when unknown") {
  AovSet d;
  CHECK(d.channels() == std::vector<std::string>{"R", "G", "B", "variance.R", "variance.G", "variance.B"});
  CHECK_FALSE(d.first_hit());
  CHECK(AovSet::parse("none").channels() == std::vector<std::string>{"R", "G", "B"});
  CHECK(AovSet::parse("all").channels() ==
        std::vector<std::string>{"R", "G", "B", "variance.R", "variance.G", "variance.B", "albedo.R", "albedo.G", "albedo.B",
                                 "N.X", "N.Y", "N.Z", "depth.Z", "samples", "nonfinite"});
  CHECK(AovSet::parse("samples,nonfinite").channels() == std::vector<std::string>{"R", "G", "B", "samples", "nonfinite"});
  CHECK_FALSE(AovSet::parse("variance,samples,nonfinite").first_hit());
  CHECK(AovSet::parse("depth").first_hit());
  CHECK_THROWS_WITH_AS(AovSet::parse("albedo,normals"), doctest::Contains("unknown AOV 'normals'"), Error);
  CHECK_THROWS_AS(AovSet::parse(""), Error);
  CHECK_THROWS_AS(AovSet::parse("albedo,,depth"), Error);
  CHECK_THROWS_AS(AovSet::parse("albedo,none"), Error);
}

TEST_CASE("first-hit albedo and normals are the albedo and normals integrators' images; the beauty is untouched") {
  auto scene = room_scene();
  REQUIRE(scene->has_partial_coverage());
  Job with = make_job(scene, options("path", "all"));
  REQUIRE(with.render.first_hit);
  RenderResult r = render(with);
  Image image = r.film.to_image(with.aovs);
  RenderResult albedo = render(make_job(scene, options("albedo", nullptr)));
  RenderResult normals = render(make_job(scene, options("normals", nullptr)));
  RenderResult plain = render(make_job(scene, options("path", nullptr)));
  size_t a = channel(image, "albedo.R"), n = channel(image, "N.X"), z = channel(image, "depth.Z");
  size_t s = channel(image, "samples"), bad = channel(image, "nonfinite");
  int differ_albedo = 0, differ_beauty = 0, far_normals = 0, partial = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      Spectrum al = albedo.film.mean(x, y), no = normals.film.mean(x, y), beauty = plain.film.mean(x, y);
      for (int c = 0; c < 3; ++c) {
        // The same surfaces, the same floats, summed in the same order: equal to the bit.
        differ_albedo += image.at(x, y, a + c) != al[c];
        differ_beauty += image.at(x, y, c) != beauty[c];
        // The normals integrator remaps each sample to n / 2 + 1/2 (every ray hits in this room).
        far_normals += std::abs(image.at(x, y, n + c) * 0.5f + 0.5f - no[c]) > 1e-5f;
      }
      Spectrum al0 = albedo.film.mean(x, y);
      partial += al0.x > 0.75f && al0.x < 0.85f;  // a pixel seeing the veil and what lies behind it
      // Depth: inside the room, beyond the sphere's nearest point.
      CHECK(image.at(x, y, z) > 1.0f);
      CHECK(image.at(x, y, z) < 7.0f);
      CHECK(image.at(x, y, s) == 8.0f);
      CHECK(image.at(x, y, bad) == 0.0f);
    }
  }
  CHECK(differ_albedo == 0);
  CHECK(differ_beauty == 0);
  CHECK(far_normals == 0);
  CHECK(r.film.min_count() == 8);
  // The beauty of the AOV render is the plain render's, bit for bit, and so is its variance.
  Image plain_image = plain.film.to_image(true);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      for (int c = 0; c < 6; ++c) CHECK(image.at(x, y, c) == plain_image.at(x, y, c));
    }
  }
  MESSAGE(partial << " pixels mix the veil's albedo with the wall's");
}

TEST_CASE("depth is the distance to the first hit, 0 where every sample escapes; N is 0 there") {
  // A wall facing the camera at distance 4 that covers the left half of the view, nothing else.
  SceneBuilder b;
  uint32_t grey = add_material(b, diffuse(Spectrum(0.5f)));
  add_quad(b, {-10, -10, -4}, {0, -10, -4}, {0, 10, -4}, {-10, 10, -4}, grey);
  b.environment = Environment(Spectrum(1.0f));
  set_view(b, {0, 0, 0}, {0, 0, -1}, 20.0f, 16, 8);
  auto scene = finish(std::move(b));
  JobOptions o = options("direct", "depth,normal,albedo");
  Job job = make_job(scene, o);
  RenderResult r = render(job);
  Image image = r.film.to_image(job.aovs);
  size_t z = channel(image, "depth.Z"), n = channel(image, "N.X"), a = channel(image, "albedo.R");
  // The half-diagonal of a 20-degree view at aspect 2: no ray leaves the axis by more than that.
  const float half_h = std::tan(10.0f * kPi / 180.0f), half_w = 2 * half_h;
  const float farthest = 4.0f * std::sqrt(1 + half_h * half_h + half_w * half_w);
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      CHECK(image.at(x, y, z) >= 4.0f);
      CHECK(image.at(x, y, z) <= farthest);
      CHECK(image.at(x, y, n + 2) == doctest::Approx(1.0f));  // faces +z, toward the camera
      CHECK(image.at(x, y, a) == doctest::Approx(0.5f));
    }
    for (int x = 8; x < 16; ++x) {
      CHECK(image.at(x, y, z) == 0.0f);
      CHECK(image.at(x, y, n + 2) == 0.0f);
      CHECK(image.at(x, y, a) == 0.0f);
    }
  }
}

namespace {
// Returns NaN for camera rays right of x0 (in the camera's units at distance 1) and +inf for rays
// below y0, radiance 1 otherwise: a planted fault whose samples the test can predict exactly.
class FaultyIntegrator final : public Integrator {
 public:
  FaultyIntegrator(float x0, float y0) : x0_(x0), y0_(y0) {}
  static int fault(const Ray& ray, float x0, float y0) {
    if (ray.d.x / -ray.d.z > x0) return 1;
    if (ray.d.y / -ray.d.z < y0) return 2;
    return 0;
  }
  Spectrum Li(const Ray& ray, const Scene&, const Accel&, Sampler&, SampleInfo&) const override {
    switch (fault(ray, x0_, y0_)) {
      case 1: return Spectrum(std::nanf(""));
      case 2: return Spectrum(0.0f, kInf, 0.0f);
      default: return Spectrum(1.0f);
    }
  }

 private:
  float x0_, y0_;
};
}  // namespace

TEST_CASE("a planted NaN or infinite sample is counted in the nonfinite AOV and the beauty stays finite") {
  SceneBuilder b;
  uint32_t grey = add_material(b, diffuse(Spectrum(0.5f)));
  add_quad(b, {-1, -1, -4}, {1, -1, -4}, {1, 1, -4}, {-1, 1, -4}, grey);
  set_view(b, {0, 0, 0}, {0, 0, -1}, 30.0f, 12, 8);
  auto scene = finish(std::move(b));
  JobOptions o = options("direct", "samples,nonfinite");
  o.spp = 16;
  Job job = make_job(scene, o);
  const RenderOptions& ro = job.render;
  // Faults through the middle of column 8 and of row 6, so those pixels mix kept and dropped samples.
  const float half_h = std::tan(15.0f * kPi / 180.0f), half_w = half_h * 12 / 8;
  const float x0 = -half_w + 2 * half_w * 8.5f / 12, y0 = half_h - 2 * half_h * 6.5f / 8;
  FaultyIntegrator faulty(x0, y0);
  RenderResult r = render(*job.scene, *job.accel, faulty, ro);
  Image image = r.film.to_image(job.aovs);
  size_t s = channel(image, "samples"), bad = channel(image, "nonfinite");
  // Predict every sample's fault from its camera ray, made as the renderer makes it.
  const CameraRays camera_rays(ro.camera, ro.width, ro.height, ro.spp, false);
  uint64_t total = 0;
  int mixed = 0;
  for (int y = 0; y < ro.height; ++y) {
    for (int x = 0; x < ro.width; ++x) {
      int faults = 0;
      for (int i = 0; i < ro.spp; ++i) {
        Sampler sampler(ro.sampler, ro.seed, static_cast<uint64_t>(y) * ro.width + x, static_cast<uint32_t>(i));
        Vec2f j = sampler.next2d();
        faults += FaultyIntegrator::fault(camera_rays(x, y, j), x0, y0) != 0;
      }
      CAPTURE(x);
      CAPTURE(y);
      CHECK(image.at(x, y, bad) == static_cast<float>(faults));
      CHECK(image.at(x, y, s) == static_cast<float>(ro.spp - faults));
      for (int c = 0; c < 3; ++c) {
        CHECK(std::isfinite(image.at(x, y, c)));
        // The kept samples are exactly 1; a pixel with none kept is 0, not NaN.
        CHECK(image.at(x, y, c) == (faults < ro.spp ? 1.0f : 0.0f));
      }
      total += faults;
      mixed += faults > 0 && faults < ro.spp;
    }
  }
  CHECK(r.nonfinite == total);
  CHECK(mixed >= 8);  // column 8 and row 6 hold pixels with both
  CHECK(total > 0);
}

TEST_CASE("AOV channels do not depend on the thread count") {
  auto scene = room_scene();
  Job job = make_job(scene, options("path", "all"));
  RenderControl one, two;
  one.threads = 1;
  two.threads = 2;
  one.tile_size = 8;  // other tiles too: a pixel's samples never depend on who renders them
  Image a = render(job, one).film.to_image(job.aovs), b = render(job, two).film.to_image(job.aovs);
  REQUIRE(a.channels == b.channels);
  CHECK(a.pixels == b.pixels);
}
