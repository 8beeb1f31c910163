// glTF 2.0: .gltf with data-URI or external buffers and .glb load the same scene; nodes place
// meshes with matrices or TRS; strips, fans, colours, materials, cameras and lights come through;
// every validation rule refuses its file with the file and a JSON pointer.
#include <doctest/doctest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <fstream>
#include <functional>
#include <iterator>

#include "core/accel/accel.h"
#include "core/image/image.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "gltf_text.h"
#include "temp_dir.h"

using namespace pt;
using nlohmann::json;

namespace {

// One square placed by two nodes (x + 2 and x - 2), a camera at z = 5 and a point light of
// 683 cd above.
GltfText two_squares() {
  GltfText g;
  g.doc["materials"] = {{{"pbrMetallicRoughness", {{"baseColorFactor", {0.5, 0.25, 1.0, 1.0}}, {"metallicFactor", 0.0}}}}};
  int mesh = add_square(g, 0);
  g.doc["nodes"] = {{{"mesh", mesh}, {"translation", {2, 0, 0}}},
                    {{"mesh", mesh}, {"matrix", {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -2, 0, 0, 1}}},
                    {{"camera", 0}, {"translation", {0, 1, 5}}},
                    {{"children", {4}}, {"translation", {0, 3, 0}}},
                    {{"extensions", {{"KHR_lights_punctual", {{"light", 0}}}}}}};
  g.doc["scenes"] = {{{"nodes", {0, 1, 2, 3}}}};
  g.doc["scene"] = 0;
  g.doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 0.5}, {"znear", 0.1}}}}};
  g.doc["extensionsUsed"] = {"KHR_lights_punctual"};
  g.doc["extensions"] = {{"KHR_lights_punctual", {{"lights", {{{"type", "point"}, {"intensity", 683.0}, {"color", {1, 0.5, 0.25}}}}}}}};
  return g;
}

// Makes light 0 of two_squares() a spot light; returns it.
json& spot(GltfText& g) {
  json& l = g.doc["extensions"]["KHR_lights_punctual"]["lights"][0];
  l["type"] = "spot";
  l["spot"] = {{"outerConeAngle", 0.7}};
  return l;
}

std::string error_of(const std::string& path, const LoadOptions& options = {}) {
  try {
    load_scene(path, options);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

void check_two_squares(const Scene& scene) {
  // The square is used by two nodes, so it is stored once and placed twice (instances), not baked.
  const Geometry& geometry = scene.geometry();
  CHECK(geometry.mesh().triangle_count() == 0);
  REQUIRE(geometry.instances().size() == 2);
  CHECK(geometry.objects().size() == 1);
  CHECK(geometry.instance_mesh(0).triangle_count() == 2);
  CHECK(geometry.world_triangle_count() == 4);
  BBox b = geometry.bounds();
  CHECK(b.lo.x == 2 - 4);
  CHECK(b.hi.x == 3);
  REQUIRE(scene.camera().has_value());
  CHECK(scene.camera()->position.z == 5);
  CHECK(scene.camera()->look_at.z == doctest::Approx(4));
  CHECK(scene.camera()->vfov_degrees == doctest::Approx(0.5 * 180 / M_PI));
  // The light: 683 cd of colour (1, 0.5, 0.25) is (1, 0.5, 0.25) W/sr, at its parent's y = 3.
  const std::vector<PointLight>& points = scene.light_set().points();
  REQUIRE(points.size() == 1);
  CHECK(points[0].position.y == 3);
  CHECK(points[0].intensity.x == doctest::Approx(1));
  CHECK(points[0].intensity.z == doctest::Approx(0.25));
  CHECK(!scene.studio().has_value());
  REQUIRE(scene.contents().size() == 1);
  CHECK(scene.contents()[0].find("1 meshes placed by 2 nodes (instances); 2 triangles in the meshes, 4 after instancing") !=
        std::string::npos);
  CHECK(scene.contents()[0].find("extensions used: KHR_lights_punctual") != std::string::npos);
}

}  // namespace

TEST_CASE("glTF: data URI, external buffer and GLB give the same scene") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  check_two_squares(load_scene(dir.write("a.gltf", g.gltf())));
  dir.write("a.bin", g.bin);
  Scene external = load_scene(dir.write("b.gltf", g.gltf_external("a.bin")));
  check_two_squares(external);
  CHECK(std::count(external.inputs().begin(), external.inputs().end(), (dir.path / "a.bin").string()) == 1);
  check_two_squares(load_scene(dir.write("c.glb", g.glb())));
}

TEST_CASE("glTF: the base colour is the diffuse colour; COLOR_0 multiplies it; uv v runs down") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  int colors = g.accessor(std::vector<float>{1, 0, 0, 1, 1, 0, 1, 1, 1, 0, 0, 1, 1, 1, 0, 1}, "VEC4", 5126, 4);
  g.doc["meshes"][0]["primitives"][0]["attributes"]["COLOR_0"] = colors;
  Scene scene = load_scene(dir.write("a.gltf", g.gltf()));
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  Ray ray{{2.01f, 10, -0.01f}, {0, -1, 0}};  // near vertex 0 (red)
  auto hit = accel->intersect(ray);
  REQUIRE(hit.has_value());
  SurfaceInteraction si = scene.interaction(ray, *hit);
  // A rough dielectric's diffuse part: the base colour less the 4% its specular layer reflects.
  CHECK(scene.albedo(si).x == doctest::Approx(0.5 * 0.96).epsilon(0.03));
  CHECK(scene.albedo(si).y == doctest::Approx(0.0).epsilon(0.03));
  CHECK(si.uv.y == doctest::Approx(0.0f).epsilon(0.02));  // glTF v = 1 at vertex 0 is pt's v = 0
  CHECK(si.ns.y == doctest::Approx(1));
}

