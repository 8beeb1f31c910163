// Surface textures through the TextureSystem (core/image/texture_cache.h): colour and data
// encodings, filtering in linear light, wrap modes, UV transforms, maketx output, and the footprint
// ray differentials cut out of a surface (core/scene/footprint.h), centred on the sample's stratum.
#include <doctest/doctest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>

#include "core/accel/accel.h"
#include "core/image/coarse_levels.h"
#include "core/image/image.h"
#include "core/image/texture_cache.h"
#include "core/geometry/uv_gradients.h"
#include "core/math/rng.h"
#include "core/scene/camera.h"
#include "core/scene/footprint.h"
#include "core/scene/loader.h"
#include "core/material/texture_binding.h"
#include "core/material/texture_lookup.h"
#include "renderer/render/job.h"
#include "temp_dir.h"

using namespace pt;
namespace fs = std::filesystem;

namespace {

// A w x h image of one value per texel from f(x, y), written as `path` (.png: 8-bit sRGB-encoded, so
// the linear value v is stored as the byte round(255 encode(v)); .exr: float, as given).
template <class F>
std::string write_grey(const TempDir& dir, const std::string& name, int w, int h, F f) {
  Image img(w, h, {"R", "G", "B"});
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = f(x, y, c);
    }
  }
  std::string path = (dir.path / name).string();
  write_image(path, img);
  return path;
}

TextureQuery at(float s, float t, float width = 0.0f) {
  TextureQuery q;
  q.s = s, q.t = t;
  q.dsdx = width, q.dtdy = width;
  return q;
}

}  // namespace

TEST_CASE("textures: an 8-bit colour texture is sRGB-decoded, the same file as data is not") {
  TempDir dir("pt-tex");
  const float byte128 = srgb_decode(128.0f / 255.0f);  // stored as 128
  std::string png = write_grey(dir, "grey.png", 8, 8, [&](int, int, int) { return byte128; });
  std::string exr = write_grey(dir, "grey.exr", 8, 8, [](int, int, int) { return 0.3f; });
  auto cache = make_texture_cache({});
  int colour = cache->add(png, TextureEncoding::kColour);
  int data = cache->add(png, TextureEncoding::kData);
  int linear = cache->add(exr, TextureEncoding::kColour);
  CHECK(colour != data);
  CHECK(cache->add(png, TextureEncoding::kColour) == colour);  // registered once
  CHECK(cache->info(colour).width == 8);
  CHECK(cache->lookup(colour, at(0.5f, 0.5f)).x == doctest::Approx(byte128).epsilon(2e-3));
  CHECK(cache->lookup(data, at(0.5f, 0.5f)).y == doctest::Approx(128.0f / 255.0f).epsilon(1e-4));
  // A float file is linear whatever its role.
  CHECK(cache->lookup(linear, at(0.5f, 0.5f)).z == doctest::Approx(0.3f).epsilon(1e-6));
}

TEST_CASE("textures: MIP levels of a colour texture average in linear light; bilinear mode ignores the footprint") {
  TempDir dir("pt-tex");
  // A checkerboard of single texels, 0 and 1: its average is 0.5 in linear light. Averaging the
  // encoded bytes and decoding would give decode(0.5) = 0.21.
  std::string png = write_grey(dir, "checker.png", 64, 64, [](int x, int y, int) { return float((x + y) % 2); });
  auto mip = make_texture_cache({});
  int id = mip->add(png, TextureEncoding::kColour);
  CHECK(mip->info(id).mip_levels == 1);  // the cache makes the others (automip)
  // A footprint as wide as the texture: the coarsest levels.
  Spectrum far = mip->lookup(id, at(0.5f, 0.5f, 1.0f));
  CHECK(far.x == doctest::Approx(0.5f).epsilon(0.02));
  // At a texel's centre with no footprint: the texel itself.
  CHECK(mip->lookup(id, at(0.5f / 64, 0.5f / 64)).x == doctest::Approx(0.0f));
  CHECK(mip->lookup(id, at(1.5f / 64, 0.5f / 64)).x == doctest::Approx(1.0f).epsilon(1e-3));
  TextureCacheOptions bilinear_options;
  bilinear_options.filter = TextureFilter::kBilinear;
  auto bilinear = make_texture_cache(bilinear_options);
  int b = bilinear->add(png, TextureEncoding::kColour);
  CHECK(bilinear->lookup(b, at(1.5f / 64, 0.5f / 64, 1.0f)).x == doctest::Approx(1.0f).epsilon(1e-3));
  // Between two texel centres, bilinear interpolation in linear light.
  CHECK(bilinear->lookup(b, at(1.0f / 64, 0.5f / 64)).x == doctest::Approx(0.5f).epsilon(1e-3));
}

