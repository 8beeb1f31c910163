// Normal and bump maps (core/scene/shading_normal.h, core/geometry/tangents.h): tangents, a constant
// tilt against a tilted plane, a height ramp against the analytic slope, a furnace, the dark side.
#include <doctest/doctest.h>

#include <cmath>

#include "core/accel/accel.h"
#include "core/geometry/tangents.h"
#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/scene/shading_normal.h"
#include "integrators/integrator.h"
#include "renderer/render/job.h"
#include "renderer/render/render.h"
#include "scene_helpers.h"
#include "temp_dir.h"

using namespace pt;

namespace {

// A 4x4 float texture of one RGB value (data: read as stored).
std::string write_constant(const TempDir& dir, const std::string& name, Spectrum v) {
  Image img(4, 4, {"R", "G", "B"});
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = v[c];
    }
  }
  std::string path = (dir.path / name).string();
  write_image(path, img);
  return path;
}

// The quad y = 0, x and z in [-r, r], front face up; u runs along +x and v along -z (so the
// bitangent, up in the image, is -z).
const char* kQuadObj = R"(v -R 0 R
v R 0 R
v R 0 -R
v -R 0 -R
vt 0 0
vt 1 0
vt 1 1
vt 0 1
usemtl m
f 1/1 2/2 3/3 4/4
)";

std::string quad_scene(const TempDir& dir, const std::string& material_json, float r = 1.0f) {
  std::string obj = kQuadObj;
  std::string rs = std::to_string(r);
  for (size_t at = obj.find('R'); at != std::string::npos; at = obj.find('R', at)) obj.replace(at, 1, rs);
  dir.write("quad.obj", obj);
  return dir.write("scene.json", R"({"objects": [{"file": "quad.obj", "material": "m"}],
    "materials": {"m": )" + material_json + R"(},
    "environment": {"radiance": 1}})");
}

// The shading point a ray from `from` toward the origin finds, as the integrators make it.
ShadingPoint shade(const Scene& scene, const Accel& accel, Vec3f from, Vec3f to = {0, 0, 0}) {
  Ray ray;
  ray.o = from;
  ray.d = normalize(to - from);
  std::optional<Hit> hit = accel.intersect(ray);
  REQUIRE(hit.has_value());
  return make_shading_point(scene, ray, *hit);
}

void check_near(const Vec3f& a, const Vec3f& b, float tolerance = 1e-4f) {
  CHECK(a.x == doctest::Approx(b.x).epsilon(tolerance).scale(1));
  CHECK(a.y == doctest::Approx(b.y).epsilon(tolerance).scale(1));
  CHECK(a.z == doctest::Approx(b.z).epsilon(tolerance).scale(1));
}

}  // namespace

TEST_CASE("tangents: along increasing u, orthonormal to the normal, handedness from the uv orientation") {
  Mesh mesh;
  mesh.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  mesh.indices = {0, 1, 2, 0, 2, 3};
  mesh.material = {0, 0};
  mesh.corner_uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 0}, {1, 1}, {0, 1}};
  compute_tangents(mesh);
  REQUIRE(mesh.corner_tangents.size() == 6);
  for (int c = 0; c < 6; ++c) {
    check_near(mesh.corner_tangents[c], {1, 0, 0});
    CHECK(mesh.corner_tangent_signs[c] == 1.0f);  // cross(n, t) = +y, the direction of increasing v
  }
  // Mirrored in u (as a mirrored half of a model is): the tangent follows u, the sign flips so the
  // bitangent still follows v.
  for (Vec2f& uv : mesh.corner_uvs) uv.x = 1 - uv.x;
  compute_tangents(mesh);
  for (int c = 0; c < 6; ++c) {
    check_near(mesh.corner_tangents[c], {-1, 0, 0});
    CHECK(mesh.corner_tangent_signs[c] == -1.0f);
  }
  // Smooth normals: the tangent is orthogonalised against each corner's normal.
  Vec3f tilted = normalize(Vec3f(1, 0, 1));
  mesh.corner_normals.assign(6, tilted);
  compute_tangents(mesh);
  CHECK(dot(mesh.corner_tangents[0], tilted) == doctest::Approx(0.0f).scale(1));
  CHECK(length(mesh.corner_tangents[0]) == doctest::Approx(1.0f));
}

