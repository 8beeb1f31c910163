// MTL's PBR extension as Blender 3.4's OBJ exporter writes it ("PBR Extensions" on) onto the
// metallic-roughness model (core/scene/obj_loader.cpp, the table in scenes/README.md): Kd, Pr, Pm,
// Pc, Pcr, Ks as the Principled BSDF's Specular, Ke; map_Kd and map_Ke as colour, map_Pr and map_Pm
// as data; the keys the model does not have (Ps, aniso, anisor, Tf) named in one warning; classic
// MTL materials keep their old mapping.
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>

#include "core/accel/accel.h"
#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "temp_dir.h"

using namespace pt;

namespace {

Scene load_unlit(const std::string& path) {
  LoadOptions o;
  o.studio = Studio::kNone;
  return load_scene(path, o);
}

const Material& find(const Scene& scene, const std::string& name) {
  auto it = std::find_if(scene.materials().begin(), scene.materials().end(), [&](const Material& m) { return m.name == name; });
  REQUIRE(it != scene.materials().end());
  return *it;
}

std::string all_notes(const Scene& scene) {
  std::string out;
  for (const std::string& n : scene.notes()) out += n + "\n";
  return out;
}

// An 8-bit PNG of one value per channel, as stored in the file (0-255).
void write_png(const std::string& path, int r, int g, int b) {
  Image img(4, 4, {"R", "G", "B"});
  for (int y = 0; y < 4; ++y) {
    for (int x = 0; x < 4; ++x) {
      img.at(x, y, 0) = srgb_decode(r / 255.0f);  // write_image sRGB-encodes 8-bit files
      img.at(x, y, 1) = srgb_decode(g / 255.0f);
      img.at(x, y, 2) = srgb_decode(b / 255.0f);
    }
  }
  write_image(path, img);
}

std::string quad_obj(const TempDir& dir, const std::string& mtl, const std::string& m) {
  return dir.write("quad.obj", "mtllib " + mtl + "\nv -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n" +
                                   "usemtl " + m + "\nf 1/1 2/2 3/3 4/4\n");
}

float f0_of(float ior) {
  float s = (ior - 1) / (ior + 1);
  return s * s;
}

}  // namespace

TEST_CASE("MTL PBR: Blender 3.4's export of a Principled BSDF is the metallic-roughness model") {
  TempDir dir("pt-mtl-pbr");
  // What Blender 3.4.1 wrote for a Principled BSDF (base colour, metallic 0.8, roughness 0.3,
  // specular 0.6, sheen 0.2, clearcoat 0.4 / 0.1, anisotropic 0.25 / 0.1, emission (0.5, 0.2, 0.1)
  // x 2, IOR 1.45, transmission 0.3) with "PBR Extensions" on.
  dir.write("gold.mtl", R"(# Blender 3.4.1 MTL File: 'None'
# www.blender.org

newmtl Gold
Kd 1.000000 0.780000 0.340000
Ks 0.600000 0.600000 0.600000
Ke 1.000000 0.400000 0.200000
Ni 1.450000
d 1.000000
illum 3
Pr 0.300000
Pm 0.800000
Ps 0.200000
Pc 0.400000
Pcr 0.100000
aniso 0.250000
anisor 0.100000
Tf 0.300000 0.300000 0.300000
)");
  Scene scene = load_unlit(quad_obj(dir, "gold.mtl", "Gold"));
  const Material& m = find(scene, "Gold");
  REQUIRE(m.is<MetallicRoughness>());  // not a mirror, whatever illum 3 says
  const MetallicRoughness& mr = std::get<MetallicRoughness>(m.model);
  CHECK(mr.base_color.y == doctest::Approx(0.78f));
  CHECK(mr.metallic == doctest::Approx(0.8f));
  CHECK(mr.roughness == doctest::Approx(0.3f));
  CHECK(f0_of(mr.ior) == doctest::Approx(0.08 * 0.6).epsilon(1e-4));  // Specular 0.6; Ni is refraction only
  CHECK(mr.clearcoat == doctest::Approx(0.4f));  // Pc
  CHECK(mr.clearcoat_roughness == doctest::Approx(0.1f));  // Pcr
  CHECK(m.emission.y == doctest::Approx(0.4f));
  CHECK(m.opacity == 1.0f);
  std::string notes = all_notes(scene);
  INFO(notes);
  CHECK(notes.find("ignoring MTL keys not supported") != std::string::npos);
  std::string ignored = notes.substr(notes.find("ignoring MTL keys not supported"));
  ignored = ignored.substr(0, ignored.find('\n'));
  CHECK(ignored.find("Ps, Tf, aniso, anisor") != std::string::npos);
  for (const char* used : {"Pr", "Pm", "Pc,", "Pcr"}) CHECK(ignored.find(used) == std::string::npos);
}