TEST_CASE("textures: wrap modes outside [0, 1]") {
  TempDir dir("pt-tex");
  // Two columns: 0.25 on the left, 0.75 on the right.
  std::string exr = write_grey(dir, "two.exr", 2, 2, [](int x, int, int) { return x == 0 ? 0.25f : 0.75f; });
  auto cache = make_texture_cache({});
  int id = cache->add(exr, TextureEncoding::kData);
  auto lookup = [&](TextureWrap w, float s) {
    TextureQuery q = at(s, 0.25f);
    q.wrap_s = q.wrap_t = w;
    return cache->lookup(id, q).x;
  };
  // s = 1.25 is the left column's centre repeated, beyond the right edge clamped, the right column
  // mirrored, nothing in black.
  CHECK(lookup(TextureWrap::kRepeat, 1.25f) == doctest::Approx(0.25f));
  CHECK(lookup(TextureWrap::kClamp, 1.25f) == doctest::Approx(0.75f));
  CHECK(lookup(TextureWrap::kMirror, 1.25f) == doctest::Approx(0.75f));
  CHECK(lookup(TextureWrap::kBlack, 1.25f) == doctest::Approx(0.0f));
  CHECK(lookup(TextureWrap::kRepeat, -0.75f) == doctest::Approx(0.25f));
  CHECK(lookup(TextureWrap::kMirror, -0.25f) == doctest::Approx(0.25f));
}

TEST_CASE("textures: KHR_texture_transform is translation * rotation * scale") {
  UvTransform t;
  t.offset = {0.5f, 0.25f};
  t.rotation = kPi / 2;
  t.scale = {2.0f, 3.0f};
  // The extension's matrix: [[c sx, s sy, ox], [-s sx, c sy, oy]] with c = cos r, s = sin r.
  Vec2f a = t.apply({1.0f, 0.0f});
  CHECK(a.x == doctest::Approx(0.5f).epsilon(1e-6));
  CHECK(a.y == doctest::Approx(0.25f - 2.0f));
  Vec2f b = t.apply({0.0f, 1.0f});
  CHECK(b.x == doctest::Approx(0.5f + 3.0f));
  CHECK(b.y == doctest::Approx(0.25f).epsilon(1e-6));
  CHECK(UvTransform{}.is_identity());
}

TEST_CASE("textures: maketx output is read as it is, MIP levels and all") {
  TempDir dir("pt-tex");
  std::string png = write_grey(dir, "ramp.png", 64, 64, [](int x, int, int) { return x / 63.0f; });
  std::string tx = (dir.path / "ramp.tx").string();
  std::string command = "maketx -o '" + tx + "' '" + png + "' >/dev/null 2>&1";
  REQUIRE(std::system(command.c_str()) == 0);
  auto cache = make_texture_cache({});
  int id = cache->add(tx, TextureEncoding::kData);
  CHECK(cache->info(id).mip_levels == 7);  // 64, 32, ..., 1
  CHECK(cache->info(id).width == 64);
  // The finest level holds the file's bytes.
  CHECK(cache->lookup(id, at(10.5f / 64, 0.5f)).x ==
        doctest::Approx(std::round(255.0f * srgb_encode(10.0f / 63.0f)) / 255.0f).epsilon(1e-3));
}

TEST_CASE("textures: the footprint of ray differentials on a plane is the pixel's size there") {
  // A ray straight down from height h onto the plane y = 0, whose uv are x and -z: the neighbouring
  // ray one pixel over (an angle delta) meets the plane h * delta away.
  const float h = 4.0f, delta = 0.01f;
  Ray ray;
  ray.o = {0, h, 0};
  ray.d = {0, -1, 0};
  ray.diff.dddx = {delta, 0, 0};
  ray.diff.dddy = {0, 0, delta};
  ray.diff.scale = 1.0f;
  SurfaceInteraction si;
  si.p = {0, 0, 0};
  si.ng = si.ns = {0, 1, 0};
  const UvGradients uv{{1, 0, 0}, {0, 0, -1}};
  compute_footprint(ray, si, &uv);
  CHECK(si.duvdx.x == doctest::Approx(h * delta));
  CHECK(si.duvdx.y == doctest::Approx(0.0f));
  CHECK(si.duvdy.y == doctest::Approx(-h * delta));
  // Seen at 60 degrees from the normal from distance h, the footprint along the view is
  // foreshortened: exactly h delta / (cos - sin delta) for a neighbour at angle delta inside the plane
  // of incidence; across it, h delta.
  const float c = 0.5f, s = std::sqrt(1 - c * c);
  ray.o = Vec3f(-s, c, 0) * h;
  ray.d = {s, -c, 0};
  ray.diff.dddx = Vec3f(c, s, 0) * delta;  // in the plane of incidence
  ray.diff.dddy = {0, 0, delta};
  compute_footprint(ray, si, &uv);
  CHECK(si.duvdx.x == doctest::Approx(h * delta / (c - s * delta)).epsilon(1e-3));
  CHECK(std::abs(si.duvdy.y) == doctest::Approx(h * delta).epsilon(1e-3));
  // No differentials: no footprint.
  ray.diff = {};
  compute_footprint(ray, si, &uv);
  CHECK(si.duvdx.x == 0.0f);
  CHECK(si.duvdy.y == 0.0f);
}

