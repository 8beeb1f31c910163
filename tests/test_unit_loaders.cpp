// OBJ/MTL and JSON scene loading: what the files say is what the scene holds.
#include <doctest/doctest.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include "core/accel/accel.h"
#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "renderer/render/job.h"
#include "temp_dir.h"

using namespace pt;
namespace fs = std::filesystem;

namespace {


size_t count_notes(const Scene& scene, const std::string& needle) {
  return std::count_if(scene.notes().begin(), scene.notes().end(),
                       [&](const std::string& n) { return n.find(needle) != std::string::npos; });
}

size_t occurrences(const std::string& text, const std::string& needle) {
  size_t n = 0;
  for (size_t at = text.find(needle); at != std::string::npos; at = text.find(needle, at + 1)) ++n;
  return n;
}

// A 2x2 texture with a different colour in each corner, so orientation mistakes show:
// top-left red, top-right green, bottom-left blue, bottom-right white.
void write_corner_texture(const std::string& path) {
  fs::create_directories(fs::path(path).parent_path());
  Image img(2, 2, {"R", "G", "B"});
  const Spectrum colours[4] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 1}};
  for (int i = 0; i < 4; ++i) {
    for (int c = 0; c < 3; ++c) img.at(i % 2, i / 2, c) = colours[i][c];
  }
  write_image(path, img);
}

// The surface a ray straight down through (x, z) hits, as the integrators would see it.
SurfaceInteraction look_down(const Scene& scene, const Accel& accel, float x, float z) {
  Ray ray{{x, 10, z}, {0, -1, 0}};
  std::optional<Hit> hit = accel.intersect(ray);
  REQUIRE(hit.has_value());
  return scene.interaction(ray, *hit);
}

const char* kQuadPentagonObj = R"(# a quad and a pentagon in the y = 0 plane, front faces up
mtllib two.mtl
v 0 0 0
v 1 0 0
v 1 0 -1
v 0 0 -1
v 2 0 0
v 4 0 0
v 4 0 -2
v 3 0 -3
v 2 0 -2
vt 0 0
vt 1 0
vt 1 1
vt 0 1
vn 0 1 0
vn 0.6 0.8 0
usemtl red
f 1/1/1 2/2/1 3/3/1 4/4/1
usemtl lamp
f 5//2 6//2 7//2 8//2 9//2
l 1 2
l 2 3
vp 0.5
)";

const char* kTwoMtl = R"(newmtl red
Kd 0.8 0.1 0.1
Ka 0.1 0.1 0.1
newmtl lamp
Kd 0 0 0
Ke 4 3 2
Ka 0 0 0
refl sky.png
)";

}  // namespace

