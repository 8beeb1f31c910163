// What exporters write in MTL files and how each reading maps onto pt's materials (the table in
// scenes/README.md): d and Tr as coverage, glass only from illum 4/6/7, the warnings that say
// what changes the picture (once per material), missing textures, normals and uvs as warnings.
#include <doctest/doctest.h>

#include <algorithm>
#include <filesystem>

#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "renderer/render/job.h"
#include "stats.h"
#include "temp_dir.h"

using namespace pt;
namespace fs = std::filesystem;

namespace {

// The file's own triangles: no studio ground.
Scene load_unlit(const std::string& path) {
  LoadOptions o;
  o.studio = Studio::kNone;
  return load_scene(path, o);
}

size_t count_notes(const Scene& scene, const std::string& needle) {
  return std::count_if(scene.notes().begin(), scene.notes().end(),
                       [&](const std::string& n) { return n.find(needle) != std::string::npos; });
}

std::string all_notes(const Scene& scene) {
  std::string out;
  for (const std::string& n : scene.notes()) out += n + "\n";
  return out;
}

// A uniform-colour texture.
void write_flat_texture(const std::string& path, Spectrum colour) {
  Image img(4, 4, {"R", "G", "B"});
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      for (int c = 0; c < 3; ++c) img.at(x, y, c) = colour[c];
    }
  }
  write_image(path, img);
}

// A unit quad in z = 0 facing +z, with uvs, using material `m` of `mtl`.
std::string quad_obj(const TempDir& dir, const std::string& name, const std::string& mtl, const std::string& m) {
  return dir.write(name, "mtllib " + mtl + "\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" +
                             "usemtl " + m + "\nf 1/1 2/2 3/3 4/4\n");
}

// A scene file looking straight at the quad of `obj`, which fills the image, lit by a point light
// (so the default lighting adds nothing).
std::string quad_scene(const TempDir& dir, const std::string& obj, int spp) {
  return dir.write("scene.json", R"({"objects": [{"file": ")" + obj + R"("}],
    "camera": {"position": [0, 0, 4], "look_at": [0, 0, 0], "fov": 20},
    "lights": [{"type": "point", "position": [0, 0, 5], "intensity": 1}],
    "render": {"resolution": [24, 24], "spp": )" + std::to_string(spp) + "}}");
}

}  // namespace