TEST_CASE("textures: a triangle's uv gradients give its corners' uv differences along it, none across") {
  Pcg32 rng(17, 3);
  auto rnd = [&] { return 4.0f * rng.next_float() - 2.0f; };
  for (int k = 0; k < 1000; ++k) {
    const Vec3f p0{rnd(), rnd(), rnd()}, p1{rnd(), rnd(), rnd()}, p2{rnd(), rnd(), rnd()};
    const Vec2f uv0{rnd(), rnd()}, uv1{rnd(), rnd()}, uv2{rnd(), rnd()};
    const Vec3f n = cross(p1 - p0, p2 - p0);
    if (length(n) < 0.05f) continue;  // ill-conditioned: float corners, double gradients
    const UvGradients g = triangle_uv_gradients(p0, p1, p2, uv0, uv1, uv2);
    const float scale = 1e-4f * (1.0f + length(Vec3f(uv0.x, uv1.x, uv2.x)) + length(Vec3f(uv0.y, uv1.y, uv2.y))) / std::min(1.0f, length(n));
    CHECK(std::abs(dot(g.u, p1 - p0) - (uv1.x - uv0.x)) < scale);
    CHECK(std::abs(dot(g.u, p2 - p0) - (uv2.x - uv0.x)) < scale);
    CHECK(std::abs(dot(g.v, p1 - p0) - (uv1.y - uv0.y)) < scale);
    CHECK(std::abs(dot(g.v, p2 - p0) - (uv2.y - uv0.y)) < scale);
    CHECK(std::abs(dot(g.u, n)) < scale * length(n));
    CHECK(std::abs(dot(g.v, n)) < scale * length(n));
  }
  // A uv map flat in v keeps u's gradient; a triangle flat in space has none.
  const UvGradients flat_v = triangle_uv_gradients({0, 0, 0}, {2, 0, 0}, {0, 0, 4}, {0, 5}, {1, 5}, {0.5f, 5});
  CHECK(flat_v.u.x == doctest::Approx(0.5f));
  CHECK(flat_v.u.z == doctest::Approx(0.125f));
  CHECK(length(flat_v.v) == 0.0f);
  const UvGradients none = triangle_uv_gradients({0, 0, 0}, {1, 1, 1}, {2, 2, 2}, {0, 0}, {1, 0}, {0, 1});
  CHECK(length(none.u) + length(none.v) == 0.0f);
}

TEST_CASE("textures: the uv footprint on an instanced mesh is its baked copy's") {
  // A textured quad placed twice (so kept as instances: stretched, rotated, one mirrored) and the
  // same two placements as plain objects (baked into the world mesh). The instance's uv gradients are
  // taken to the world by the inverse's transpose; the baked triangles' are made in the world.
  TempDir dir("pt-tex-instances");
  write_grey(dir, "checker.exr", 8, 8, [](int x, int y, int) { return float((x + y) % 2); });
  dir.write("quad.obj", "v -1 0 1\nv 1 0 1\nv 1 0 -1\nv -1 0 -1\nvt 0 0\nvt 3 0\nvt 3 2\nvt 0.5 2\nf 1/1 2/2 3/3 4/4\n");
  const std::string a = R"("scale": [2, 1, 0.5], "rotate": [20, 35, 10], "translate": [-3, 0, 0])";
  const std::string b = R"("scale": [-1, 1, 1.5], "rotate": [-15, 80, 5], "translate": [3, 0.5, 0])";
  const std::string materials = R"("materials": {"tex": {"texture": "checker.exr"}}, "environment": {"radiance": 1})";
  Scene inst = load_scene(dir.write("inst.json", R"({"objects": [{"file": "quad.obj", "material": "tex", "instances": [{)" + a +
                                                      "}, {" + b + "}]}], " + materials + "}"));
  Scene flat = load_scene(dir.write("flat.json", R"({"objects": [{"file": "quad.obj", "material": "tex", )" + a +
                                                      R"(}, {"file": "quad.obj", "material": "tex", )" + b + "}], " + materials + "}"));
  REQUIRE(inst.geometry().instances().size() == 2);
  REQUIRE(flat.geometry().instances().empty());
  auto ai = make_accel(inst.geometry(), AccelOptions{});
  auto af = make_accel(flat.geometry(), AccelOptions{});
  Pcg32 rng(5, 5);
  int compared = 0;
  for (int k = 0; k < 400; ++k) {
    Ray ray;
    ray.o = {0, 6, 6};
    ray.d = normalize(Vec3f(8 * rng.next_float() - 4, -6, 2 * rng.next_float() - 7));
    ray.diff.dodx = {0.002f, 0, 0};
    ray.diff.dddx = {0.003f, 0.001f, 0};
    ray.diff.dddy = {0, 0.002f, -0.004f};
    ray.diff.scale = 1.0f;
    ray.diff.centre = {0.3f, -0.2f};
    auto hi = ai->intersect(ray), hf = af->intersect(ray);
    REQUIRE(bool(hi) == bool(hf));
    if (!hi) continue;
    REQUIRE(hi->inst != kNoInstance);
    const SurfaceInteraction si = inst.interaction(ray, *hi), sf = flat.interaction(ray, *hf);
    ++compared;
    const float size = std::abs(sf.duvdx.x) + std::abs(sf.duvdx.y) + std::abs(sf.duvdy.x) + std::abs(sf.duvdy.y);
    REQUIRE(size > 0.0f);
    CHECK(std::abs(si.duvdx.x - sf.duvdx.x) < 1e-4f * size);
    CHECK(std::abs(si.duvdx.y - sf.duvdx.y) < 1e-4f * size);
    CHECK(std::abs(si.duvdy.x - sf.duvdy.x) < 1e-4f * size);
    CHECK(std::abs(si.duvdy.y - sf.duvdy.y) < 1e-4f * size);
    CHECK(std::abs(si.duv_centre.x - sf.duv_centre.x) < 1e-4f * size);
    CHECK(std::abs(si.duv_centre.y - sf.duv_centre.y) < 1e-4f * size);
    // and the footprint is uv's change to the neighbouring ray's hit: its uv, less this one's.
    Ray next = ray;
    next.o = ray.o + ray.diff.dodx;
    next.d = ray.d + ray.diff.dddx;
    next.diff = {};
    auto hn = af->intersect(next);
    if (!hn || hn->prim != hf->prim) continue;
    const SurfaceInteraction sn = flat.interaction(next, *hn);
    CHECK(std::abs(sn.uv.x - sf.uv.x - sf.duvdx.x) < 1e-3f * size);
    CHECK(std::abs(sn.uv.y - sf.uv.y - sf.duvdx.y) < 1e-3f * size);
  }
  CHECK(compared > 100);
}