TEST_CASE("OBJ: polygons are triangulated, materials per face, normals and uvs kept, Ke makes lights") {
  TempDir dir("pt-loaders");
  std::string obj = dir.write("two.obj", kQuadPentagonObj);
  dir.write("two.mtl", kTwoMtl);
  Scene scene = load_scene(obj);
  const Mesh& mesh = scene.mesh();
  REQUIRE(mesh.triangle_count() == 5);  // 4 - 2 + 5 - 2

  // Triangulation covers each polygon exactly: areas add up to the polygons' areas.
  double quad_area = 0, pentagon_area = 0;
  for (size_t t = 0; t < 2; ++t) quad_area += mesh.area(t);
  for (size_t t = 2; t < 5; ++t) pentagon_area += mesh.area(t);
  CHECK(quad_area == doctest::Approx(1.0));
  CHECK(pentagon_area == doctest::Approx(5.0));  // shoelace area of (2,0),(4,0),(4,-2),(3,-3),(2,-2)
  for (size_t t = 0; t < 5; ++t) CHECK(mesh.geometric_normal(t).y > 0);  // winding kept

  // Per-face materials, converted from the MTL.
  const Material& red = scene.materials()[mesh.material[0]];
  const Material& lamp = scene.materials()[mesh.material[2]];
  CHECK(red.name == "red");
  CHECK(mesh.material[1] == mesh.material[0]);
  CHECK(std::get<Diffuse>(red.model).kd.x == doctest::Approx(0.8f));
  CHECK(std::get<Diffuse>(red.model).kd.y == doctest::Approx(0.1f));
  CHECK(lamp.name == "lamp");
  CHECK(mesh.material[3] == mesh.material[2]);
  CHECK(lamp.emission == Spectrum(4, 3, 2));

  // Ke makes the lamp's three triangles area lights, and the scene then needs no default light.
  CHECK(scene.light_set().count(LightType::kTriangle) == 3);
  CHECK_FALSE(scene.environment().has_value());
  CHECK(count_notes(scene, "default white environment") == 0);

  // Normals and uvs per corner, from the file.
  REQUIRE(mesh.corner_normals.size() == 15);
  REQUIRE(mesh.corner_uvs.size() == 15);
  for (int c = 0; c < 6; ++c) CHECK(mesh.corner_normals[c] == Vec3f(0, 1, 0));
  for (int c = 6; c < 15; ++c) {
    CHECK(mesh.corner_normals[c].x == doctest::Approx(0.6f));
    CHECK(mesh.corner_normals[c].y == doctest::Approx(0.8f));
  }
  // Each corner's uv is the one its vertex was given (vertex k of the quad has vt k).
  const Vec2f quad_uvs[4] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  const Vec3f quad_pos[4] = {{0, 0, 0}, {1, 0, 0}, {1, 0, -1}, {0, 0, -1}};
  for (int c = 0; c < 6; ++c) {
    Vec3f p = mesh.positions[mesh.indices[c]];
    int k = static_cast<int>(std::find(quad_pos, quad_pos + 4, p) - quad_pos);
    REQUIRE(k < 4);
    CHECK(mesh.corner_uvs[c].x == quad_uvs[k].x);
    CHECK(mesh.corner_uvs[c].y == quad_uvs[k].y);
  }

  // Keys we do not model are listed once each, in one note per file kind.
  CHECK(count_notes(scene, "OBJ statements not supported") == 1);
  CHECK(count_notes(scene, "MTL keys not supported") == 1);
  for (const std::string& note : scene.notes()) {
    if (note.find("OBJ statements") != std::string::npos) {
      CHECK(occurrences(note, " l") + occurrences(note, ": l") >= 1);
      CHECK(occurrences(note, "vp") == 1);
      CHECK(note.find(obj) != std::string::npos);
    }
    if (note.find("MTL keys") != std::string::npos) {
      CHECK(occurrences(note, "Ka") == 0);  // every exporter writes it; not worth a warning
      CHECK(occurrences(note, "refl") == 1);
    }
  }
}

TEST_CASE("OBJ: map_Kd is loaded and looked up with v up, bilinear and wrapping") {
  TempDir dir("pt-loaders");
  write_corner_texture((dir.path / "tex" / "corners.png").string());
  dir.write("quad.mtl", "newmtl tex\nKd 0.5 0.5 0.5\nmap_Kd tex/corners.png\n");
  // Quad over [0,1] x [0,1] in x and -z, uv = (x, -z), front face up.
  std::string obj = dir.write("quad.obj",
                              "mtllib quad.mtl\nv 0 0 0\nv 1 0 0\nv 1 0 -1\nv 0 0 -1\n"
                              "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nusemtl tex\nf 1/1 2/2 3/3 4/4\n");
  Scene scene = load_scene(obj);
  REQUIRE(scene.textures().size() == 1);
  const Diffuse& m = std::get<Diffuse>(scene.materials()[scene.mesh().material[0]].model);
  CHECK(m.kd_texture == 0);
  CHECK(m.kd == Spectrum(1.0f));  // the map replaces Kd
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  // Texel centres: uv (0.25, 0.75) is the top-left texel, (0.75, 0.25) the bottom-right.
  struct Case {
    float u, v;
    Spectrum expected;
  } cases[] = {{0.25f, 0.75f, {1, 0, 0}}, {0.75f, 0.75f, {0, 1, 0}}, {0.25f, 0.25f, {0, 0, 1}}, {0.75f, 0.25f, {1, 1, 1}},
               // Halfway between the two top texels: bilinear blend of red and green.
               {0.5f, 0.75f, {0.5f, 0.5f, 0}},
               // At u = 0 the lookup wraps: half the left column (blue), half the right (white).
               {0.0f, 0.25f, {0.5f, 0.5f, 1.0f}}};
  for (const Case& c : cases) {
    CAPTURE(c.u);
    CAPTURE(c.v);
    SurfaceInteraction si = look_down(scene, *accel, std::clamp(c.u, 1e-4f, 1 - 1e-4f), -c.v);
    Spectrum a = scene.albedo(si);
    for (int k = 0; k < 3; ++k) CHECK(a[k] == doctest::Approx(c.expected[k]).epsilon(2e-3));
  }
}

