// KHR_draco_mesh_compression: a primitive compressed with libdraco's encoder loads as the mesh it
// was made from (positions and texture coordinates with their points), and malformed Draco data or
// accessors that disagree with it refuse the file with a JSON pointer.
#include <doctest/doctest.h>
#include <draco/compression/decode.h>
#include <draco/compression/encode.h>
#include <draco/mesh/triangle_soup_mesh_builder.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>

#include "core/accel/accel.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "gltf_text.h"
#include "temp_dir.h"

using namespace pt;
using nlohmann::json;

namespace {

constexpr int kCells = 4;  // a kCells x kCells grid of squares on y = 0 over [0, 1]^2, uv = (x, z)

struct Encoded {
  std::string bytes;
  int position_id = -1, uv_id = -1;
  size_t points = 0, faces = 0;
};

Encoded encode_grid() {
  draco::TriangleSoupMeshBuilder builder;
  builder.Start(2 * kCells * kCells);
  const int pos = builder.AddAttribute(draco::GeometryAttribute::POSITION, 3, draco::DT_FLOAT32);
  const int uv = builder.AddAttribute(draco::GeometryAttribute::TEX_COORD, 2, draco::DT_FLOAT32);
  int face = 0;
  auto corner = [](int i, int j) { return std::array<float, 2>{float(i) / kCells, float(j) / kCells}; };
  for (int i = 0; i < kCells; ++i) {
    for (int j = 0; j < kCells; ++j) {
      const std::array<float, 2> c[2][3] = {{corner(i, j), corner(i, j + 1), corner(i + 1, j + 1)},
                                            {corner(i, j), corner(i + 1, j + 1), corner(i + 1, j)}};
      for (const auto& tri : c) {
        float p[3][3], t[3][2];
        for (int k = 0; k < 3; ++k) p[k][0] = tri[k][0], p[k][1] = 0, p[k][2] = tri[k][1], t[k][0] = tri[k][0], t[k][1] = tri[k][1];
        builder.SetAttributeValuesForFace(pos, draco::FaceIndex(face), p[0], p[1], p[2]);
        builder.SetAttributeValuesForFace(uv, draco::FaceIndex(face), t[0], t[1], t[2]);
        ++face;
      }
    }
  }
  std::unique_ptr<draco::Mesh> mesh = builder.Finalize();
  REQUIRE(mesh);
  draco::Encoder encoder;
  encoder.SetAttributeQuantization(draco::GeometryAttribute::POSITION, 14);
  encoder.SetAttributeQuantization(draco::GeometryAttribute::TEX_COORD, 12);
  draco::EncoderBuffer out;
  REQUIRE(encoder.EncodeMeshToBuffer(*mesh, &out).ok());
  Encoded e;
  e.bytes.assign(out.data(), out.size());
  e.position_id = static_cast<int>(mesh->attribute(pos)->unique_id());
  e.uv_id = static_cast<int>(mesh->attribute(uv)->unique_id());
  // What the file's accessors must say: the decoded mesh's counts (the encoder may merge points).
  draco::DecoderBuffer in;
  in.Init(e.bytes.data(), e.bytes.size());
  draco::Decoder decoder;
  auto decoded = decoder.DecodeMeshFromBuffer(&in);
  REQUIRE(decoded.ok());
  e.points = decoded.value()->num_points();
  e.faces = decoded.value()->num_faces();
  return e;
}

// A glTF whose one primitive is the Draco grid, required, with accessors holding no buffer view.
GltfText draco_grid(const Encoded& e) {
  GltfText g;
  g.bin = e.bytes;
  g.doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", e.bytes.size()}}};
  g.doc["accessors"] = {{{"componentType", 5126}, {"count", e.points}, {"type", "VEC3"}},
                        {{"componentType", 5126}, {"count", e.points}, {"type", "VEC2"}},
                        {{"componentType", 5125}, {"count", 3 * e.faces}, {"type", "SCALAR"}}};
  json draco = {{"bufferView", 0}, {"attributes", {{"POSITION", e.position_id}, {"TEXCOORD_0", e.uv_id}}}};
  g.doc["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", 0}, {"TEXCOORD_0", 1}}},
                                       {"indices", 2},
                                       {"extensions", {{"KHR_draco_mesh_compression", draco}}}}}}}};
  g.doc["nodes"] = {{{"mesh", 0}}};
  g.doc["scenes"] = {{{"nodes", {0}}}};
  g.doc["extensionsUsed"] = {"KHR_draco_mesh_compression"};
  g.doc["extensionsRequired"] = {"KHR_draco_mesh_compression"};
  return g;
}