TEST_CASE("MTL: each reading of d, Tr, illum, Kd + Ks and Ke, with one warning line where the picture changes") {
  struct Case {
    const char* what;
    const char* mtl;  // the body of material 'm'
    const char* type;
    float opacity;
    const char* note;  // what the one warning about 'm' says, or "" for none
  } cases[] = {
      {"d is coverage, not glass", "Kd 0.5 0.5 0.5\nd 0.75\nillum 2\n", "diffuse", 0.75f, "'d 0.75' read as coverage"},
      {"d 1 is opaque", "Kd 0.5 0.5 0.5\nd 1\n", "diffuse", 1.0f, ""},
      {"Tr 0 alone is opaque (the MTL convention)", "Kd 0.5 0.5 0.5\nTr 0\n", "diffuse", 1.0f, ""},
      {"Tr 1 alone (MeshLab) is opacity", "Kd 0.8 0.8 0.8\nKs 0 0 0\nTr 1.000000\nillum 2\n", "diffuse",
       1.0f, "'Tr 1' without 'd' read as opacity"},
      {"Tr 0.8 alone: the more visible reading", "Kd 0.5 0.5 0.5\nTr 0.8\n", "diffuse", 0.8f,
       "read as opacity"},
      {"Tr 0.25 alone: transparency", "Kd 0.5 0.5 0.5\nTr 0.25\n", "diffuse", 0.75f,
       "'Tr 0.25' without 'd' read as transparency"},
      {"d wins over Tr (Tr after d)", "Kd 0.5 0.5 0.5\nd 1\nTr 0.5\n", "diffuse", 1.0f, "d wins"},
      {"d wins over Tr (Tr before d)", "Kd 0.5 0.5 0.5\nTr 0.5\nd 0.3\n", "diffuse", 0.3f, "d wins"},
      {"d and Tr agreeing", "Kd 0.5 0.5 0.5\nd 0.6\nTr 0.4\n", "diffuse", 0.6f, "'d 0.6' read as coverage"},
      {"illum 4 is glass; its d is the glass's", "Kd 0.5 0.5 0.5\nd 0.3\nNi 1.33\nillum 4\n", "dielectric",
       1.0f, ""},
      {"illum 6 is glass", "Ni 1.5\nillum 6\n", "dielectric", 1.0f, ""},
      {"illum 7 is glass", "illum 7\n", "dielectric", 1.0f, ""},
      {"illum 3 is a mirror", "Ks 0.9 0.9 0.9\nillum 3\n", "mirror", 1.0f, ""},
      {"Ks makes glossy", "Kd 0.5 0.5 0.5\nKs 0.3 0.3 0.3\nNs 50\nillum 2\n", "glossy", 1.0f, ""},
      {"Kd + Ks above 1 is dimmed, and said", "Kd 0.9 0.5 0.5\nKs 0.6 0.6 0.6\nillum 2\n", "glossy", 1.0f,
       "Kd + Ks reaches 1.5"},
      {"Kd above 1 is dimmed, and said", "Kd 1.25 0.5 0.5\n", "diffuse", 1.0f, "Kd reaches 1.25"},
      {"a light is opaque", "Kd 0 0 0\nKe 4 4 4\nd 0.5\n", "diffuse", 1.0f, "kept opaque"},
      {"Ka is read and ignored, silently", "Ka 1 1 1\nKd 0.5 0.5 0.5\n", "diffuse", 1.0f, ""},
  };
  for (const Case& c : cases) {
    std::string what = c.what;
    CAPTURE(what);
    TempDir dir("pt-mtl");
    // A second, plain material and an emitter keep the default lighting (and its notes) out.
    dir.write("a.mtl", std::string("newmtl m\n") + c.mtl + "newmtl lamp\nKd 0 0 0\nKe 1 1 1\n");
    std::string obj = dir.write("a.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl m\nf 1 2 3\n"
                                         "usemtl lamp\nf 1 3 4\n");
    Scene scene = load_scene(obj);
    const Material& m = scene.materials()[scene.mesh().material[0]];
    REQUIRE(m.name == "m");
    CHECK(std::string(m.type_name()) == c.type);
    CHECK(m.opacity == doctest::Approx(c.opacity));
    CHECK(scene.has_partial_coverage() == (c.opacity < 1.0f));
    std::string notes = all_notes(scene);
    CAPTURE(notes);
    // Every warning about a material names the MTL file and the line of its newmtl.
    std::string place = (dir.path / "a.mtl").string() + ":1: material 'm'";
    if (*c.note) {
      CHECK(scene.notes().size() == 1);
      CHECK(count_notes(scene, place) == 1);
      CHECK(count_notes(scene, c.note) == 1);
    } else {
      CHECK(scene.notes().empty());
    }
    if (std::string(c.type) == "dielectric" && std::string(c.mtl).find("Ni 1.33") != std::string::npos) {
      CHECK(std::get<Dielectric>(m.model).ior == doctest::Approx(1.33f));
    }
  }
}

TEST_CASE("MTL: the Kd + Ks rescale keeps the material's colour and conserves energy") {
  TempDir dir("pt-mtl");
  dir.write("a.mtl", "newmtl m\nKd 0.9 0.5 0.5\nKs 0.6 0.6 0.6\nillum 2\n");
  Scene scene = load_scene(dir.write("a.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl m\nf 1 2 3\n"));
  const Glossy& m = std::get<Glossy>(scene.materials()[scene.mesh().material[0]].model);
  CHECK(m.kd.x == doctest::Approx(0.6f));
  CHECK(m.kd.y == doctest::Approx(0.5f / 1.5f));
  CHECK(m.ks.x == doctest::Approx(0.4f));
  CHECK(max_component(m.kd + m.ks) == doctest::Approx(1.0f));
}