TEST_CASE("glTF: strips and fans, points skipped with one note, a file of points refused") {
  TempDir dir("pt-gltf");
  for (int mode : {5, 6}) {
    GltfText g;
    // A zig-zag for the strip, a fan around vertex 0 for the fan: every triangle faces +y.
    int pos = mode == 5 ? g.vec3({0, 0, 0, 1, 0, 0, 0, 0, -1, 1, 0, -1, 0, 0, -2})
                        : g.vec3({0, 0, 0, 1, 0, 0, 1, 0, -1, 0, 0, -1, -1, 0, -1});
    g.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"mode", mode}}, {{"attributes", {{"POSITION", pos}}}, {"mode", 0}}}}}};
    g.doc["nodes"] = {{{"mesh", 0}}};
    Scene scene = load_scene(dir.write("s.gltf", g.gltf()));
    CHECK(scene.studio()->first_triangle == 3);  // 5 vertices make 3 triangles, in either mode
    size_t notes = 0;
    for (const std::string& n : scene.notes()) notes += n.find("1 points or lines primitives skipped") != std::string::npos;
    CHECK(notes == 1);
    // A strip's winding alternates so that every triangle faces the same way.
    for (size_t t = 0; t < 3; ++t) CHECK(scene.geometry().mesh().geometric_normal(t).y > 0);
  }
  GltfText points;
  int pos = points.vec3({0, 0, 0, 1, 0, 0, 1, 0, -1});
  points.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}}}, {"mode", 0}}}}}};
  points.doc["nodes"] = {{{"mesh", 0}}};
  std::string path = dir.write("p.gltf", points.gltf());
  CHECK(error_of(path).find("p.gltf: the glTF scene has no triangles (only points or lines)") != std::string::npos);
}

TEST_CASE("glTF: materials: alpha modes, emission with its strength, metals") {
  TempDir dir("pt-gltf");
  GltfText g;
  g.doc["materials"] = {
      {{"alphaMode", "BLEND"}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.25}}}}},
      {{"alphaMode", "MASK"}, {"alphaCutoff", 0.5}, {"pbrMetallicRoughness", {{"baseColorFactor", {1, 1, 1, 0.25}}}}},
      {{"emissiveFactor", {1, 0.5, 0}}, {"extensions", {{"KHR_materials_emissive_strength", {{"emissiveStrength", 4.0}}}}}},
      {{"pbrMetallicRoughness", {{"baseColorFactor", {0.9, 0.8, 0.7, 1}}, {"metallicFactor", 1.0}, {"roughnessFactor", 0.0}}}}};
  g.doc["nodes"] = json::array();
  for (int i = 0; i < 4; ++i) g.doc["nodes"].push_back({{"mesh", add_square(g, i)}, {"translation", {2 * i, 0, 0}}});
  Scene scene = load_scene(dir.write("m.gltf", g.gltf()));
  const auto& mats = scene.materials();
  // By reference: the metals below are read through references into the material.
  auto find = [&](const std::string& name) -> const Material& {
    auto it = std::find_if(mats.begin(), mats.end(), [&](const Material& m) { return m.name == name; });
    REQUIRE(it != mats.end());
    return *it;
  };
  CHECK(find("glTF material 0").opacity == 0.25f);
  CHECK(find("glTF material 1").opacity == 0.0f);
  CHECK(find("glTF material 2").emission.x == 4.0f);
  CHECK(find("glTF material 2").emission.y == 2.0f);
  REQUIRE(find("glTF material 3").is<MetallicRoughness>());
  const MetallicRoughness& metal = std::get<MetallicRoughness>(find("glTF material 3").model);
  CHECK(metal.base_color.y == doctest::Approx(0.8f));
  CHECK(metal.metallic == 1.0f);
  CHECK(metal.roughness == 0.0f);
  // glTF's defaults: a white rough metal.
  const MetallicRoughness& plain = std::get<MetallicRoughness>(find("glTF material 0").model);
  CHECK(plain.metallic == 1.0f);
  CHECK(plain.roughness == 1.0f);
}

TEST_CASE("glTF: KHR_lights_punctual spot and directional lights: pt's units, down the node's -z") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  // Node 4 (at y = 3 under node 3) turned so that its -z points down (-y): 90 degrees about +x.
  double h = std::sqrt(0.5);
  g.doc["nodes"][4]["rotation"] = {-h, 0, 0, h};
  g.doc["nodes"][4]["extensions"]["KHR_lights_punctual"]["light"] = 1;
  g.doc["nodes"].push_back({{"rotation", {-h, 0, 0, h}}, {"extensions", {{"KHR_lights_punctual", {{"light", 2}}}}}});
  g.doc["scenes"][0]["nodes"].push_back(5);
  auto& lights = g.doc["extensions"]["KHR_lights_punctual"]["lights"];
  lights.push_back({{"type", "spot"}, {"intensity", 1366.0}, {"spot", {{"innerConeAngle", 0.25}, {"outerConeAngle", 0.5}}}});
  lights.push_back({{"type", "directional"}, {"intensity", 6830.0}, {"color", {1, 0.5, 0}}, {"range", 4.0}});
  Scene scene = load_scene(dir.write("l.gltf", g.gltf()));
  const LightSet& set = scene.light_set();
  CHECK(set.points().empty());  // light 0 is placed by no node now
  REQUIRE(set.spots().size() == 1);
  const SpotLight& spot = set.spots()[0];
  CHECK(spot.position().y == doctest::Approx(3));
  CHECK(spot.direction().y == doctest::Approx(-1));
  CHECK(spot.intensity().x == doctest::Approx(2));  // 1366 cd / 683 lm/W
  CHECK(spot.cos_inner() == doctest::Approx(std::cos(0.25)));
  CHECK(spot.cos_outer() == doctest::Approx(std::cos(0.5)));
  REQUIRE(set.directionals().size() == 1);
  const DirectionalLight& sun = set.directionals()[0];
  CHECK(sun.direction.y == doctest::Approx(-1));
  CHECK(std::abs(sun.direction.z) < 1e-6f);
  CHECK(sun.irradiance.x == doctest::Approx(10));  // 6830 lux / 683 lm/W
  CHECK(sun.irradiance.y == doctest::Approx(5));
  CHECK(sun.irradiance.z == 0);
  size_t range = 0;
  for (const std::string& n : scene.notes()) range += n.find("'range' is not used") != std::string::npos;
  CHECK(range == 1);
  CHECK(scene.contents()[0].find("2 lights (3 in the file)") != std::string::npos);
}