TEST_CASE("textures: a camera footprint is one stratum of the pixel, centred on the sample's") {
  // The finest square grid 2^k samples stratify: 2^floor(k/2) a side, at most 8.
  const int spp[] = {1, 2, 3, 4, 8, 15, 16, 32, 64, 100, 4096};
  const int strata[] = {1, 1, 1, 2, 2, 2, 4, 4, 8, 8, 8};
  for (int i = 0; i < 11; ++i) CHECK(Camera::footprint_strata(spp[i]) == strata[i]);
  // From the sample to its cell's centre, in cells.
  Vec2f c = Camera::stratum_centre({0.1f, 0.8f}, 2);
  CHECK(c.x == doctest::Approx(0.3f));   // cell 0: centre 0.5, sample at 0.2 cells
  CHECK(c.y == doctest::Approx(-0.1f));  // cell 1: centre 1.5, sample at 1.6
  c = Camera::stratum_centre({0.999999f, 0.0f}, 8);
  CHECK(c.x == doctest::Approx(-0.5f).epsilon(1e-4));
  CHECK(c.y == doctest::Approx(0.5f));
  CHECK(Camera::stratum_centre({0.3f, 0.9f}, 1).x == doctest::Approx(0.2f));

  // The centre's uv on a plane seen at 60 degrees from its normal: where the ray through the
  // centre (between the ray and its neighbours) meets the plane, not a linear step from the hit.
  const float h = 4.0f, delta = 0.05f, cos_a = 0.5f, sin_a = std::sqrt(1 - cos_a * cos_a);
  Ray ray;
  ray.o = Vec3f(-sin_a, cos_a, 0) * h;
  ray.d = {sin_a, -cos_a, 0};
  ray.diff.dddx = Vec3f(cos_a, sin_a, 0) * delta;  // in the plane of incidence
  ray.diff.dddy = {0, 0, delta};
  ray.diff.scale = 0.5f;
  ray.diff.centre = {-0.5f, 0.25f};
  SurfaceInteraction si;
  si.ng = si.ns = {0, 1, 0};
  const UvGradients uv{{1, 0, 0}, {0, 0, -1}};
  compute_footprint(ray, si, &uv);
  const Vec3f d = ray.d + ray.diff.dddx * -0.5f + ray.diff.dddy * 0.25f;
  const Vec3f p = ray.o + d * (ray.o.y / -d.y);
  CHECK(si.duv_centre.x == doctest::Approx(p.x).epsilon(1e-4));
  CHECK(si.duv_centre.y == doctest::Approx(-p.z).epsilon(1e-4));
  CHECK(si.duv_centre.x != doctest::Approx(-0.5f * si.duvdx.x).epsilon(0.01));  // not linearised
}

TEST_CASE("textures: a checkerboard to the horizon at 4 spp is 3x closer to the pixel means than bilinear lookups") {
  // scenes/horizon at 96x54 (docs/textures.md measures it at 384x216): the reference is the box
  // mean of each pixel, as bilinear point lookups at 1024 spp estimate it (nobody's filter). At 4
  // spp, each sample's lookup filtered over its stratum brings the error down 3x or more (6.7x
  // here when this was written: 0.0104 against 0.0698); bilinear lookups are noise.
  auto rendered = [&](TextureFilter filter, int spp, uint64_t seed) {
    JobOptions o;
    o.scene_path = std::string(PT_SOURCE_DIR) + "/scenes/horizon";
    o.view.textures.filter = filter;
    o.spp = spp;
    o.seed = seed;
    o.splits = 1;
    auto s = load_job_scene(o);
    return render(prepare_job(s, o)).film;
  };
  const Film reference = rendered(TextureFilter::kBilinear, 1024, 99);
  auto rmse = [&](const Film& f) {
    double sum = 0;
    for (int y = 0; y < f.height(); ++y) {
      for (int x = 0; x < f.width(); ++x) {
        const double e = double(f.mean(x, y).x) - reference.mean(x, y).x;
        sum += e * e;
      }
    }
    return std::sqrt(sum / (f.width() * f.height()));
  };
  const double bilinear = rmse(rendered(TextureFilter::kBilinear, 4, 1));
  const double mipmap = rmse(rendered(TextureFilter::kMipmap, 4, 1));
  CAPTURE(bilinear);
  CAPTURE(mipmap);
  CHECK(bilinear > 0.03);  // the reference is not the bilinear render itself
  CHECK(mipmap * 3 < bilinear);
}