TEST_CASE("MTL: once per material, not per face") {
  TempDir dir("pt-mtl");
  dir.write("a.mtl", "newmtl m\nKd 1.5 1.5 1.5\nd 0.5\nmap_Kd gone.png\n");
  std::string faces;
  for (int i = 0; i < 50; ++i) faces += "f 1 2 3\n";
  std::string obj = dir.write("a.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nusemtl m\n" + faces +
                                           "f 1//1 2//1 3//1\nf 1/1 2/2 3/3\nf 1/1/1 2/1/1 3/1/1\n");
  Scene scene = load_unlit(obj);
  CAPTURE(all_notes(scene));
  CHECK(scene.mesh().triangle_count() == 53);
  CHECK(count_notes(scene, "read as coverage") == 1);
  CHECK(count_notes(scene, "Kd reaches") == 1);
  CHECK(count_notes(scene, "gone.png") == 1);
  CHECK(count_notes(scene, "texture coordinates but the file has none") == 1);
}

TEST_CASE("MTL: a Ka far above 1 without Ke is named when the scene falls back to the default lighting") {
  TempDir dir("pt-mtl");
  dir.write("a.mtl", "newmtl bulb\nKa 20 20 20\nKd 0.8 0.8 0.8\nnewmtl wall\nKa 1 1 1\nKd 0.5 0.5 0.5\n");
  std::string obj = dir.write("a.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl bulb\nf 1 2 3\n"
                                       "usemtl wall\nf 1 3 4\n");
  Scene scene = load_scene(obj);
  CAPTURE(all_notes(scene));
  CHECK(count_notes(scene, (dir.path / "a.mtl").string() + ":1: material 'bulb' has Ka up to 20 and no Ke") == 1);
  CHECK(count_notes(scene, "'wall'") == 0);
  CHECK(count_notes(scene, "MTL keys not supported") == 0);  // Ka is not a key "not supported" any more
  // Where something does emit, the scene is lit as it says and the hint is not needed.
  dir.write("b.mtl", "newmtl bulb\nKa 20 20 20\nKd 0.8 0.8 0.8\nnewmtl lamp\nKe 1 1 1\n");
  Scene lit = load_scene(dir.write("b.obj", "mtllib b.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nusemtl bulb\nf 1 2 3\n"
                                            "usemtl lamp\nf 1 3 4\n"));
  CHECK(lit.notes().empty());
}

TEST_CASE("MTL: a missing texture is a warning naming the MTL line; the material keeps its Kd") {
  TempDir dir("pt-mtl");
  dir.write("a.mtl", "# exported\nnewmtl skin\nKd 0.7 0.5 0.3\nmap_Kd textures/skin.png\n");
  std::string obj = dir.write("a.obj", "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nvt 0 0\nusemtl skin\nf 1/1 2/1 3/1\n");
  Scene scene = load_scene(obj);
  CAPTURE(all_notes(scene));
  CHECK(count_notes(scene, (dir.path / "a.mtl").string() + ":4: texture 'textures/skin.png' not found") == 1);
  CHECK(scene.textures().empty());
  const Diffuse& m = std::get<Diffuse>(scene.materials()[scene.mesh().material[0]].model);
  CHECK(m.kd_texture == -1);
  CHECK(m.kd.x == doctest::Approx(0.7f));
  CHECK(m.kd.z == doctest::Approx(0.3f));
  // A texture that exists but is not an image stays an error (the file is bad, not absent).
  dir.write("textures/skin.png", "not a PNG");
  CHECK_THROWS_AS(load_scene(obj), Error);
}