TEST_CASE("MTL PBR: map_Kd and map_Ke are colour, map_Pr and map_Pm are data and replace Pr and Pm; map_Bump is the bump map") {
  TempDir dir("pt-mtl-pbr");
  write_png((dir.path / "c.png").string(), 200, 100, 50);
  write_png((dir.path / "r.png").string(), 64, 64, 64);
  write_png((dir.path / "m.png").string(), 255, 255, 255);
  write_png((dir.path / "e.png").string(), 10, 10, 10);
  write_png((dir.path / "n.png").string(), 128, 128, 255);
  // Blender 3.4.1's export with those five images linked (it writes no Kd, Pr, Pm or Ke then).
  dir.write("t.mtl", R"(newmtl Textured
Ni 1.450000
illum 3
Ps 0.200000
map_Kd c.png
map_Pm m.png
map_Ks s.png
map_Pr r.png
map_Ke e.png
map_Bump -bm 0.700000 n.png
)");
  Scene scene = load_unlit(quad_obj(dir, "t.mtl", "Textured"));
  const MetallicRoughness& mr = std::get<MetallicRoughness>(find(scene, "Textured").model);
  REQUIRE(mr.base_color_texture >= 0);
  REQUIRE(mr.roughness_texture >= 0);
  REQUIRE(mr.metallic_texture >= 0);
  CHECK(mr.roughness == 1.0f);
  CHECK(mr.metallic == 1.0f);
  CHECK(f0_of(mr.ior) == doctest::Approx(0.04).epsilon(1e-4));  // no Ks: Blender's default Specular 0.5
  // The base colour is decoded from sRGB; roughness is the file's value.
  auto texel = [&](int slot) { return scene.textures().lookup(slot, {0.5f, 0.5f}, {0.0f, 0.0f}, {0.0f, 0.0f}); };
  CHECK(texel(mr.base_color_texture).x == doctest::Approx(srgb_decode(200 / 255.0f)).epsilon(1e-5));
  CHECK(texel(mr.roughness_texture).x == doctest::Approx(64 / 255.0).epsilon(1e-5));
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  Ray ray{{0.1f, 0.2f, 5.0f}, {0, 0, -1}};
  auto hit = accel->intersect(ray);
  REQUIRE(hit.has_value());
  Bsdf b = scene.bsdf(scene.interaction(ray, *hit));
  const auto& at = std::get<MetallicRoughnessBsdf>(b.model());
  CHECK(at.roughness == doctest::Approx(64 / 255.0).epsilon(1e-5));
  CHECK(at.metallic == doctest::Approx(1.0).epsilon(1e-5));
  CHECK(at.base_color.y == doctest::Approx(srgb_decode(100 / 255.0f)).epsilon(1e-4));
  std::string notes = all_notes(scene);
  INFO(notes);
  for (const char* key : {"map_Ks", "Ps"}) CHECK(notes.find(key) != std::string::npos);
  CHECK(notes.find("map_Ke") == std::string::npos);
  // map_Bump is read whatever the model (core/scene/mtl_maps.h). Blender writes its Normal Map
  // node there (and reads map_Bump back as one): this one's texels are normals, (128, 128, 255),
  // so it is a normal map of strength -bm, with a note; a grey one below stays a height map.
  CHECK(notes.find("map_Bump") == std::string::npos);
  CHECK(notes.find("t.mtl:10: bump map 'n.png' of material 'Textured' holds tangent-space normals") != std::string::npos);
  const Material& textured = find(scene, "Textured");
  CHECK(textured.bump_texture == -1);
  CHECK(textured.normal_texture >= 0);
  CHECK(textured.normal_scale == doctest::Approx(0.7f));
  CHECK(scene.materials().size() == 1);
  // map_Ke without Ke (Blender writes no Ke with a textured emission): the texture at strength 1,
  // as Blender's importer reads it; seen from the front, sRGB-decoded.
  REQUIRE(textured.is_emissive());
  REQUIRE(textured.emission_texture >= 0);
  CHECK(textured.emission == Spectrum(1.0f));
  SurfaceInteraction si = scene.interaction(ray, *hit);
  CHECK(scene.emitted(si, -ray.d).x == doctest::Approx(srgb_decode(10 / 255.0f)).epsilon(1e-4));
  CHECK(scene.emitted(si, ray.d).x == 0.0f);
  // A grey map_Bump (a height map, as the MTL format means it) stays one, without a note.
  write_png((dir.path / "h.png").string(), 128, 128, 128);
  dir.write("h.mtl", "newmtl Bumpy\nKd 0.5 0.5 0.5\nmap_Bump -bm 0.3 h.png\n");
  Scene bumpy = load_unlit(quad_obj(dir, "h.mtl", "Bumpy"));
  CHECK(find(bumpy, "Bumpy").bump_texture >= 0);
  CHECK(find(bumpy, "Bumpy").bump_scale == doctest::Approx(0.3f));
  CHECK(find(bumpy, "Bumpy").normal_texture == -1);
  CHECK(all_notes(bumpy).find("tangent-space normals") == std::string::npos);
}