// A 2x1 8-bit PNG, embedded as a data URI: left texel `left`, right texel `right` (0-255 each).
std::string png_uri(const TempDir& dir, std::array<int, 3> left, std::array<int, 3> right) {
  Image img(2, 1, {"R", "G", "B"});
  for (int c = 0; c < 3; ++c) {
    // write_image encodes 8-bit outputs with the sRGB curve: hand it the decoded value.
    img.at(0, 0, c) = srgb_decode(left[c] / 255.0f);
    img.at(1, 0, c) = srgb_decode(right[c] / 255.0f);
  }
  std::string png = (dir.path / "t.png").string();
  write_image(png, img);
  std::ifstream in(png, std::ios::binary);
  std::string bytes(std::istreambuf_iterator<char>(in), {});
  in.close();
  std::filesystem::remove(png);
  return "data:image/png;base64," + GltfText::base64(bytes);
}

TEST_CASE("glTF: pbrMetallicRoughness is the metallic-roughness model; metallicRoughnessTexture is data (B metallic, G roughness)") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  g.doc["images"] = {{{"uri", png_uri(dir, {0, 128, 64}, {0, 255, 255})}}};
  g.doc["textures"] = {{{"source", 0}}};
  auto& pbr = g.doc["materials"][0]["pbrMetallicRoughness"];
  pbr["baseColorFactor"] = {0.5, 0.25, 1, 1};
  pbr["metallicFactor"] = 0.5;
  pbr["roughnessFactor"] = 0.8;
  pbr["metallicRoughnessTexture"] = {{"index", 0}};
  Scene scene = load_scene(dir.write("mr.gltf", g.gltf()));
  const Material& m = scene.materials()[0];
  REQUIRE(m.is<MetallicRoughness>());
  const MetallicRoughness& mr = std::get<MetallicRoughness>(m.model);
  CHECK(mr.base_color.y == 0.25f);
  CHECK(mr.base_color_texture < 0);
  REQUIRE(mr.metallic_roughness_texture >= 0);
  // The data texture holds the file's values, not their sRGB decoding (128 -> 0.502, not 0.216).
  // The left texel's centre, with no footprint: the texel itself.
  Spectrum data = scene.textures().lookup(mr.metallic_roughness_texture, {0.25f, 0.5f}, {0.0f, 0.0f}, {0.0f, 0.0f});
  CHECK(data.y == doctest::Approx(128 / 255.0).epsilon(1e-5));
  CHECK(data.z == doctest::Approx(64 / 255.0).epsilon(1e-5));
  // At the left texel's centre the BSDF has roughness 0.8 x 0.502, metallic 0.5 x 0.251.
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  for (auto [x, left] : {std::pair{2.25f, true}, {2.75f, false}}) {
    Ray ray{{x, 10, -0.5f}, {0, -1, 0}};
    auto hit = accel->intersect(ray);
    REQUIRE(hit.has_value());
    Bsdf b = scene.bsdf(scene.interaction(ray, *hit));
    REQUIRE(std::holds_alternative<MetallicRoughnessBsdf>(b.model()));
    const auto& at = std::get<MetallicRoughnessBsdf>(b.model());
    CHECK(at.roughness == doctest::Approx(0.8 * (left ? 128 : 255) / 255.0).epsilon(1e-5));
    CHECK(at.metallic == doctest::Approx(0.5 * (left ? 64 : 255) / 255.0).epsilon(1e-5));
    CHECK(at.base_color.x == 0.5f);
  }
  // A metallicRoughnessTexture on another uv set than the base colour's is left out, with a note.
  g.doc["images"].push_back({{"uri", png_uri(dir, {255, 255, 255}, {255, 255, 255})}});
  g.doc["textures"].push_back({{"source", 1}});
  pbr["baseColorTexture"] = {{"index", 1}};
  pbr["metallicRoughnessTexture"] = {{"index", 0}, {"texCoord", 1}};
  Scene other = load_scene(dir.write("mr1.gltf", g.gltf()));
  CHECK(std::get<MetallicRoughness>(other.materials()[0].model).metallic_roughness_texture < 0);
  size_t notes = 0;
  for (const std::string& n : other.notes()) notes += n.find("metallicRoughnessTexture: on TEXCOORD_1") != std::string::npos;
  CHECK(notes == 1);
}