TEST_CASE("OBJ: faces naming normals or uvs the file does not have load without them, with one warning") {
  TempDir dir("pt-mtl");
  // As OpenSubdiv's catmark_torus_creases0.obj: uvs present, normal indices on every face, no vn.
  std::string torus = dir.write("creases.obj",
                                "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n"
                                "f 1/1/1 2/2/2 3/3/3 4/4/4\nf 2/1/5 5/2/6 6/3/7 3/4/8\nt crease 2/1/0 1 5 4.7\n");
  Scene a = load_unlit(torus);
  CAPTURE(all_notes(a));
  CHECK(a.mesh().triangle_count() == 4);
  CHECK(a.mesh().corner_normals.empty());
  CHECK(a.mesh().corner_uvs.size() == 12);
  CHECK(count_notes(a, torus + ":11: faces name normals but the file has none") == 1);
  // As tinyobjloader's smoothing-group-two-squares.obj: the vn lines are commented out.
  std::string squares = dir.write("squares.obj",
                                  "v 0 2 0\nv 0 0 0\nv 2 0 0\nv 2 2 0\nv 4 0 -3.255298\nv 4 2 -3.255298\n"
                                  "#vn 0 0 1\n#vn 0 0 1\ng all\ns 1\nf 1//1 2//2 3//3 4//4\nf 4//4 3//3 5//5\nf 4//-1 5//-2 6//-3\n");
  Scene b = load_unlit(squares);
  CAPTURE(all_notes(b));
  CHECK(b.mesh().triangle_count() == 4);
  CHECK(b.mesh().corner_normals.empty());
  CHECK(count_notes(b, squares + ":11: faces name normals but the file has none") == 1);
  CHECK(count_notes(b, "normals") == 1);
  // A file that has normals but not the one a face names is still refused, with the line.
  std::string short_of_one = dir.write("short.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//1 2//1 3//2\n");
  CHECK_THROWS_WITH_AS(load_scene(short_of_one), doctest::Contains((short_of_one + ":5:").c_str()), Error);
}

TEST_CASE("MTL: a MeshLab 'Tr 1' textured material renders opaque") {
  TempDir dir("pt-mtl");
  write_flat_texture((dir.path / "albedo.png").string(), Spectrum(0.5f, 0.25f, 0.75f));
  dir.write("q.mtl", "newmtl material_0\nKa 0.200000 0.200000 0.200000\nKd 1.000000 1.000000 1.000000\n"
                     "Ks 1.000000 1.000000 1.000000\nTr 1.000000\nillum 2\nNs 0.000000\nmap_Kd albedo.png\n");
  quad_obj(dir, "q.obj", "q.mtl", "material_0");
  JobOptions o;
  o.scene_path = quad_scene(dir, "q.obj", 4);
  o.integrator = IntegratorKind::kAlbedo;
  Job job = prepare_job(o);
  RenderResult r = render(job);
  // Every sample of every pixel found the quad: its albedo is the texture's (sRGB-decoded) colour.
  Spectrum expected(srgb_decode(std::round(srgb_encode(0.5f) * 255) / 255),
                    srgb_decode(std::round(srgb_encode(0.25f) * 255) / 255),
                    srgb_decode(std::round(srgb_encode(0.75f) * 255) / 255));
  for (int y = 0; y < 24; ++y) {
    for (int x = 0; x < 24; ++x) {
      Spectrum a = r.film.mean(x, y);
      for (int c = 0; c < 3; ++c) CHECK(a[c] == doctest::Approx(expected[c]).epsilon(1e-3));
    }
  }
}

TEST_CASE("MTL: a 'd 0.75' material covers 0.75 of what lies behind it, within error bars") {
  TempDir dir("pt-mtl");
  dir.write("q.mtl", "newmtl lace\nKd 1 1 1\nd 0.75\n");
  quad_obj(dir, "q.obj", "q.mtl", "lace");
  for (const char* backend : {"embree", "bvh"}) {
    CAPTURE(backend);
    JobOptions o;
    o.scene_path = quad_scene(dir, "q.obj", 64);
    o.integrator = IntegratorKind::kAlbedo;
    o.sampler = SamplerKind::kIndependent;
    o.accel.backend = kBackendNames.parse(backend);
    Job job = prepare_job(o);
    REQUIRE(job.scene->has_partial_coverage());
    RenderResult r = render(job);
    // Each sample sees the white quad (albedo 1) or, through it, nothing (albedo 0): a Bernoulli
    // trial with p = the coverage.
    double hits = 0, n = 0;
    for (int y = 0; y < 24; ++y) {
      for (int x = 0; x < 24; ++x) {
        hits += r.film.mean(x, y).x * r.film.count(x, y);
        n += r.film.count(x, y);
      }
    }
    double p = hits / n, se = std::sqrt(0.75 * 0.25 / n);
    INFO("coverage " << p << " +- " << se << " over " << n << " samples");
    CHECK(std::abs(p - 0.75) <= stats::z_bound(1e-4) * se);
    CHECK(se < 0.005);  // the test can tell 0.75 from a neighbour reading (0.7, 0.8)
  }
}