TEST_CASE("textures: a bounce widens the footprint by its lobe, a specular one does not") {
  RayDifferential camera;
  camera.dddx = {0.001f, 0, 0};
  camera.dddy = {0, 0.001f, 0};
  camera.scale = 0.5f;
  SurfaceInteraction si;
  si.dpdx = {0.01f, 0, 0};
  si.dpdy = {0, 0, 0.01f};
  // The bounce ray along +y, its direction differentials made as a hit would make them.
  auto bounced = [&](const RayDifferential& in, float pdf) {
    Ray r{{0, 0, 0}, {0, 1, 0}};
    r.diff = bounce_differential(in, si, pdf);
    make_direction_differentials(r);
    return r.diff;
  };
  RayDifferential mirror = bounced(camera, 0.0f);
  CHECK(length(mirror.dddx) == doctest::Approx(0.001f));
  CHECK(length(mirror.dddy) == doctest::Approx(0.001f));
  CHECK(mirror.dodx.x == doctest::Approx(0.01f));
  CHECK_FALSE(mirror.rough);
  RayDifferential diffuse = bounced(camera, kInvPi);
  CHECK(length(diffuse.dddx) == doctest::Approx(0.001f + 0.5f));  // scale * min(1, sqrt(1 / (pi pdf)))
  CHECK(diffuse.rough);
  RayDifferential glossy = bounced(camera, 100.0f);
  CHECK(length(glossy.dddx) == doctest::Approx(0.001f + 0.5f * std::sqrt(1.0f / (kPi * 100.0f))));
  CHECK(dot(glossy.dddx, Vec3f(0, 1, 0)) == doctest::Approx(0.0f));  // across the new ray
  CHECK(dot(glossy.dddy, Vec3f(0, 1, 0)) == doctest::Approx(0.0f));
  CHECK(dot(glossy.dddx, glossy.dddy) == doctest::Approx(0.0f));
  // A second bounce widens the deferred spread as it would the made one.
  RayDifferential twice = bounced(bounce_differential(camera, si, kInvPi), kInvPi);
  CHECK(length(twice.dddx) == doctest::Approx(0.001f + 0.5f + 0.5f));
  // Made in place once: spread cleared, so making them again changes nothing.
  Ray r{{0, 0, 0}, {0, 1, 0}};
  r.diff = bounce_differential(camera, si, kInvPi);
  CHECK(r.diff.spread > 0.0f);
  make_direction_differentials(r);
  CHECK(r.diff.spread == 0.0f);
  const Vec3f made = r.diff.dddx;
  make_direction_differentials(r);
  CHECK(r.diff.dddx.x == made.x);
}

TEST_CASE("textures: held levels are the box-filtered means of level 0, down to 1x1") {
  // A 6x3 texture (odd sizes) of known values, 1 channel: level 1 is 3x1, level 2 1x1.
  std::vector<float> rows(18);
  for (int i = 0; i < 18; ++i) rows[i] = static_cast<float>(i);
  LevelBuilder all(6, 3, 1, 1 << 20);
  all.add_rows(0, 2, rows.data());
  all.add_rows(2, 1, rows.data() + 12);
  CoarseLevels held = all.finish();
  REQUIRE(held.first() == 0);
  REQUIRE(held.levels().size() == 3);
  CHECK(held.levels()[1].width == 3);
  CHECK(held.levels()[1].height == 1);
  // Level 1's texel 0 covers level-0 rows 0-1 (pairs) and, the last row having no pair, row 2 too.
  const auto& l1 = held.levels()[1].texels;
  CHECK(l1[0] == doctest::Approx((0 + 1 + 6 + 7 + 12 + 13) / 6.0f));
  // A grey texture's alphas are all 1: RGB alone, and a float of 1 after the last texel.
  CHECK(held.levels()[1].stride == 3);
  CHECK(l1.size() == 3 * 3 + 1);
  CHECK(l1.back() == 1.0f);
  CHECK(held.levels()[2].texels[0] == doctest::Approx(8.5f));  // the mean of all
  // With a budget of 2 texels the first held level is level 2 (1x1), made from level 0 directly.
  LevelBuilder coarse(6, 3, 1, 2);
  coarse.add_rows(0, 3, rows.data());
  CoarseLevels c = coarse.finish();
  CHECK(c.first() == 2);
  CHECK(c.levels()[0].texels[0] == doctest::Approx(8.5f));
}

TEST_CASE("textures: a large first held level is summed in place, the last column and row taking what is left") {
  // 2049 x 1031 held from level 1 (1024 x 515, more than the first pass holds): each texel the mean
  // of 2 x 2 level-0 texels, the last column of 3 x 2, the last row of 2 x 3, the corner of 3 x 3.
  const int w = 2049, h = 1031;
  auto value = [](int x, int y) { return static_cast<float>((x * 7 + y * 13) % 101) / 100.0f; };
  std::vector<float> row(w);
  LevelBuilder builder(w, h, 1, size_t(1024) * 515);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) row[x] = value(x, y);
    builder.add_rows(y, 1, row.data());
  }
  CoarseLevels held = builder.finish();
  REQUIRE(held.first() == 1);
  const auto& top = held.levels()[0];
  REQUIRE(top.width == 1024);
  REQUIRE(top.height == 515);
  auto mean = [&](int tx, int ty) {
    int x1 = tx == 1023 ? w : 2 * tx + 2, y1 = ty == 514 ? h : 2 * ty + 2;
    double sum = 0;
    int n = 0;
    for (int y = 2 * ty; y < y1; ++y) {
      for (int x = 2 * tx; x < x1; ++x) sum += value(x, y), ++n;
    }
    return sum / n;
  };
  for (auto [tx, ty] : {std::pair{0, 0}, {517, 300}, {1023, 10}, {40, 514}, {1023, 514}}) {
    CAPTURE(tx);
    CAPTURE(ty);
    const size_t i = static_cast<size_t>(top.stride) * (static_cast<size_t>(ty) * top.width + tx);
    CHECK(top.texels[i] == doctest::Approx(mean(tx, ty)).epsilon(1e-6));
  }
  CHECK(top.stride == 3);  // a grey texture: every alpha 1
}