TEST_CASE("OBJ: a texture that will not load names the OBJ and the image") {
  TempDir dir("pt-loaders");
  dir.write("bad.png", "this is not a PNG");
  dir.write("q.mtl", "newmtl t\nmap_Kd bad.png\n");
  std::string obj = dir.write("q.obj", "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl t\nf 1 2 3\n");
  try {
    load_scene(obj);
    FAIL("expected pt::Error");
  } catch (const Error& e) {
    std::string what = e.what();
    CHECK(what.find(obj) != std::string::npos);
    CHECK(what.find("bad.png") != std::string::npos);
  }
}

TEST_CASE("OBJ alone, --studio none: default camera frames the model and a default white environment is announced") {
  TempDir dir("pt-loaders");
  // A long thin box-like point cloud far from the origin, as triangles.
  std::string obj = dir.write("m.obj",
                              "v 100 50 -20\nv 104 50 -20\nv 104 51 -20\nv 100 51 -21\n"
                              "f 1 2 3\nf 1 3 4\n");
  for (auto [w, h] : {std::pair{640, 480}, std::pair{200, 600}}) {
    JobOptions o;
    o.scene_path = obj;
    o.resolution = std::to_string(w) + "x" + std::to_string(h);
    o.view.studio = Studio::kNone;
    Job job = prepare_job(o);
    const Scene& scene = *job.scene;
    CHECK_FALSE(scene.camera().has_value());
    CHECK(job.default_camera);
    REQUIRE(scene.environment().has_value());
    CHECK(scene.environment()->constant() == Spectrum(1.0f));
    CHECK(count_notes(scene, "default white environment") == 1);
    // Every corner of the bounds projects inside the image, and the centre near its middle;
    // both for the plain framing every candidate view starts from and the one the job picks by
    // looking around.
    auto check_framing = [&](const Camera& cam) {
      const BBox& b = scene.bounds();
      CHECK(length(cam.look_at - b.center()) < 1e-3f);
      Vec3f f = normalize(cam.look_at - cam.position);
      Vec3f r = normalize(cross(f, cam.up));
      Vec3f u = cross(r, f);
      float tan_v = std::tan(0.5f * cam.vfov_degrees * kPi / 180.0f);
      float tan_h = tan_v * w / h;
      for (int i = 0; i < 8; ++i) {
        Vec3f p{i & 1 ? b.hi.x : b.lo.x, i & 2 ? b.hi.y : b.lo.y, i & 4 ? b.hi.z : b.lo.z};
        Vec3f d = p - cam.position;
        float z = dot(d, f);
        REQUIRE(z > 0);
        CHECK(std::abs(dot(d, r) / z) <= tan_h);
        CHECK(std::abs(dot(d, u) / z) <= tan_v);
      }
      // ...and the model is not a speck: the bounds fill a good part of the frame.
      float size = length(b.extent()) / length(b.center() - cam.position);
      CHECK(size > 0.5f * tan_v);
    };
    check_framing(Camera::framing(scene.bounds(), static_cast<float>(w) / h));
    check_framing(job.render.camera);
  }
}