TEST_CASE("glTF: KHR_materials_clearcoat's factors are the model's coat (its textures named as not used); KHR_materials_ior its ior") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  g.doc["extensionsUsed"] = {"KHR_materials_clearcoat"};
  g.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"] = {
      {"clearcoatFactor", 0.75}, {"clearcoatRoughnessFactor", 0.125}, {"clearcoatNormalTexture", {{"index", 0}}}};
  Scene scene = load_scene(dir.write("cc.gltf", g.gltf()));
  const MetallicRoughness& mr = std::get<MetallicRoughness>(scene.materials()[0].model);
  CHECK(mr.clearcoat == 0.75f);
  CHECK(mr.clearcoat_roughness == 0.125f);
  size_t notes = 0;
  for (const std::string& n : scene.notes()) notes += n.find("KHR_materials_clearcoat textures are not used") != std::string::npos;
  CHECK(notes == 1);
  CHECK(scene.contents()[0].find("extensions used: KHR_materials_clearcoat") != std::string::npos);
  // KHR_materials_ior sets the dielectric's F0.
  g.doc["materials"][0]["extensions"]["KHR_materials_ior"] = {{"ior", 2.0}};
  CHECK(std::get<MetallicRoughness>(load_scene(dir.write("ior.gltf", g.gltf())).materials()[0].model).ior == 2.0f);
  // Without the extensions: no coat, ior 1.5.
  g.doc["materials"][0].erase("extensions");
  Scene plain = load_scene(dir.write("plain.gltf", g.gltf()));
  CHECK(std::get<MetallicRoughness>(plain.materials()[0].model).clearcoat == 0.0f);
  CHECK(std::get<MetallicRoughness>(plain.materials()[0].model).ior == 1.5f);
}

TEST_CASE("glTF: cameras: the first by default, --camera N, orthographic with its film size") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  g.doc["cameras"].push_back({{"type", "perspective"}, {"perspective", {{"yfov", 1.0}, {"znear", 0.1}}}});
  g.doc["cameras"].push_back({{"type", "orthographic"}, {"orthographic", {{"xmag", 1.0}, {"ymag", 1.0}, {"znear", 0.1}, {"zfar", 10.0}}}});
  g.doc["nodes"].push_back({{"camera", 1}, {"translation", {0, 0, 9}}});
  g.doc["nodes"].push_back({{"camera", 2}, {"translation", {0, 0, 9}}});
  g.doc["scenes"][0]["nodes"] = {0, 1, 2, 3, 5, 6};
  std::string path = dir.write("c.gltf", g.gltf());
  CHECK(load_scene(path).camera()->position.z == 5);
  LoadOptions pick;
  pick.camera = 1;
  CHECK(load_scene(path, pick).camera()->position.z == 9);
  pick.camera = 2;
  Scene ortho = load_scene(path, pick);
  REQUIRE(ortho.camera()->orthographic());
  CHECK(ortho.camera()->ortho_height == doctest::Approx(2.0f));  // 2 ymag
  // Its rays run parallel, from the film: the centre ray from the camera, the corner ones 1 unit up
  // and 1 across (xmag 1).
  Camera::Basis b = ortho.camera()->basis(1.0f);
  Ray centre = Camera::ray(b, {0.5f, 0.5f}), corner = Camera::ray(b, {0.0f, 0.0f});
  CHECK(centre.o.z == doctest::Approx(9.0f));
  CHECK(corner.d.z == doctest::Approx(-1.0f));
  CHECK(corner.o.x == doctest::Approx(-1.0f));
  CHECK(corner.o.y == doctest::Approx(1.0f));
  pick.camera = 7;
  CHECK(error_of(path, pick).find("--camera 7: the file has 3 cameras") != std::string::npos);
}