TEST_CASE("normal map: a constant tilt shades as a plane tilted by as much") {
  TempDir dir("pt-normal-map");
  const float tilt = 30.0f * kPi / 180.0f, s = std::sin(tilt), c = std::cos(tilt);
  // Red tilts toward the tangent (+x), green toward the bitangent (-z here: up in the image).
  write_constant(dir, "red.exr", {0.5f + 0.5f * s, 0.5f, 0.5f + 0.5f * c});
  write_constant(dir, "green.exr", {0.5f, 0.5f + 0.5f * s, 0.5f + 0.5f * c});
  for (auto [file, expected] : {std::pair<const char*, Vec3f>{"red.exr", {s, c, 0}}, {"green.exr", {0, c, -s}}}) {
    CAPTURE(file);
    Scene mapped = load_scene(quad_scene(dir, std::string(R"({"normal_texture": ")") + file + R"("})"));
    auto accel = make_accel(mapped.geometry(), AccelOptions{});
    ShadingPoint sp = shade(mapped, *accel, {0.1f, 3.0f, 0.2f});
    check_near(sp.frame.n, expected);
    // The same plane, tilted for real: identical shading for every light direction.
    SceneBuilder b;
    uint32_t m = test::add_material(b, test::diffuse(Spectrum(0.8f)));
    // Corners -t-u, t-u, t+u, -t+u face cross(t, u) = expected.
    Vec3f t = normalize(cross(expected, std::abs(expected.z) < 0.9f ? Vec3f(0, 0, 1) : Vec3f(1, 0, 0)));
    Vec3f u = cross(expected, t);
    test::add_quad(b, t * -2 - u * 2, t * 2 - u * 2, t * 2 + u * 2, u * 2 - t * 2, m);
    b.environment = Environment(Spectrum(1.0f));
    Scene tilted(std::move(b));
    auto tilted_accel = make_accel(tilted.geometry(), AccelOptions{});
    ShadingPoint ref = shade(tilted, *tilted_accel, expected * 3.0f + Vec3f(0.1f, 0.0f, 0.2f), Vec3f(0.1f, 0.0f, 0.2f));
    check_near(sp.frame.n, ref.frame.n);
    for (Vec3f l : {Vec3f(0, 1, 0), normalize(Vec3f(1, 1, 0)), normalize(Vec3f(-0.3f, 1, 0.8f))}) {
      Spectrum a = sp.bsdf.eval(sp.frame.to_local(sp.wo), sp.frame.to_local(l)) * sp.frame.to_local(l).z;
      Spectrum r = ref.bsdf.eval(ref.frame.to_local(ref.wo), ref.frame.to_local(l)) * ref.frame.to_local(l).z;
      CHECK(a.x == doctest::Approx(r.x).epsilon(1e-4));
    }
  }
}

TEST_CASE("bump map: a height ramp gives the slope of the displaced surface") {
  TempDir dir("pt-bump");
  // h(u) = u across a 256-texel float ramp (clamped, so its ends do not wrap into each other).
  Image img(256, 4, {"R", "G", "B"});
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 256; ++x) {
      for (int ch = 0; ch < 3; ++ch) img.at(x, y, ch) = (x + 0.5f) / 256.0f;
    }
  }
  write_image((dir.path / "ramp.exr").string(), img);
  const float scale = 0.5f;
  Scene scene = load_scene(quad_scene(
      dir, R"({"bump_texture": {"file": "ramp.exr", "wrap": "clamp"}, "bump_scale": )" + std::to_string(scale) + "}"));
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  // The quad spans 2 units of x per unit of u: displaced by scale * u, its height is
  // scale (x + 1) / 2, of slope scale / 2, with normal (-scale / 2, 1, 0) normalised.
  ShadingPoint sp = shade(scene, *accel, {0.1f, 3.0f, 0.3f}, {0.1f, 0.0f, 0.3f});
  check_near(sp.frame.n, normalize(Vec3f(-scale / 2, 1, 0)), 2e-3f);
}