TEST_CASE("JSON: a material's opacity, and lights stay opaque") {
  TempDir dir("pt-mtl");
  dir.write("tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n");
  Scene scene = load_scene(dir.write("a.json", R"({"materials": {"lace": {"opacity": 0.25}},
    "objects": [{"file": "tri.obj", "material": "lace"}]})"));
  CHECK(scene.materials()[scene.mesh().material[0]].opacity == 0.25f);
  CHECK(scene.has_partial_coverage());
  std::string bad = dir.write("b.json", R"({"materials": {"lamp": {"emission": 1, "opacity": 0.5}},
    "objects": [{"file": "tri.obj", "material": "lamp"}]})");
  CHECK_THROWS_WITH_AS(load_scene(bad), doctest::Contains("/materials/lamp/opacity"), Error);
  std::string range = dir.write("c.json", R"({"materials": {"m": {"opacity": 1.5}}, "objects": [{"file": "tri.obj"}]})");
  CHECK_THROWS_WITH_AS(load_scene(range), doctest::Contains("/materials/m/opacity"), Error);
}

TEST_CASE("MTL: texture options with fewer values than three (-o u v, -s u v) keep their texture and mean what they say") {
  TempDir dir("pt-mtl");
  // Four quadrants of different colours, so that an offset, a scale and clamping all show.
  Image img(8, 8, {"R", "G", "B"});
  for (int y = 0; y < 8; ++y) {
    for (int x = 0; x < 8; ++x) {
      img.at(x, y, 0) = x < 4 ? 0.9f : 0.1f;
      img.at(x, y, 1) = y < 4 ? 0.8f : 0.2f;
      img.at(x, y, 2) = 0.5f;
    }
  }
  write_image((dir.path / "tex.png").string(), img);
  const std::string obj = (dir.path / "q.obj").string();
  auto albedo = [&](const std::string& map_line) {
    dir.write("q.mtl", "newmtl m\nKd 1 1 1\n" + map_line + "\n");
    quad_obj(dir, "q.obj", "q.mtl", "m");
    JobOptions o;
    o.scene_path = quad_scene(dir, "q.obj", 4);
    o.integrator = IntegratorKind::kAlbedo;
    RenderResult r = render(prepare_job(o));
    std::vector<float> out;
    for (int y = 0; y < 24; ++y) {
      for (int x = 0; x < 24; ++x) {
        for (int c = 0; c < 3; ++c) out.push_back(r.film.mean(x, y)[c]);
      }
    }
    return out;
  };
  std::vector<float> short_form = albedo("map_Kd -o 0.5 0.5 -s 2 2 -clamp on tex.png");
  {
    Scene scene = load_unlit(obj);
    CAPTURE(all_notes(scene));
    CHECK(scene.textures().size() == 1);
    CHECK(count_notes(scene, "not found") == 0);
  }
  std::vector<float> long_form = albedo("map_Kd -o 0.5 0.5 0 -s 2 2 1 -clamp on tex.png");
  std::vector<float> plain = albedo("map_Kd tex.png");
  CHECK(short_form == long_form);
  CHECK(short_form != plain);
  // An option with no value at all: its default, with a note, and the texture kept.
  std::vector<float> bare = albedo("map_Kd -s tex.png");
  Scene scene = load_unlit(obj);
  CAPTURE(all_notes(scene));
  CHECK(scene.textures().size() == 1);
  CHECK(count_notes(scene, "q.mtl:3: 'map_Kd' option '-s' without a number; read as its default") == 1);
  CHECK(bare == plain);
}