TEST_CASE("glTF: every validation rule refuses its file with a JSON pointer") {
  TempDir dir("pt-gltf");
  struct Case {
    std::string name;
    std::function<void(GltfText&)> change;
    std::string expected;
  };
  std::vector<Case> cases = {
      {"version", [](GltfText& g) { g.doc["asset"]["version"] = "1.0"; }, "/asset/version: '1.0'"},
      {"required", [](GltfText& g) { g.doc["extensionsRequired"] = {"KHR_texture_basisu"}; },
       "/extensionsRequired/0: the file requires extension 'KHR_texture_basisu'"},
      {"unsupported required", [](GltfText& g) { g.doc["extensionsRequired"] = {"KHR_materials_sheen"}; },
       "/extensionsRequired/0: the file requires extension 'KHR_materials_sheen'"},
      {"draco only", [](GltfText& g) {
         json& p = g.doc["meshes"][0]["primitives"][0];
         p["attributes"].erase("POSITION");
         p["extensions"] = {{"KHR_draco_mesh_compression", {{"bufferView", 0}, {"attributes", {{"POSITION", 0}}}}}};
       }, "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression/bufferView: buffer view 0 does not hold a Draco triangle mesh"},
      {"count", [](GltfText& g) { g.doc["accessors"][0]["count"] = 5; }, "/accessors/0/count: 5 elements of 12 bytes"},
      {"offset", [](GltfText& g) { g.doc["accessors"][0]["byteOffset"] = 4; }, "/accessors/0/count"},
      {"view", [](GltfText& g) { g.doc["bufferViews"][0]["byteLength"] = 100000; }, "/bufferViews/0/byteLength"},
      {"index", [](GltfText& g) { g.doc["accessors"][3]["count"] = 6; g.bin[g.bin.size() - 2] = 9; },
       "/accessors/3: index 9 (element 5) but the primitive has 4 vertices"},
      {"cycle", [](GltfText& g) { g.doc["nodes"][3]["children"] = {4}; g.doc["nodes"][4]["children"] = {3}; },
       "/nodes/3: is its own ancestor (the node tree has a cycle)"},
      {"self", [](GltfText& g) { g.doc["nodes"][4]["children"] = {4}; }, "/nodes/4/children/0: node 4 is its own child"},
      {"shared", [](GltfText& g) { g.doc["nodes"][2]["children"] = {4}; }, "/nodes/3/children/0: node 4 already has parent 2"},
      {"root", [](GltfText& g) { g.doc["scenes"][0]["nodes"].push_back(4); }, "/scenes/0/nodes/4: node 4 is a child of node 3"},
      {"mesh", [](GltfText& g) { g.doc["nodes"][0]["mesh"] = 7; }, "/nodes/0/mesh: refers to 7, but there are 1"},
      {"material", [](GltfText& g) { g.doc["meshes"][0]["primitives"][0]["material"] = 3; }, "/meshes/0/primitives/0/material"},
      {"nan", [](GltfText& g) { float nan = NAN; std::memcpy(&g.bin[4], &nan, 4); }, "/accessors/0: POSITION element 0 is not a finite number"},
      {"attribute count", [](GltfText& g) { g.doc["accessors"][1]["count"] = 3; }, "/meshes/0/primitives/0/attributes/NORMAL: 3 elements"},
      {"normal type", [](GltfText& g) { g.doc["accessors"][1]["type"] = "VEC2"; }, "/accessors/1/type: NORMAL with 2 components"},
      {"sparse", [](GltfText& g) {
         g.doc["accessors"][0]["sparse"] = {{"count", 1}, {"indices", {{"bufferView", 3}, {"componentType", 5123}}}, {"values", {{"bufferView", 0}}}};
       }, "/accessors/0/sparse: sparse accessors are not supported"},
      {"light", [](GltfText& g) { g.doc["nodes"][4]["extensions"]["KHR_lights_punctual"]["light"] = 5; },
       "/nodes/4/extensions/KHR_lights_punctual/light"},
      {"light type", [](GltfText& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["type"] = "area"; },
       "/extensions/KHR_lights_punctual/lights/0/type: unknown light type 'area'"},
      {"outer cone", [](GltfText& g) { spot(g)["spot"]["outerConeAngle"] = 2.0; },
       "/extensions/KHR_lights_punctual/lights/0/spot/outerConeAngle: expected radians in (0, pi/2]"},
      {"inner cone", [](GltfText& g) { spot(g)["spot"] = {{"innerConeAngle", 0.5}, {"outerConeAngle", 0.5}}; },
       "/extensions/KHR_lights_punctual/lights/0/spot/innerConeAngle"},
      {"negative cone", [](GltfText& g) { spot(g)["spot"]["innerConeAngle"] = -0.1; },
       "/extensions/KHR_lights_punctual/lights/0/spot/innerConeAngle"},
      {"range", [](GltfText& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["range"] = -1; },
       "/extensions/KHR_lights_punctual/lights/0/range"},
      {"intensity", [](GltfText& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = -1; },
       "/extensions/KHR_lights_punctual/lights/0/intensity"},
      {"light colour", [](GltfText& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = {1, -1, 0}; },
       "/extensions/KHR_lights_punctual/lights/0/color: components must not be negative"},
      {"spot without cone", [](GltfText& g) { spot(g).erase("spot"); },
       "/extensions/KHR_lights_punctual/lights/0/spot: a spot light needs its cone ('spot')"},
      {"light direction", [](GltfText& g) { spot(g); g.doc["nodes"][4]["scale"] = {0, 0, 0}; },
       "/nodes/4: the transform of a spot light leaves it no direction"},
      {"yfov", [](GltfText& g) { g.doc["cameras"][0]["perspective"]["yfov"] = 4.0; }, "/cameras/0/perspective/yfov"},
      {"base colour", [](GltfText& g) { g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {2, 0, 0, 1}; },
       "/materials/0/pbrMetallicRoughness/baseColorFactor: components must be from 0 to 1"},
      {"metallic", [](GltfText& g) { g.doc["materials"][0]["pbrMetallicRoughness"]["metallicFactor"] = 1.5; },
       "/materials/0/pbrMetallicRoughness/metallicFactor: must be from 0 to 1"},
      {"roughness", [](GltfText& g) { g.doc["materials"][0]["pbrMetallicRoughness"]["roughnessFactor"] = -0.5; },
       "/materials/0/pbrMetallicRoughness/roughnessFactor: must be from 0 to 1"},
      {"metallic-roughness texture", [](GltfText& g) { g.doc["materials"][0]["pbrMetallicRoughness"]["metallicRoughnessTexture"] = {{"index", 2}}; },
       "/materials/0/pbrMetallicRoughness/metallicRoughnessTexture/index: refers to 2, but there are 0"},
      {"alpha mode", [](GltfText& g) { g.doc["materials"][0]["alphaMode"] = "SOMETIMES"; }, "/materials/0/alphaMode"},
      {"ior", [](GltfText& g) { g.doc["materials"][0]["extensions"]["KHR_materials_ior"] = {{"ior", 0.5}}; },
       "/materials/0/extensions/KHR_materials_ior/ior: expected a number from 1 up (or 0)"},
      {"clearcoat", [](GltfText& g) { g.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"] = {{"clearcoatFactor", 2}}; },
       "/materials/0/extensions/KHR_materials_clearcoat/clearcoatFactor: expected a number from 0 to 1"},
      {"clearcoat roughness",
       [](GltfText& g) { g.doc["materials"][0]["extensions"]["KHR_materials_clearcoat"] = {{"clearcoatRoughnessFactor", "rough"}}; },
       "/materials/0/extensions/KHR_materials_clearcoat/clearcoatRoughnessFactor: expected a number from 0 to 1"},
      {"triangles", [](GltfText& g) { g.doc["accessors"][3]["count"] = 5; }, "/meshes/0/primitives/0: 5 vertices is not a whole number"},
      {"image", [](GltfText& g) { g.doc["images"] = {{{"uri", "missing.png"}}}; }, "/images/0/uri:"},
      {"image view", [](GltfText& g) { g.doc["images"] = {{{"bufferView", 99}, {"mimeType", "image/png"}}}; },
       "/images/0/bufferView: no such buffer view"},
      {"image source", [](GltfText& g) { g.doc["images"] = {{{"uri", "a.png"}, {"bufferView", 0}}}; },
       "/images/0: needs either 'uri' or 'bufferView'"},
      {"view buffer", [](GltfText& g) { g.doc["bufferViews"][0]["buffer"] = 3; }, "/bufferViews/0/buffer: no buffer 3"},
      {"texture source", [](GltfText& g) { g.doc["textures"] = {{{"source", 4}}}; }, "/textures/0/source: refers to 4, but there are 0"},
      {"scene", [](GltfText& g) { g.doc["scene"] = 3; }, "/scene: refers to scene 3"},
      {"uri scheme", [](GltfText& g) { g.doc["images"] = {{{"uri", "http://127.0.0.1:9/a.png"}}}; },
       "/images/0/uri: 'http://127.0.0.1:9/a.png': pt reads data: URIs and file paths, not http: URIs"},
      {"file scheme", [](GltfText& g) { g.doc["images"] = {{{"uri", "file:///tmp/a.png"}}}; }, "/images/0/uri: 'file:///tmp/a.png'"},
      {"matrix and TRS", [](GltfText& g) { g.doc["nodes"][1]["translation"] = {0, 1, 0}; },
       "/nodes/1: has both a matrix and translation, rotation or scale"},
      {"projective matrix", [](GltfText& g) { g.doc["nodes"][1]["matrix"][3] = 0.5; },
       "/nodes/1/matrix: not an affine transform (its bottom row must be 0 0 0 1)"},
      {"wrap mode", [](GltfText& g) { g.doc["samplers"] = {{{"wrapS", 12345}}}; },
       "/samplers/0/wrapS: unknown wrap mode 12345"},
      {"integer positions", [](GltfText& g) { g.doc["accessors"][0]["componentType"] = 5123; },
       "/meshes/0/primitives/0/attributes/POSITION: integer positions need KHR_mesh_quantization"},
      {"uri NUL", [](GltfText& g) { g.doc["images"] = {{{"uri", "a.png%00.jpg"}}}; },
       "/images/0/uri: encodes a NUL byte (%00), which no file name holds"},
      // Found by attack (each crashed, overran a buffer or allocated without bound before).
      {"normal texture", [](GltfText& g) { g.doc["materials"][0]["normalTexture"] = {{"index", 7}}; },
       "/materials/0/normalTexture/index: refers to 7, but there are 0"},
      {"occlusion texture", [](GltfText& g) { g.doc["materials"][0]["occlusionTexture"] = {{"index", 2}}; },
       "/materials/0/occlusionTexture/index: refers to 2, but there are 0"},
      {"texture sampler", [](GltfText& g) {
         g.doc["images"] = {{{"uri", "data:image/png;base64,AAAA"}}};
         g.doc["textures"] = {{{"source", 0}, {"sampler", 5}}};
       }, "/textures/0/sampler: refers to 5, but there are 0"},
      {"zeros overflow", [](GltfText& g) {
         g.doc["accessors"][0].erase("bufferView");
         g.doc["accessors"][0]["count"] = 6148914691236517206ull;  // (2^64 + 2) / 3: 3 floats each wrap around
       }, "/accessors/0/count: 6148914691236517206 elements without a bufferView (zeros) would take more than"},
      {"zeros huge", [](GltfText& g) {
         g.doc["accessors"][0].erase("bufferView");
         g.doc["accessors"][0]["count"] = 30000000;
       }, "/accessors/0/count: 30000000 elements without a bufferView"},
      {"image media type", [](GltfText& g) { g.doc["images"] = {{{"uri", "data:image/webp;base64,UklGRg=="}}}; },
       "/images/0/uri: a data: URI of type 'image/webp;base64' (pt reads image/png and image/jpeg, base64)"},
      {"light overflow", [](GltfText& g) { g.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = 1e300; },
       "/extensions/KHR_lights_punctual/lights/0/intensity: expected a number from 0 to 1e30"},
      {"light colour overflow", [](GltfText& g) {
         g.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["color"] = {1e20, 1, 1};
         g.doc["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"] = 1e20;
       }, "/extensions/KHR_lights_punctual/lights/0/color: color times intensity is above 1e30"},
      {"emission overflow", [](GltfText& g) {
         g.doc["materials"][0]["emissiveFactor"] = {1e38, 0, 0};
         g.doc["materials"][0]["extensions"]["KHR_materials_emissive_strength"] = {{"emissiveStrength", 1e300}};
       }, "/materials/0/extensions/KHR_materials_emissive_strength/emissiveStrength: emissiveFactor times emissiveStrength is above 1e30"},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    GltfText g = two_squares();
    c.change(g);
    std::string path = dir.write("bad.gltf", g.gltf());
    std::string e = error_of(path);
    CHECK_MESSAGE(e.find(path + ": " + c.expected) != std::string::npos, e);
  }
  GltfText g = two_squares();
  // The buffer's bytes against its declared length, in each form.
  json d = json::parse(g.gltf());
  d["buffers"][0]["byteLength"] = g.bin.size() + 4;
  std::string path = dir.write("len.gltf", d.dump());
  CHECK(error_of(path).find(path + ": /buffers/0/byteLength: " + std::to_string(g.bin.size() + 4) + " bytes, but the data URI holds") !=
        std::string::npos);
  path = dir.write("ext.gltf", g.gltf_external("nowhere.bin"));
  CHECK(error_of(path).find(path + ": /buffers/0/uri:") != std::string::npos);
  CHECK(error_of(path).find("no such file") != std::string::npos);
  std::string glb = g.glb();
  path = dir.write("cut.glb", glb.substr(0, glb.size() - 8));
  CHECK(error_of(path).find(path + ": GLB: the header says") != std::string::npos);
  path = dir.write("empty.glb", "");
  CHECK(error_of(path).find(path + ": the file is empty (0 bytes)") != std::string::npos);
  path = dir.write("json.gltf", "{\"asset\": ");
  CHECK(error_of(path).find(path + ": not valid JSON") != std::string::npos);
}

TEST_CASE("glTF: deep JSON is refused without recursion; a long chain of nodes loads in linear time") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  // 50,000 nested arrays in `extras` (100 KB) overflowed the stack in tinygltf's copy of them.
  std::string text = g.gltf();
  REQUIRE(text.front() == '{');
  const size_t depth = 50000;
  std::string deep = "{\"extras\": " + std::string(depth, '[') + std::string(depth, ']') + ", " + text.substr(1);
  std::string path = dir.write("deep.gltf", deep);
  CHECK_MESSAGE(error_of(path).find(path + ": JSON nested more than 256 levels deep") != std::string::npos, error_of(path));
  // Nesting glTF itself uses (a few levels, and extras a little deeper) is fine.
  std::string shallow = "{\"extras\": " + std::string(100, '[') + std::string(100, ']') + ", " + text.substr(1);
  path = dir.write("shallow.gltf", shallow);
  check_two_squares(load_scene(path));
  // A chain of 100,000 nodes under the light's node: validated once per node (walking each node's
  // ancestors took 10 s), and placed without recursion.
  const int chain = 100000;
  int first = static_cast<int>(g.doc["nodes"].size());
  for (int i = 0; i < chain; ++i) {
    json node = json::object();
    if (i + 1 < chain) node["children"] = {first + i + 1};
    g.doc["nodes"].push_back(node);
  }
  g.doc["nodes"][4]["children"] = {first};
  path = dir.write("chain.gltf", g.gltf());
  check_two_squares(load_scene(path));
  // The same chain, taken from under the light and closed into a loop, is a cycle.
  g.doc["nodes"][4].erase("children");
  g.doc["nodes"][first + chain - 1]["children"] = {first};
  path = dir.write("loop.gltf", g.gltf());
  CHECK_MESSAGE(error_of(path).find("the node tree has a cycle") != std::string::npos, error_of(path));
}