TEST_CASE("MTL: map_Ke multiplies Ke, keeps the material opaque, and a missing map_Ke file is a note naming its line") {
  TempDir dir("pt-mtl-map-ke");
  write_png((dir.path / "e.png").string(), 255, 128, 0);
  dir.write("k.mtl", "newmtl Sign\nKd 0.5 0.5 0.5\nKe 4 4 4\nmap_Ke e.png\n"
                     "newmtl Lost\nKd 0.5 0.5 0.5\nKe 2 2 2\nmap_Ke gone.png\n"
                     "newmtl Glow\nd 0.5\nmap_Ke e.png\n");
  Scene scene = load_unlit(quad_obj(dir, "k.mtl", "Sign"));
  REQUIRE(find(scene, "Sign").emission_texture >= 0);
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  Ray ray{{0.1f, 0.2f, 5.0f}, {0, 0, -1}};
  auto hit = accel->intersect(ray);
  REQUIRE(hit.has_value());
  Spectrum le = scene.emitted(scene.interaction(ray, *hit), -ray.d);
  CHECK(le.x == doctest::Approx(4.0f).epsilon(1e-4));
  CHECK(le.y == doctest::Approx(4.0f * srgb_decode(128 / 255.0f)).epsilon(1e-4));
  CHECK(le.z == 0.0f);
  std::string notes = all_notes(scene);
  INFO(notes);
  CHECK(notes.find("k.mtl:11: emits light (map_Ke), so material 'Glow' is kept opaque") != std::string::npos);
  CHECK(find(scene, "Glow").opacity == 1.0f);
  CHECK(find(scene, "Glow").emission_texture >= 0);
  CHECK(notes.find("k.mtl:8: texture 'gone.png' not found; material 'Lost' emits its Ke") != std::string::npos);
  CHECK(find(scene, "Lost").emission_texture == -1);
  CHECK(find(scene, "Lost").emission == Spectrum(2.0f));
}

TEST_CASE("MTL PBR: roughness from Ns without Pr; classic materials keep their mapping; Pr and Pm are checked") {
  TempDir dir("pt-mtl-pbr");
  dir.write("m.mtl", R"(newmtl half
Kd 0.5 0.5 0.5
Ns 250
Pm 1
newmtl classic
Kd 0.5 0.5 0.5
Ks 0.3 0.3 0.3
Ns 100
illum 2
newmtl plain_pbr
Kd 0.2 0.4 0.6
Pm 0
)");
  std::string obj = dir.write("q.obj", "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\n"
                                       "usemtl half\nf 1 2 3\nusemtl classic\nf 1 3 4\nusemtl plain_pbr\nf 2 5 6\n");
  Scene scene = load_unlit(obj);
  const MetallicRoughness& half = std::get<MetallicRoughness>(find(scene, "half").model);
  CHECK(half.roughness == doctest::Approx(0.5));  // 1 - sqrt(250 / 1000)
  CHECK(half.metallic == 1.0f);
  CHECK(find(scene, "classic").is<Glossy>());
  const MetallicRoughness& plain = std::get<MetallicRoughness>(find(scene, "plain_pbr").model);
  CHECK(plain.roughness == 1.0f);  // neither Pr nor Ns: glTF's default
  CHECK(plain.metallic == 0.0f);

  for (const char* bad : {"Pr 1.5", "Pm -0.1", "Pr nan", "Pc 2", "Pcr -1"}) {
    CAPTURE(bad);
    dir.write("bad.mtl", std::string("newmtl x\nKd 1 1 1\n") + bad + "\n");
    std::string path = dir.write("bad.obj", "mtllib bad.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nusemtl x\nf 1 2 3\n");
    std::string message;
    try {
      load_unlit(path);
    } catch (const Error& e) {
      message = e.what();
    }
    CHECK(message.find("bad.mtl:3:") != std::string::npos);
  }
}