TEST_CASE("textures: held levels of an opaque texture keep RGB alone and filter to the same bits") {
  // The same RGB twice, once with every alpha 1 (held as RGB, 12 bytes a texel) and once with
  // alpha 0.75 (RGBA): every lookup, point or filtered, of any wrap, gives the same RGB.
  const int w = 64, h = 32;
  std::vector<float> opaque(4 * w * h), translucent(4 * w * h);
  Pcg32 rng(3, 7);
  for (int i = 0; i < w * h; ++i) {
    for (int c = 0; c < 3; ++c) opaque[4 * i + c] = translucent[4 * i + c] = rng.next_float();
    opaque[4 * i + 3] = 1.0f;
    translucent[4 * i + 3] = 0.75f;
  }
  LevelBuilder a(w, h, 4, 1 << 20), b(w, h, 4, 1 << 20);
  a.add_rows(0, h, opaque.data());
  b.add_rows(0, h, translucent.data());
  const CoarseLevels packed = a.finish(), full = b.finish();
  REQUIRE(packed.levels().size() == full.levels().size());
  for (size_t l = 0; l < packed.levels().size(); ++l) {
    CHECK(packed.levels()[l].stride == 3);
    CHECK(full.levels()[l].stride == 4);
  }
  int compared = 0;
  for (int k = 0; k < 4000; ++k) {
    TextureQuery q;
    q.s = 3 * rng.next_float() - 1, q.t = 3 * rng.next_float() - 1;
    const float size = std::exp2(8 * rng.next_float() - 9);  // 1/512 to 1/2 of the texture
    q.dsdx = size * (rng.next_float() - 0.5f), q.dtdx = size * (rng.next_float() - 0.5f);
    q.dsdy = 0.1f * size * (rng.next_float() - 0.5f), q.dtdy = size * (rng.next_float() - 0.5f);
    q.wrap_s = static_cast<TextureWrap>(k % 4);
    q.wrap_t = static_cast<TextureWrap>((k / 4) % 4);
    q.isotropic = k % 7 == 0;
    const bool filtered = k % 5 != 0;
    float x[4], y[4];
    REQUIRE(packed.lookup(q, filtered, x));
    REQUIRE(full.lookup(q, filtered, y));
    CAPTURE(k);
    for (int c = 0; c < 3; ++c) CHECK(x[c] == y[c]);
    CHECK(x[3] == 1.0f);
    ++compared;
  }
  CHECK(compared == 4000);
}

TEST_CASE("textures: held levels and the TextureSystem agree where one hands over to the other") {
  TempDir dir("pt-tex");
  // 1024^2 (level 0 stays with the TextureSystem, 512^2 and coarser are held), smooth in linear
  // light, so that the two filters' small differences in shape show as small differences in value.
  std::string exr = write_grey(dir, "smooth.exr", 1024, 1024, [](int x, int y, int c) {
    return 0.5f + 0.4f * std::sin(0.02f * x + 0.5f * c) * std::cos(0.015f * y);
  });
  auto cache = make_texture_cache({});
  int id = cache->add(exr, TextureEncoding::kData);
  for (float width : {0.4f / 1024, 0.9f / 1024, 1.1f / 1024, 2.5f / 1024, 8.0f / 1024}) {
    for (float s : {0.13f, 0.52f, 0.87f}) {
      Spectrum v = cache->lookup(id, at(s, 1.0f - s, width));
      float x = s * 1024 - 0.5f, y = (1.0f - s) * 1024 - 0.5f;
      float exact = 0.5f + 0.4f * std::sin(0.02f * x) * std::cos(0.015f * y);
      CAPTURE(width * 1024);
      CAPTURE(s);
      CHECK(v.x == doctest::Approx(exact).epsilon(0.02));
    }
  }
}

