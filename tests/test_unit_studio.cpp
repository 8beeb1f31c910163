// The default "studio" lighting of a scene in which nothing emits: a ground under the model and a
// sky with a sun to the camera's left, nothing below the horizon; the default camera frames the
// model (not the ground); --studio none and scenes that light themselves get no studio; and the
// picture shows the model's form: a lit and a shaded side, and a contact shadow on the ground.
#include <doctest/doctest.h>

#include "core/scene/loader.h"
#include "core/scene/scene_builder.h"
#include "core/scene/studio.h"
#include "renderer/render/job.h"
#include "temp_dir.h"

using namespace pt;

namespace {

// A sphere-like blob: an octahedron of radius 1 around (5, 2, -3), as an OBJ.
std::string octahedron(const TempDir& dir, bool z_up) {
  auto v = [&](float x, float y, float z) {
    char buf[96];
    if (z_up) std::snprintf(buf, sizeof buf, "v %g %g %g\n", 5 + x, 3 - z, 2 + y);  // (x, y, z) -> (x, -z, y)
    else std::snprintf(buf, sizeof buf, "v %g %g %g\n", 5 + x, 2 + y, -3 + z);
    return std::string(buf);
  };
  return dir.write(z_up ? "octa_z.obj" : "octa.obj",
                   v(1, 0, 0) + v(-1, 0, 0) + v(0, 1, 0) + v(0, -1, 0) + v(0, 0, 1) + v(0, 0, -1) +
                       "f 1 3 5\nf 3 2 5\nf 2 4 5\nf 4 1 5\nf 3 1 6\nf 2 3 6\nf 4 2 6\nf 1 4 6\n");
}

Job job_for(const std::string& path, const std::string& studio, const std::string& axis = "y") {
  JobOptions o;
  o.scene_path = path;
  o.resolution = std::string("48x36");
  o.view.studio = kStudioNames.parse(studio);
  o.view.up_axis = kUpAxisNames.parse(axis);
  return prepare_job(o);
}

// The centre of the sky's brightest region (texels above a tenth of the brightest): the sun.
Vec3f sun_of(const Environment& env) {
  const Texture& sky = *env.image();
  float brightest = 0;
  for (const Spectrum& t : sky.texels) brightest = std::max(brightest, luminance(t));
  Vec3f sum(0.0f);
  for (int y = 0; y < sky.height; ++y) {
    for (int x = 0; x < sky.width; ++x) {
      if (luminance(sky.texel(x, y)) > 0.1f * brightest) {
        sum += env.uv_to_direction({(x + 0.5f) / sky.width, (y + 0.5f) / sky.height});
      }
    }
  }
  return normalize(sum);
}

}  // namespace

TEST_CASE("studio: a ground just under the model, a sky with the sun to the camera's left, nothing below the horizon") {
  TempDir dir("pt-studio");
  for (const char* axis : {"y", "z"}) {
    std::string axis_name = axis;
    CAPTURE(axis_name);
    bool z = std::string(axis) == "z";
    Job job = job_for(octahedron(dir, z), "sun", axis);
    const Scene& scene = *job.scene;
    REQUIRE(scene.studio().has_value());
    Vec3f up = z ? Vec3f(0, 0, 1) : Vec3f(0, 1, 0);
    // The model's bounds are what the camera frames; the ground is beyond them.
    BBox model = scene.studio()->model_bounds;
    CHECK(scene.bounds().lo == model.lo);
    CHECK(scene.bounds().hi == model.hi);
    CHECK(length(model.extent()) == doctest::Approx(2 * std::sqrt(3.0f)));
    float bottom = dot(model.lo, up), radius = 0.5f * length(model.extent());
    BBox ground;
    const Mesh& mesh = scene.mesh();
    for (size_t t = scene.studio()->first_triangle; t < mesh.triangle_count(); ++t) {
      CHECK(scene.materials()[mesh.material[t]].name == "studio ground");
      CHECK(dot(normalize(mesh.geometric_normal(t)), up) == doctest::Approx(1.0f));  // faces up
      for (int c = 0; c < 3; ++c) ground.expand(mesh.vertex(t, c));
    }
    // Just under the lowest point (no depth fight with a face lying on it), not visibly below.
    CHECK(dot(ground.lo, up) < bottom);
    CHECK(dot(ground.lo, up) > bottom - 1e-3f * radius);
    CHECK(dot(ground.extent(), up) == doctest::Approx(0.0f).epsilon(1e-6));
    CHECK(length(ground.extent()) > 1e4f * radius);  // reaches the horizon
    // The sky: nothing below the horizon, so no light sample is spent where the ground hides it.
    const Environment& env = *scene.environment();
    CHECK(env.has_image());
    CHECK(is_black(env.eval(-up)));
    CHECK(env.pdf(normalize(-up + Vec3f(0.1f, 0.1f, 0.1f))) == 0.0f);
    for (int i = 0; i < 1000; ++i) {
      float pdf;
      Vec3f d = env.sample({(i + 0.5f) / 1000, std::fmod(i * 0.618034f, 1.0f)}, &pdf);
      CHECK(dot(d, up) > -0.02f);  // bilinear filtering blurs the horizon by less than a texel
    }
    // The sun: 50 degrees up, to the left of the default camera, which is what the studio was
    // arranged for and what renders.
    REQUIRE(scene.studio()->camera.has_value());
    const Camera& cam = job.render.camera;
    CHECK(cam.position == scene.studio()->camera->position);
    CHECK(cam.up == up);
    Vec3f sun = sun_of(env);
    CHECK(std::asin(dot(sun, up)) * 180 / kPi == doctest::Approx(50).epsilon(0.03));
    Vec3f forward = normalize(cam.look_at - cam.position), right = normalize(cross(forward, up));
    CHECK(dot(sun, right) < -0.3f);   // from the left
    CHECK(dot(sun, forward) < -0.3f); // and from the camera's side, so the visible side is lit
  }
}