TEST_CASE("default camera frames the geometry, not the point lights") {
  // A light well off to one side must not pull the view off the model.
  TempDir dir("pt-loaders");
  std::string file = dir.write("scene.json", R"({"spheres": [{"center": [1, 2, 3], "radius": 0.5}],
    "lights": [{"type": "point", "position": [40, 30, 20], "intensity": 100}]})");
  JobOptions o;
  o.scene_path = file;
  Job job = prepare_job(o);
  CHECK(job.scene->bounds().center() == Vec3f(1, 2, 3));
  CHECK(Camera::framing(job.scene->bounds(), 4.0f / 3.0f).look_at == Vec3f(1, 2, 3));
  CHECK(job.render.camera.look_at == Vec3f(1, 2, 3));
}

TEST_CASE("JSON: every section of the format") {
  TempDir dir("pt-loaders");
  write_corner_texture((dir.path / "maps" / "wood.png").string());
  write_corner_texture((dir.path / "sky.png").string());
  dir.write("meshes/tri.obj", "v 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\n");
  std::string file = dir.write("scene.json", R"({
    "camera": {"position": [1, 2, 3], "look_at": [0, 0.5, 0], "up": [0, 0, 1], "fov": 50},
    "materials": {
      "matte": {"type": "diffuse", "albedo": [0.25, 0.5, 0.75]},
      "grey": {"albedo": 0.3},
      "wood": {"type": "diffuse", "texture": "maps/wood.png"},
      "chrome": {"type": "mirror", "specular": [0.9, 0.8, 0.7]},
      "glass": {"type": "dielectric", "ior": 1.33},
      "plastic": {"type": "glossy", "albedo": 0.4, "specular": 0.5, "exponent": 200},
      "neon": {"emission": [1, 2, 3], "albedo": 0}
    },
    "objects": [
      {"file": "meshes/tri.obj", "translate": [1, 2, 3], "rotate": [0, 90, 0], "scale": 2, "material": "chrome"},
      {"file": "meshes/tri.obj"}
    ],
    "spheres": [
      {"center": [0, 1, 0], "radius": 0.5, "material": "glass"},
      {"center": [5, 5, 5], "radius": 2}
    ],
    "lights": [
      {"type": "point", "position": [0, 4, 0], "intensity": [10, 20, 30]},
      {"type": "quad", "corners": [[0, 3, 0], [1, 3, 0], [1, 3, 1], [0, 3, 1]], "radiance": 5},
      {"type": "triangle", "corners": [[0, 0, 9], [1, 0, 9], [0, 1, 9]], "radiance": [1, 0.5, 0.25]},
      {"type": "spot", "position": [1, 5, 1], "direction": [0, -2, 0], "intensity": 7, "inner_angle": 20, "outer_angle": 30},
      {"type": "spot", "position": [2, 5, 1], "direction": [1, 0, 0], "intensity": [1, 2, 3]},
      {"type": "directional", "direction": [0, -3, 4], "irradiance": [2, 2, 1]}
    ],
    "environment": {"file": "sky.png", "scale": 2.5, "rotation": 90},
    "render": {"resolution": [320, 200], "spp": 12, "integrator": "path", "seed": 42, "shadow_rays": 3,
               "max_depth": 5, "strategy": "light", "sampler": "independent"},
    "comment": "unknown keys are reported"
  })");
  Scene scene = load_scene(file);

  // camera
  REQUIRE(scene.camera().has_value());
  CHECK(scene.camera()->position == Vec3f(1, 2, 3));
  CHECK(scene.camera()->look_at == Vec3f(0, 0.5f, 0));
  CHECK(scene.camera()->up == Vec3f(0, 0, 1));
  CHECK(scene.camera()->vfov_degrees == 50.0f);

  // materials, by name
  auto find = [&](const std::string& name) -> const Material& {
    for (const Material& m : scene.materials()) {
      if (m.name == name) return m;
    }
    FAIL("no material " << name);
    return scene.materials()[0];
  };
  CHECK(find("matte").is<Diffuse>());
  CHECK(std::get<Diffuse>(find("matte").model).kd == Spectrum(0.25f, 0.5f, 0.75f));
  CHECK(std::get<Diffuse>(find("grey").model).kd == Spectrum(0.3f));
  CHECK(std::get<Diffuse>(find("wood").model).kd_texture >= 0);
  CHECK(std::get<Diffuse>(find("wood").model).kd == Spectrum(1.0f));
  CHECK(find("chrome").is<Mirror>());
  CHECK(std::get<Mirror>(find("chrome").model).ks == Spectrum(0.9f, 0.8f, 0.7f));
  CHECK(find("glass").is<Dielectric>());
  CHECK(std::get<Dielectric>(find("glass").model).ior == doctest::Approx(1.33f));
  CHECK(find("plastic").is<Glossy>());
  CHECK(std::get<Glossy>(find("plastic").model).exponent == 200.0f);
  CHECK(find("neon").emission == Spectrum(1, 2, 3));

  // objects: scale, then rotate (x, y, z order, degrees, right-handed), then translate; the
  // material override applies to every face. Vertex (1,0,0) -> (2,0,0) -> (0,0,-2) -> (1,2,1).
  const Mesh& mesh = scene.mesh();
  REQUIRE(mesh.triangle_count() >= 2);
  Vec3f moved = mesh.vertex(0, 0);
  CHECK(moved.x == doctest::Approx(1.0f));
  CHECK(moved.y == doctest::Approx(2.0f));
  CHECK(moved.z == doctest::Approx(1.0f));
  CHECK(scene.materials()[mesh.material[0]].name == "chrome");
  CHECK(mesh.vertex(1, 0) == Vec3f(1, 0, 0));  // second instance untransformed
  CHECK(scene.materials()[mesh.material[1]].name == "default");

  // spheres
  REQUIRE(scene.spheres().size() == 2);
  CHECK(scene.spheres()[0].radius == 0.5f);
  CHECK(scene.materials()[scene.spheres()[0].material].name == "glass");
  CHECK(scene.materials()[scene.spheres()[1].material].name == "default");

  // lights: the point light, the quad (2 triangles) and the triangle, each emitting toward
  // cross(c1 - c0, c2 - c0): -y for the quad as written, +z for the triangle.
  const LightSet& lights = scene.light_set();
  REQUIRE(lights.points().size() == 1);
  CHECK(lights.points()[0].position == Vec3f(0, 4, 0));
  CHECK(lights.points()[0].intensity == Spectrum(10, 20, 30));
  CHECK(lights.count(LightType::kPoint) == 1);
  CHECK(lights.count(LightType::kTriangle) == 3);
  CHECK(lights.count(LightType::kEnvironment) == 1);
  // Spot cones in degrees (KHR_lights_punctual's defaults: inner 0, outer 45), directions made unit.
  REQUIRE(lights.spots().size() == 2);
  CHECK(lights.spots()[0].direction() == Vec3f(0, -1, 0));
  CHECK(lights.spots()[0].intensity() == Spectrum(7.0f));
  CHECK(lights.spots()[0].cos_inner() == doctest::Approx(std::cos(20 * 3.141592653589793 / 180)));
  CHECK(lights.spots()[0].cos_outer() == doctest::Approx(std::cos(30 * 3.141592653589793 / 180)));
  CHECK(lights.spots()[1].cos_inner() == 1.0f);
  CHECK(lights.spots()[1].cos_outer() == doctest::Approx(std::sqrt(0.5)));
  REQUIRE(lights.directionals().size() == 1);
  CHECK(lights.directionals()[0].direction.y == doctest::Approx(-0.6));
  CHECK(lights.directionals()[0].direction.z == doctest::Approx(0.8));
  CHECK(lights.directionals()[0].irradiance == Spectrum(2, 2, 1));
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  {
    Ray up{{0.5f, 2, 0.5f}, {0, 1, 0}};  // from below the quad
    auto hit = accel->intersect(up);
    REQUIRE(hit.has_value());
    SurfaceInteraction si = scene.interaction(up, *hit);
    CHECK(scene.emitted(si, {0, -1, 0}) == Spectrum(5.0f));
    CHECK(is_black(scene.emitted(si, {0, 1, 0})));
  }

  // environment: an image, scaled and rotated
  REQUIRE(scene.environment().has_value());
  CHECK(scene.environment()->has_image());
  CHECK(scene.environment()->scale() == 2.5f);
  CHECK(scene.environment()->rotation_degrees() == doctest::Approx(90.0f));

  // render settings
  const RenderSettings& s = scene.settings();
  CHECK(s.width == 320);
  CHECK(s.height == 200);
  CHECK(s.spp == 12);
  CHECK(s.integrator == IntegratorKind::kPath);
  CHECK(s.seed == 42);
  CHECK(s.shadow_rays == 3);
  CHECK(s.max_depth == 5);
  CHECK(s.strategy == Strategy::kLight);
  CHECK(s.sampler == SamplerKind::kIndependent);

  // unknown keys reported, once
  CHECK(count_notes(scene, "unknown key 'comment'") == 1);
}