TEST_CASE("textures: once all are registered, pt holds the finer levels of as many as its budget fits, whatever their order") {
  TempDir dir("pt-tex");
  auto value = [](int x, int y, int c) { return 0.5f + 0.4f * std::sin(0.02f * x + 0.5f * c) * std::cos(0.015f * y); };
  std::string a = write_grey(dir, "a.exr", 1024, 1024, value);
  std::string b = write_grey(dir, "b.exr", 1024, 1024, [&](int x, int y, int c) { return value(y, x, c); });
  // The whole pyramid of a 1024^2 texture is 22.4 MB: one fits in 40 MB, two do not, nor in the 30 MB
  // (3/4) that levels short of whole may take.
  TextureCacheOptions options;
  options.max_memory_mb = 40.0f;
  auto one = make_texture_cache(options);
  int id = one->add(a, TextureEncoding::kData);
  CHECK(one->info(id).held_first == 1);  // the first pass holds 512^2 and coarser
  std::vector<Spectrum> before;
  for (float width : {0.4f / 1024, 2.5f / 1024, 8.0f / 1024, 100.0f / 1024}) before.push_back(one->lookup(id, at(0.37f, 0.61f, width)));
  one->finish_loading();
  CHECK(one->info(id).held_first == 0);
  // The same levels where both held them (up to the rounding of how they were averaged), and level 0
  // itself now pt's: a point at a texel's centre is the texel.
  size_t i = 0;
  for (float width : {0.4f / 1024, 2.5f / 1024, 8.0f / 1024, 100.0f / 1024}) {
    CAPTURE(width * 1024);
    Spectrum after = one->lookup(id, at(0.37f, 0.61f, width));
    const float tolerance = width * 1024 < 1.5f ? 0.02f : 1e-5f;  // level 0: the TextureSystem's filter before
    CHECK(after.x == doctest::Approx(before[i].x).epsilon(tolerance));
    CHECK(after.z == doctest::Approx(before[i].z).epsilon(tolerance));
    ++i;
  }
  CHECK(one->lookup(id, at(100.5f / 1024, 200.5f / 1024)).x == doctest::Approx(value(100, 200, 0)).epsilon(1e-6));
  // Two that do not both fit: neither gains, in either order.
  for (bool swap : {false, true}) {
    auto two = make_texture_cache(options);
    int first = two->add(swap ? b : a, TextureEncoding::kData), second = two->add(swap ? a : b, TextureEncoding::kData);
    two->finish_loading();
    CHECK(two->info(first).held_first == 1);
    CHECK(two->info(second).held_first == 1);
  }
  // An image held in memory (a glTF's) gains its levels from its bytes, as a file does from disk.
  {
    std::string png = write_grey(dir, "c.png", 1024, 1024, [&](int x, int y, int c) { return value(x, y, c); });
    std::ifstream in(png, std::ios::binary);
    std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    options.max_memory_mb = 80.0f;  // room for both
    auto both = make_texture_cache(options);
    int memory = both->add_memory("embedded image", "png", bytes, TextureEncoding::kColour);
    int file = both->add(png, TextureEncoding::kColour);
    CHECK(both->info(memory).held_first == 1);
    both->finish_loading();
    CHECK(both->info(memory).held_first == 0);
    CHECK(both->info(file).held_first == 0);
    CHECK(both->lookup(memory, at(300.5f / 1024, 700.5f / 1024)).x == both->lookup(file, at(300.5f / 1024, 700.5f / 1024)).x);
    options.max_memory_mb = 40.0f;
  }
  // Both whole within the whole bound (44.7 MB in 50), though not within 3/4 of it: held whole,
  // since the TextureSystem then needs no cache at all.
  {
    TextureCacheOptions roomy = options;
    roomy.max_memory_mb = 50.0f;
    auto two = make_texture_cache(roomy);
    int first = two->add(a, TextureEncoding::kData), second = two->add(b, TextureEncoding::kData);
    two->finish_loading();
    CHECK(two->info(first).held_first == 0);
    CHECK(two->info(second).held_first == 0);
  }
  // A file that no longer reads when its levels are read again (changed after it was checked) is
  // an error naming it, thrown from the reading threads to the caller.
  {
    std::string d = write_grey(dir, "d.exr", 1024, 1024, value);
    auto cache = make_texture_cache(options);
    cache->add(d, TextureEncoding::kData);
    std::ofstream(d, std::ios::binary | std::ios::trunc) << "not an image any more";
    CHECK_THROWS_WITH_AS(cache->finish_loading(), doctest::Contains("d.exr"), Error);
  }
  // A budget too small for 512^2 (the first pass then holds 64^2): nothing changes.
  options.max_memory_mb = 4.0f;
  auto small = make_texture_cache(options);
  int s = small->add(a, TextureEncoding::kData);
  CHECK(small->info(s).held_first == 4);
  small->finish_loading();
  CHECK(small->info(s).held_first == 4);
}

TEST_CASE("textures: an anisotropic footprint is averaged along its major axis, not across") {
  TempDir dir("pt-tex");
  // Columns alternate 0 and 1 (linear, float); rows are constant. A footprint 8 texels long along
  // s and half a texel wide along t averages to 0.5; the same footprint along t keeps a column's
  // value (at a ratio of 8, within CoarseLevels::kMaxProbes: a longer one widens across).
  std::string exr = write_grey(dir, "cols.exr", 256, 256, [](int x, int, int) { return float(x % 2); });
  auto cache = make_texture_cache({});
  int id = cache->add(exr, TextureEncoding::kData);
  TextureQuery along;
  along.s = 100.5f / 256, along.t = 0.5f;
  along.dsdx = 8.0f / 256, along.dtdy = 0.5f / 256;
  CHECK(cache->lookup(id, along).x == doctest::Approx(0.5f).epsilon(0.05));
  TextureQuery across = along;
  across.dsdx = 0.5f / 256, across.dtdy = 8.0f / 256;
  CHECK(cache->lookup(id, across).x == doctest::Approx(0.0f).scale(1).epsilon(0.05));
  across.s = 101.5f / 256;
  CHECK(cache->lookup(id, across).x == doctest::Approx(1.0f).epsilon(0.05));
  // Filtered as after a rough bounce (isotropic), the long footprint averages both ways.
  across.isotropic = true;
  CHECK(cache->lookup(id, across).x == doctest::Approx(0.5f).epsilon(0.05));
}