TEST_CASE("glTF: optional extensions not understood are named once each; required ones pt knows load") {
  TempDir dir("pt-gltf");
  GltfText g = two_squares();
  g.doc["extensionsUsed"] = {"KHR_lights_punctual", "KHR_materials_sheen", "EXT_unknown"};
  g.doc["extensionsRequired"] = {"KHR_lights_punctual"};
  Scene scene = load_scene(dir.write("x.gltf", g.gltf()));
  size_t sheen = 0, unknown = 0;
  for (const std::string& n : scene.notes()) {
    sheen += n.find("'KHR_materials_sheen' is not supported") != std::string::npos;
    unknown += n.find("'EXT_unknown' is not supported") != std::string::npos;
  }
  CHECK(sheen == 1);
  CHECK(unknown == 1);
  CHECK(scene.contents()[0].find("ignored: KHR_materials_sheen EXT_unknown") != std::string::npos);
}

TEST_CASE("glTF: an occlusion texture and textures on a uv set the primitive lacks are named, not dropped silently") {
  TempDir dir("pt-gltf");
  Image img(1, 1, {"R", "G", "B"});
  std::string png = (dir.path / "t.png").string();
  write_image(png, img);
  std::string bytes;
  {
    std::ifstream in(png, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  auto notes_of = [&](GltfText& g) {
    g.doc["images"] = {{{"uri", "data:image/png;base64," + GltfText::base64(bytes)}}};
    g.doc["textures"] = {{{"source", 0}}};
    std::string all;
    const Scene scene = load_scene(dir.write("t.gltf", g.gltf()));  // notes() refers into it
    for (const std::string& n : scene.notes()) all += n + "\n";
    return all;
  };
  GltfText g = two_squares();
  g.doc["materials"][0]["occlusionTexture"] = {{"index", 0}};
  CHECK(notes_of(g).find("occlusionTexture is not used") != std::string::npos);
  GltfText h = two_squares();
  h.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}, {"texCoord", 1}};
  const std::string notes = notes_of(h);
  CHECK_MESSAGE(notes.find("/meshes/0/primitives/0: material 0's textures use TEXCOORD_1, which the primitive does not have") !=
                    std::string::npos,
                notes);
  GltfText k = two_squares();
  k.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  CHECK(notes_of(k).find("which the primitive does not have") == std::string::npos);  // TEXCOORD_0 is there
}