TEST_CASE("JSON: the lat-long environment's orientation") {
  // A 4x2 map whose columns are distinct: u = 0.5 looks toward -z, u = 0.75 toward +x, the top
  // row looks up. The bottom row is black so "down" is told apart from "up".
  TempDir dir("pt-loaders");
  Image img(4, 2, {"R", "G", "B"});
  const Spectrum top[4] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {1, 1, 0}};
  for (int x = 0; x < 4; ++x) {
    for (int c = 0; c < 3; ++c) img.at(x, 0, c) = top[x][c];
  }
  write_image((dir.path / "env.exr").string(), img);
  dir.write("meshes/tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  for (float rotation : {0.0f, 90.0f}) {
    std::string file = dir.write("scene.json", R"({"objects": [{"file": "meshes/tri.obj"}],
      "environment": {"file": "env.exr", "rotation": )" + std::to_string(rotation) + "}}");
    Scene scene = load_scene(file);
    const Environment& env = *scene.environment();
    // Near the zenith (v < half a texel) the lookup clamps to the top row, never blending in
    // the bottom one (the other pole). Column centres are at u = 0.125, 0.375, 0.625, 0.875,
    // and phi = 2 pi (u - 0.5) turns from -z toward +x.
    auto dir_at = [&](float u) {
      // rotation is right-handed about +y: it carries -z toward -x, lowering phi
      float phi = (u - 0.5f) * 2 * kPi - rotation * kPi / 180.0f;
      return Vec3f(std::sin(phi) * 0.2f, 0.98f, -std::cos(phi) * 0.2f);
    };
    CAPTURE(rotation);
    for (int x = 0; x < 4; ++x) {
      Spectrum e = env.eval(normalize(dir_at((x + 0.5f) / 4)));
      for (int c = 0; c < 3; ++c) CHECK(e[c] == doctest::Approx(top[x][c]).epsilon(1e-3).scale(1));
    }
    CHECK(is_black(env.eval({0, -1, 0})));
    // u = 0.5 is -z when unrotated: the boundary between columns 1 and 2 (green and blue).
    if (rotation == 0.0f) {
      Spectrum e = env.eval(normalize(Vec3f(0, 0.98f, -0.2f)));
      CHECK(e.y == doctest::Approx(e.z).epsilon(1e-3));
      CHECK(e.x < 0.05f);
    }
  }
}