std::string error_of(const std::string& path) {
  try {
    load_scene(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace

TEST_CASE("glTF: a Draco-compressed primitive loads as the mesh it was made from") {
  TempDir dir("pt-draco");
  Encoded e = encode_grid();
  REQUIRE(e.faces == 2 * kCells * kCells);
  for (bool glb : {false, true}) {
    CAPTURE(glb);
    GltfText g = draco_grid(e);
    Scene scene = glb ? load_scene(dir.write("d.glb", g.glb())) : load_scene(dir.write("d.gltf", g.gltf()));
    const Mesh& mesh = scene.geometry().mesh();
    size_t grid = 0;
    double area = 0;
    for (size_t t = 0; t < mesh.triangle_count(); ++t) {
      Vec3f p[3];
      for (int k = 0; k < 3; ++k) p[k] = mesh.positions[mesh.indices[3 * t + k]];
      bool in_grid = true;  // not the studio's ground
      for (const Vec3f& q : p) in_grid = in_grid && std::abs(q.y) < 1e-3f && q.x > -1e-3f && q.x < 1.001f && q.z > -1e-3f && q.z < 1.001f;
      if (!in_grid) continue;
      ++grid;
      area += 0.5 * length(cross(p[1] - p[0], p[2] - p[0]));
    }
    CHECK(grid == e.faces);
    CHECK(area == doctest::Approx(1.0).epsilon(1e-3));
    // Each point keeps its own texture coordinate: the file's uv = (x, z) wherever a ray lands
    // (pt's v runs up, glTF's down: v = 1 - z).
    auto accel = make_accel(scene.geometry(), AccelOptions{});
    for (auto [x, z] : {std::pair{0.3f, 0.7f}, {0.81f, 0.12f}, {0.55f, 0.45f}}) {
      Ray ray{{x, 1, z}, {0, -1, 0}};
      auto hit = accel->intersect(ray);
      REQUIRE(hit.has_value());
      CHECK(hit->t == doctest::Approx(1.0f).epsilon(1e-3));
      SurfaceInteraction si = scene.interaction(ray, *hit);
      CHECK(si.uv.x == doctest::Approx(x).epsilon(2e-3));
      CHECK(si.uv.y == doctest::Approx(1.0f - z).epsilon(2e-3));
    }
  }
}

TEST_CASE("glTF: malformed Draco data, or accessors that disagree with it, refuse the file with a JSON pointer") {
  TempDir dir("pt-draco");
  Encoded e = encode_grid();
  const std::string ext = "/meshes/0/primitives/0/extensions/KHR_draco_mesh_compression";
  struct Case {
    const char* name;
    std::function<void(GltfText&)> mutate;
    std::string expect;
  };
  const std::vector<Case> cases = {
      {"truncated", [&](GltfText& g) { g.bin.resize(12), g.doc["bufferViews"][0]["byteLength"] = 12; }, ext + "/bufferView: "},
      {"not Draco", [&](GltfText& g) { std::fill(g.bin.begin(), g.bin.end(), 'x'); }, ext + "/bufferView: "},
      {"view out of range", [](GltfText& g) { g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["bufferView"] = 9; },
       ext + "/bufferView: refers to 9"},
      {"unknown attribute id",
       [](GltfText& g) { g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"]["TEXCOORD_0"] = 7; },
       ext + "/attributes/TEXCOORD_0: the Draco mesh has no attribute 7"},
      {"attribute not in the primitive", [](GltfText& g) { g.doc["meshes"][0]["primitives"][0]["attributes"].erase("TEXCOORD_0"); },
       ext + "/attributes/TEXCOORD_0: the primitive's attributes have no TEXCOORD_0"},
      {"no POSITION", [](GltfText& g) { g.doc["meshes"][0]["primitives"][0]["extensions"]["KHR_draco_mesh_compression"]["attributes"].erase("POSITION"); },
       ext + "/attributes: no POSITION"},
      {"point count", [&](GltfText& g) { g.doc["accessors"][0]["count"] = e.points + 1; }, "/accessors/0/count: "},
      {"index count", [&](GltfText& g) { g.doc["accessors"][2]["count"] = 3; }, "/accessors/2/count: 3 indices"},
      {"matrix attribute", [](GltfText& g) { g.doc["accessors"][1]["type"] = "MAT4"; }, "/accessors/1/type: "},
      {"lines", [](GltfText& g) { g.doc["meshes"][0]["primitives"][0]["mode"] = 1; }, "/meshes/0/primitives/0/mode: "},
  };
  for (const Case& c : cases) {
    CAPTURE(c.name);
    GltfText g = draco_grid(e);
    c.mutate(g);
    std::string path = dir.write("bad.gltf", g.gltf());
    std::string error = error_of(path);
    CHECK(error.find(path) != std::string::npos);
    CHECK(error.find(c.expect) != std::string::npos);
    CAPTURE(error);
  }
}

TEST_CASE("glTF: mutated Draco data loads or is refused with pt::Error, never anything else") {
  TempDir dir("pt-draco");
  Encoded e = encode_grid();
  std::mt19937 rng(7);
  int loaded = 0, refused = 0;
  for (int i = 0; i < 300; ++i) {
    GltfText g = draco_grid(e);
    for (int k = 1 + static_cast<int>(rng() % 4); k > 0; --k) {
      const size_t at = rng() % g.bin.size();
      if (rng() % 2) {
        g.bin[at] = static_cast<char>(rng());
      } else {
        g.bin[at] = static_cast<char>(g.bin[at] ^ (1 << (rng() % 8)));
      }
    }
    std::string path = dir.write("m.gltf", g.gltf());
    try {
      load_scene(path);
      ++loaded;
    } catch (const Error& error) {
      CHECK(std::string(error.what()).find(path) != std::string::npos);
      ++refused;
    }
  }
  CHECK(loaded + refused == 300);
  CHECK(refused > 0);  // the mutations reach the decoder's checks
  MESSAGE(loaded << " mutants loaded, " << refused << " refused");
}