TEST_CASE("glTF: an embedded PNG base colour texture is read by pt's image code") {
  TempDir dir("pt-gltf");
  // A 2x1 texture: left red, right blue.
  Image img(2, 1, {"R", "G", "B"});
  img.at(0, 0, 0) = 1;
  img.at(1, 0, 2) = 1;
  std::string png = (dir.path / "t.png").string();
  write_image(png, img);
  std::string bytes;
  {
    std::ifstream in(png, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  GltfText g = two_squares();
  g.doc["images"] = {{{"uri", "data:image/png;base64," + GltfText::base64(bytes)}}};
  g.doc["textures"] = {{{"source", 0}}};
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 1};
  std::filesystem::remove(png);
  Scene scene = load_scene(dir.write("t.gltf", g.gltf()));
  REQUIRE(scene.textures().size() == 1);
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  for (auto [x, red] : {std::pair{2.25f, true}, {2.75f, false}}) {  // texel centres
    Ray ray{{x, 10, -0.5f}, {0, -1, 0}};
    auto hit = accel->intersect(ray);
    REQUIRE(hit.has_value());
    Spectrum a = scene.albedo(scene.interaction(ray, *hit));
    CHECK((red ? a.x : a.z) > 0.7f);
  }
}

namespace {
// two_squares() with an embedded 2x1 RGBA texture (left texel `left`, right `right`) as texture 0.
GltfText with_texture(const std::array<float, 4>& left, const std::array<float, 4>& right, const TempDir& dir) {
  Image img(2, 1, {"R", "G", "B", "A"});
  for (int c = 0; c < 4; ++c) img.at(0, 0, c) = left[c], img.at(1, 0, c) = right[c];
  std::string png = (dir.path / "rgba.png").string();
  write_image(png, img);
  std::string bytes;
  std::ifstream in(png, std::ios::binary);
  bytes.assign(std::istreambuf_iterator<char>(in), {});
  GltfText g = two_squares();
  g.doc["images"] = {{{"uri", "data:image/png;base64," + GltfText::base64(bytes)}}};
  g.doc["textures"] = {{{"source", 0}, {"sampler", 0}}};
  g.doc["samplers"] = {{{"wrapS", 33071}, {"wrapT", 33071}}};  // clamp: no blending across the edges
  return g;
}
}  // namespace

TEST_CASE("glTF: base colour alpha is coverage under MASK (cut) and BLEND (a fraction)") {
  TempDir dir("pt-gltf");
  GltfText g = with_texture({1, 1, 1, 1}, {1, 1, 1, 0.2f}, dir);
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorTexture"] = {{"index", 0}};
  g.doc["materials"][0]["pbrMetallicRoughness"]["baseColorFactor"] = {1, 1, 1, 0.5};
  for (const char* mode : {"MASK", "BLEND"}) {
    CAPTURE(mode);
    g.doc["materials"][0]["alphaMode"] = mode;
    g.doc["materials"][0]["alphaCutoff"] = 0.3;
    Scene scene = load_scene(dir.write("a.gltf", g.gltf()));
    CHECK(scene.has_partial_coverage());
    auto accel = make_accel(scene.geometry(), AccelOptions{});
    std::vector<float> seen;
    for (float x : {2.25f, 2.75f}) {  // texel centres: alpha 1 and 0.2, times the factor's 0.5
      Ray ray{{x, 10, -0.5f}, {0, -1, 0}};
      auto hit = accel->intersect(ray);
      REQUIRE(hit.has_value());
      seen.push_back(scene.opacity(ray, *hit));
    }
    if (std::string(mode) == "MASK") {
      CHECK(seen[0] == 1.0f);  // 0.5 >= 0.3
      CHECK(seen[1] == 0.0f);  // 0.1 < 0.3
    } else {
      CHECK(seen[0] == doctest::Approx(0.5f).epsilon(0.01));
      CHECK(seen[1] == doctest::Approx(0.1f).epsilon(0.05));
    }
  }
}

TEST_CASE("glTF: an emissive texture: what a surface emits where it is hit is what its light samples send") {
  TempDir dir("pt-gltf");
  GltfText g = with_texture({1, 0, 0, 1}, {0, 0, 1, 1}, dir);
  g.doc["materials"][0]["emissiveFactor"] = {2, 2, 2};
  g.doc["materials"][0]["emissiveTexture"] = {{"index", 0}};
  g.doc["materials"][0].erase("pbrMetallicRoughness");
  // No point light: every light sample is then one of the textured triangles.
  g.doc["nodes"][4] = json::object();
  g.doc.erase("extensions");
  g.doc.erase("extensionsUsed");
  // Facing down: the squares' front face is +y; look from above.
  Scene scene = load_scene(dir.write("e.gltf", g.gltf()));
  REQUIRE(scene.light_set().count(LightType::kTriangle) > 0);
  auto accel = make_accel(scene.geometry(), AccelOptions{});
  for (float x : {2.25f, 2.75f}) {
    Ray ray{{x, 10, -0.5f}, {0, -1, 0}};
    auto hit = accel->intersect(ray);
    REQUIRE(hit.has_value());
    Spectrum e = scene.emitted(scene.interaction(ray, *hit), {0, 1, 0});
    CHECK(e.x == doctest::Approx(x < 2.5f ? 2.0f : 0.0f).scale(1).epsilon(0.02));
    CHECK(e.z == doctest::Approx(x < 2.5f ? 0.0f : 2.0f).scale(1).epsilon(0.02));
  }
  // Every light sample sends what the surface emits at the point it chose.
  const Vec3f p{1.0f, 3.0f, -0.3f};
  int checked = 0;
  for (int i = 0; i < 400; ++i) {
    LightSample ls;
    const float u = (i + 0.5f) / 400.0f;
    if (!scene.sample_light(p, {0, -1, 0}, u, {std::fmod(u * 7.31f, 1.0f), std::fmod(u * 3.17f, 1.0f)}, ls)) continue;
    if (ls.delta) continue;
    Ray ray{p, ls.wi};
    auto hit = accel->intersect(ray);
    REQUIRE(hit.has_value());
    Spectrum e = scene.emitted(scene.interaction(ray, *hit), -ls.wi);
    CHECK(ls.radiance.x == doctest::Approx(e.x).scale(1).epsilon(0.02));
    CHECK(ls.radiance.z == doctest::Approx(e.z).scale(1).epsilon(0.02));
    ++checked;
  }
  CHECK(checked > 100);
}