TEST_CASE("JSON: paths are relative to the scene file, not the working folder") {
  TempDir dir("pt-loaders");
  write_corner_texture((dir.path / "deep" / "maps" / "t.png").string());
  dir.write("deep/meshes/q.mtl", "newmtl t\nmap_Kd tex.png\n");
  write_corner_texture((dir.path / "deep" / "meshes" / "tex.png").string());
  dir.write("deep/meshes/q.obj", "mtllib q.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 0 1\nusemtl t\nf 1/1 2/2 3/3\n");
  dir.write("deep/scene.json", R"({"objects": [{"file": "meshes/q.obj"}],
                                  "materials": {"m": {"texture": "maps/t.png"}},
                                  "spheres": [{"center": [0, 0, 3], "radius": 1, "material": "m"}]})");
  fs::path old = fs::current_path();
  fs::current_path(dir.path);
  try {
    // Relative to the working folder only in how the scene itself is named.
    LoadOptions unlit;  // no studio ground: count the file's triangles only
    unlit.studio = Studio::kNone;
    Scene scene = load_scene("deep/scene.json", unlit);
    CHECK(scene.textures().size() == 2);
    CHECK(scene.mesh().triangle_count() == 1);
    // And a folder holding scene.json works the same.
    Scene again = load_scene("deep", unlit);
    CHECK(again.mesh().triangle_count() == 1);
  } catch (...) {
    fs::current_path(old);
    throw;
  }
  fs::current_path(old);
}