TEST_CASE("studio: the default camera frames the model as it would without the studio; the same for y and z up") {
  TempDir dir("pt-studio");
  Job lit = job_for(octahedron(dir, false), "sun"), plain = job_for(octahedron(dir, false), "none");
  CHECK(lit.render.camera.position == plain.render.camera.position);
  CHECK(lit.render.camera.look_at == plain.render.camera.look_at);
  Job lit_z = job_for(octahedron(dir, true), "sun", "z");
  Vec3f a = lit.render.camera.position - lit.render.camera.look_at;
  Vec3f b = lit_z.render.camera.position - lit_z.render.camera.look_at;
  CHECK(b.x == doctest::Approx(a.x));
  CHECK(b.y == doctest::Approx(-a.z));
  CHECK(b.z == doctest::Approx(a.y));
}

TEST_CASE("studio: none, sky, and scenes that light themselves") {
  TempDir dir("pt-studio");
  std::string obj = octahedron(dir, false);
  Job none = job_for(obj, "none");
  CHECK_FALSE(none.scene->studio().has_value());
  CHECK(none.scene->mesh().triangle_count() == 8);
  CHECK(none.scene->environment()->constant() == Spectrum(1.0f));
  Job sky = job_for(obj, "sky");
  REQUIRE(sky.scene->studio().has_value());
  // No sun: no texel brighter than a sky.
  float brightest = 0;
  for (const Spectrum& t : sky.scene->environment()->image()->texels) brightest = std::max(brightest, max_component(t));
  CHECK(brightest < 1.0f);
  std::string lit = dir.write("lit.json", R"({"objects": [{"file": "octa.obj"}],
    "lights": [{"type": "point", "position": [0, 9, 0], "intensity": 10}]})");
  Job own = job_for(lit, "sun");
  CHECK_FALSE(own.scene->studio().has_value());
  CHECK_FALSE(own.scene->environment().has_value());
  CHECK(own.scene->mesh().triangle_count() == 8);
}

TEST_CASE("studio: the picture shows the form: a lit side, a shaded side, a contact shadow") {
  TempDir dir("pt-studio");
  // A cube standing on the ground, seen from the front and a little above (the default camera).
  std::string obj = dir.write("cube.obj", "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\n"
                                          "f 1 4 3 2\nf 5 6 7 8\nf 1 2 6 5\nf 4 8 7 3\nf 1 5 8 4\nf 2 3 7 6\n");
  JobOptions o;
  o.scene_path = obj;
  o.resolution = std::string("64x48");
  o.spp = 16;
  o.view.look_from = std::string("0.5,2,5");
  Job job = prepare_job(o);
  RenderResult r = render(job);
  const Camera& cam = job.render.camera;
  Camera::Basis basis = cam.basis(64.0f / 48.0f);
  // Where a world point lands in the image, and the mean radiance of the 3x3 pixels around it.
  auto at = [&](Vec3f p) {
    Vec3f d = p - cam.position;
    // Solve p - o = s (forward + right u + down v) for (u, v).
    Vec3f n = cross(basis.right, basis.down);
    float s = dot(d, n) / dot(basis.forward, n);
    Vec3f q = d / s - basis.forward;
    float u = dot(q, basis.right) / dot(basis.right, basis.right), v = dot(q, basis.down) / dot(basis.down, basis.down);
    int x = static_cast<int>(u * 64), y = static_cast<int>(v * 48);
    REQUIRE(x >= 1);
    REQUIRE(x < 63);
    REQUIRE(y >= 1);
    REQUIRE(y < 47);
    double sum = 0;
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) sum += luminance(r.film.mean(x + dx, y + dy));
    }
    return sum / 9;
  };
  // The sun is high, to the camera's left: the top is brighter than the front face, and the
  // cube's shadow falls behind it to the right, where the ground is darker than in the open left
  // of the cube.
  double front = at({0.5f, 0.5f, 1.0f}), top = at({0.5f, 1.0f, 0.5f});
  double open_ground = at({-0.6f, 0.0f, 1.0f}), shadow = at({1.2f, 0.0f, 0.6f});
  INFO("front face " << front << ", top " << top << ", ground in the open " << open_ground << ", in the shadow " << shadow);
  CHECK(top > 1.2 * front);            // the sun is high: the top is brightest
  CHECK(front > 0.15);                 // the face toward the camera is not black
  CHECK(shadow < 0.7 * open_ground);   // a visible shadow on the ground
}

TEST_CASE("studio: the ground keeps every per-corner array of the mesh one entry per corner") {
  // A glTF file with TANGENT (or any loader that fills tangents before the studio) left the ground's
  // triangles without them, and a hit on the ground read past the end of the tangents.
  SceneBuilder scene;
  scene.source = "test";
  Mesh& m = scene.mesh;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.indices = {0, 1, 2};
  m.material = {scene.default_material()};
  m.corner_normals.assign(3, Vec3f(0, 0, 1));
  m.corner_uvs.assign(3, Vec2f(0, 0));
  m.corner_tangents.assign(3, Vec3f(1, 0, 0));
  m.corner_tangent_signs.assign(3, 1.0f);
  add_studio(scene, Studio::kSky, UpAxis::kY);
  const size_t corners = 3 * m.triangle_count();
  REQUIRE(m.triangle_count() > 1);
  CHECK(m.corner_normals.size() == corners);
  CHECK(m.corner_uvs.size() == corners);
  CHECK(m.corner_tangents.size() == corners);
  CHECK(m.corner_tangent_signs.size() == corners);
  CHECK(m.material.size() == m.triangle_count());
}