TEST_CASE("textures: an image held in memory is registered once and looked up like its file") {
  TempDir dir("pt-tex");
  std::string png = write_grey(dir, "grey.png", 8, 8, [&](int x, int, int) { return x < 4 ? 0.2f : 0.7f; });
  std::ifstream in(png, std::ios::binary);
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  auto cache = make_texture_cache({});
  int file = cache->add(png, TextureEncoding::kColour);
  int memory = cache->add_memory("embedded image", "png", bytes, TextureEncoding::kColour);
  CHECK(file != memory);
  CHECK(cache->info(memory).path == "embedded image");
  for (float s : {0.1f, 0.4f, 0.6f, 0.9f}) {
    CHECK(cache->lookup(memory, at(s, 0.5f)).x == doctest::Approx(cache->lookup(file, at(s, 0.5f)).x));
  }
  // Bytes that are no image are refused, naming it.
  std::vector<unsigned char> junk(100, 7);
  CHECK_THROWS_WITH_AS(cache->add_memory("junk", "png", junk, TextureEncoding::kColour), doctest::Contains("junk"), Error);
}

TEST_CASE("textures: a hit computes what its material reads, and the footprint a bounce starts from in any case") {
  // Two quads side by side in one textured scene: x < 0 textured, x > 0 plain. A hit on the plain
  // one needs no uv footprint, but its bounce's differentials start from the footprint's extent,
  // which must be what a textured hit at the same place gets.
  TempDir dir("pt-tex-use");
  write_grey(dir, "checker.exr", 8, 8, [](int x, int y, int) { return float((x + y) % 2); });
  auto quad = [&](const std::string& name, float x0, float x1) {
    dir.write(name, "v " + std::to_string(x0) + " 0 1\nv " + std::to_string(x1) + " 0 1\nv " + std::to_string(x1) +
                        " 0 -1\nv " + std::to_string(x0) + " 0 -1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3 4/4\n");
  };
  quad("left.obj", -1, 0);
  quad("right.obj", 0, 1);
  auto scene_with = [&](const std::string& right_material) {
    return load_scene(dir.write("scene.json", R"({"objects": [{"file": "left.obj", "material": "tex"},
      {"file": "right.obj", "material": ")" + right_material + R"("}],
      "materials": {"tex": {"texture": "checker.exr"}, "plain": {"albedo": 0.5}},
      "environment": {"radiance": 1}})"));
  };
  Scene mixed = scene_with("plain"), all_textured = scene_with("tex");
  auto accel = make_accel(mixed.geometry(), AccelOptions{});
  auto all_accel = make_accel(all_textured.geometry(), AccelOptions{});
  auto ray_to = [](Vec3f target, bool differentials) {
    Ray ray;
    ray.o = {0.1f, 2.0f, 1.5f};
    ray.d = normalize(target - ray.o);
    if (differentials) {
      ray.diff.dddx = {0.01f, 0, 0};
      ray.diff.dddy = {0, 0.004f, 0.008f};
      ray.diff.scale = 1.0f;
      ray.diff.centre = {0.25f, -0.25f};
    }
    return ray;
  };
  for (Vec3f target : {Vec3f(-0.4f, 0, 0.2f), Vec3f(0.4f, 0, -0.3f)}) {
    const bool plain = target.x > 0;
    CAPTURE(plain);
    Ray ray = ray_to(target, true);
    std::optional<Hit> hit = accel->intersect(ray), all_hit = all_accel->intersect(ray);
    REQUIRE(hit);
    REQUIRE(all_hit);
    SurfaceInteraction si = mixed.interaction(ray, *hit), ref = all_textured.interaction(ray, *all_hit);
    CHECK(length(si.dpdx) > 0.0f);
    CHECK(length(si.dpdy) > 0.0f);
    CHECK(si.dpdx.x == ref.dpdx.x);
    CHECK(si.dpdx.z == ref.dpdx.z);
    CHECK(si.dpdy.z == ref.dpdy.z);
    CHECK(std::abs(ref.duvdx.x) + std::abs(ref.duvdx.y) > 0.0f);
    if (plain) {
      CHECK((si.duvdx.x == 0.0f && si.duvdx.y == 0.0f && si.duvdy.x == 0.0f && si.duvdy.y == 0.0f));
    } else {
      CHECK(si.duvdx.x == ref.duvdx.x);
      CHECK(si.duv_centre.y == ref.duv_centre.y);
      CHECK(std::abs(si.duv_centre.x) + std::abs(si.duv_centre.y) > 0.0f);
    }
    // Without differentials (bilinear lookups) there is no footprint to make.
    SurfaceInteraction point = mixed.interaction(ray_to(target, false), *hit);
    CHECK(length(point.dpdx) == 0.0f);
    CHECK((point.duvdx.x == 0.0f && point.duvdx.y == 0.0f));
  }
}