TEST_CASE("JSON: mistakes are errors naming the file and the place") {
  TempDir dir("pt-loaders");
  dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  struct Case {
    const char* json;
    const char* expect;  // part of the message
  } cases[] = {
      {"{\n  \"camera\": {\"fov\": 40,}\n}", ":2:"},  // syntax error: reports the line
      {R"({"spheres": [{"center": [0, 0, 0], "radius": "big"}]})", "/spheres/0/radius"},
      {R"({"spheres": [{"center": [0, 0, 0], "radius": 1, "material": "nope"}]})", "unknown material 'nope'"},
      {R"({"spheres": [{"radius": 1}]})", "needs 'center'"},
      {R"({"objects": [{"translate": [0, 0, 0]}]})", "needs a 'file'"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "point", "position": [0, 1, 0]}]})", "intensity"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "quad", "corners": [[0,0,0],[1,0,0],[1,1,0]], "radiance": 1}]})", "4 corners"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "spot", "position": [0, 1, 0], "intensity": 1}]})", "'direction'"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, 0, 0], "intensity": 1}]})", "/lights/0/direction: a direction must not be zero"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "intensity": 1, "outer_angle": 95}]})", "/lights/0/outer_angle: expected degrees from 0 to 90"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "spot", "position": [0, 1, 0], "direction": [0, -1, 0], "intensity": 1, "inner_angle": 30, "outer_angle": 30}]})", "/lights/0/inner_angle: the inner angle must be less"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "directional", "irradiance": 1}]})", "needs 'direction' and 'irradiance'"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "directional", "direction": [0, -1, 0], "irradiance": -1}]})", "/lights/0/irradiance: colour components must not be negative"},
      {R"({"objects": [{"file": "tri.obj"}], "lights": [{"type": "area"}]})", "unknown light type 'area' (point, spot, directional, quad, triangle)"},
      {R"({"objects": [{"file": "tri.obj"}], "materials": {"m": {"type": "velvet"}}})", "unknown material type"},
      {R"({"objects": [{"file": "tri.obj"}], "materials": {"m": {"type": "metallic-roughness", "clearcoat": 1.5}}})", "/materials/m/clearcoat: expected a number from 0 to 1"},
      {R"({"objects": [{"file": "tri.obj"}], "materials": {"m": {"type": "metallic-roughness", "roughness": -1}}})", "/materials/m/roughness: expected a number from 0 to 1"},
      {R"({"objects": [{"file": "tri.obj"}], "materials": {"m": {"type": "principled", "base_color": [1, 2, 0]}}})", "/materials/m/base_color: exceeds 1"},
      {R"({"objects": [{"file": "tri.obj"}], "render": {"resolution": [0, 10]}})", "/render/resolution/0"},
      {R"([1, 2, 3])", "JSON object"},
      {R"({})", "no geometry"},
  };
  for (const Case& c : cases) {
    std::string text = c.json;
    CAPTURE(text);
    std::string file = dir.write("bad.json", text);
    try {
      load_scene(file);
      FAIL("expected pt::Error");
    } catch (const Error& e) {
      std::string what = e.what();
      CAPTURE(what);
      CHECK(what.find(file) != std::string::npos);
      CHECK(what.find(c.expect) != std::string::npos);
      CHECK(what.find('\n') == std::string::npos);
    }
  }
  // A missing OBJ is named itself (the error is about that file).
  std::string file = dir.write("bad.json", R"({"objects": [{"file": "missing.obj"}]})");
  CHECK_THROWS_WITH_AS(load_scene(file), doctest::Contains((dir.path / "missing.obj").string().c_str()), Error);
}