TEST_CASE("normal map: a white furnace reflects (1 + cos tilt) / 2 of a uniform sky, never more") {
  TempDir dir("pt-normal-furnace");
  const float tilt = 30.0f * kPi / 180.0f;
  write_constant(dir, "n.exr", {0.5f + 0.5f * std::sin(tilt), 0.5f, 0.5f + 0.5f * std::cos(tilt)});
  std::string path = quad_scene(dir, R"({"albedo": 1, "normal_texture": "n.exr"})", 1000.0f);
  JobOptions o;
  o.scene_path = path;
  o.view.studio = Studio::kNone;
  o.view.look_from = "0,1,0";
  o.view.look_at = "0,0,0";
  o.view.up = "0,0,-1";
  o.view.fov = 20.0f;
  o.resolution = "8x8";
  o.spp = 1024;
  o.integrator = IntegratorKind::kPath;
  o.max_depth = 1;  // the sky seen after one bounce: the plane's reflectance
  Job job = prepare_job(o);
  Image image = render(job).film.to_image(job.aovs);
  double sum = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) sum += image.at(x, y, 0);
  }
  double mean = sum / (image.width * image.height);
  // The cosine about the tilted normal, over the hemisphere above the plane (the rest is refused
  // as below the surface): (1 + cos tilt) / 2 of a white sky, 0.933.
  CHECK(mean == doctest::Approx((1 + std::cos(tilt)) / 2).epsilon(0.01));
  CHECK(mean <= 1.0);
}

TEST_CASE("normal map: the side a tilted normal turns away from is not black, and nothing leaks") {
  TempDir dir("pt-normal-dark");
  const float tilt = 60.0f * kPi / 180.0f;
  write_constant(dir, "n.exr", {0.5f + 0.5f * std::sin(tilt), 0.5f, 0.5f + 0.5f * std::cos(tilt)});
  Scene scene = load_scene(quad_scene(dir, R"({"albedo": 1, "normal_texture": "n.exr"})", 10.0f));
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  // Seen from low on the -x side, the mapped normal (tilted toward +x by 60 degrees) faces away:
  // wo lies below its hemisphere. The adapted normal faces wo and its mirror direction stays above
  // the surface.
  Vec3f from = normalize(Vec3f(-1, 0.3f, 0)) * 5.0f;
  Vec3f raw = {std::sin(tilt), std::cos(tilt), 0};
  REQUIRE(dot(normalize(from), raw) < 0);
  ShadingPoint sp = shade(scene, *accel, from);
  Vec3f wo = sp.frame.to_local(sp.wo);
  CHECK(wo.z > 0);
  Vec3f mirror = sp.frame.to_world({-wo.x, -wo.y, wo.z});
  CHECK(dot(mirror, sp.ng) > 0);
  CHECK(sp.bsdf.eval(wo, sp.frame.to_local(Vec3f(0, 1, 0))).x > 0);
  // The adaptation alone, for any view: the result faces wo.
  for (float a = 0.05f; a < 1.5f; a += 0.1f) {
    Vec3f v = normalize(Vec3f(-std::cos(a), std::sin(a), 0.1f));
    Vec3f n = adapt_shading_normal(raw, {0, 1, 0}, v);
    CHECK(dot(n, v) > 0);
    CHECK(dot(n * (2 * dot(v, n)) - v, Vec3f(0, 1, 0)) >= 0.0f);
  }
}
