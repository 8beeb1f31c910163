#include "renderer/tools/gen_instances.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/math/rng.h"
#include "core/math/transform.h"
#include "core/scene/gltf_file.h"
#include "core/scene/loader.h"
#include "core/util/error.h"
#include "core/util/output_file.h"

namespace pt {
namespace fs = std::filesystem;

namespace {

std::string matrix_json(const Transform& t) {
  std::string out = "[";
  char buf[32];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 4; ++j) {
      std::snprintf(buf, sizeof buf, "%s%.9g", i + j > 0 ? ", " : "", static_cast<double>(t.m[i][j]));
      out += buf;
    }
  }
  return out + "]";
}

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\') out += '\\';
    if (static_cast<unsigned char>(c) < 0x20) throw Error(s, "a file name with a control character cannot go into a scene file");
    out += c;
  }
  return out + "\"";
}

bool ends_with(const std::string& s, const std::string& tail) {
  return s.size() >= tail.size() && s.compare(s.size() - tail.size(), tail.size(), tail) == 0;
}

// glTF's column-major 4x4 of a 3x4 affine transform.
nlohmann::json gltf_matrix(const Transform& t) {
  nlohmann::json m = nlohmann::json::array();
  for (int j = 0; j < 4; ++j) {
    for (int i = 0; i < 4; ++i) m.push_back(i < 3 ? static_cast<double>(t.m[i][j]) : (j == 3 ? 1.0 : 0.0));
  }
  return m;
}

// The field as one binary glTF: the mesh stored once, one node per copy naming it (a mesh used by
// several nodes is instanced by the loader) or, flattened, one mesh entry per copy over the same
// accessors (each used once, so each is baked into world space).
std::string field_glb(const Mesh& mesh, const std::vector<Transform>& placements, bool flatten, const Vec3f& eye,
                      const Vec3f& target) {
  using nlohmann::json;
  std::string bin;
  auto append = [&bin](const void* data, size_t bytes) {
    bin.append(static_cast<const char*>(data), bytes);
    while (bin.size() % 4) bin.push_back('\0');  // the next view starts 4-byte aligned
  };
  append(mesh.positions.data(), mesh.positions.size() * sizeof(Vec3f));
  const size_t position_bytes = bin.size();
  append(mesh.indices.data(), mesh.indices.size() * sizeof(uint32_t));
  BBox b = mesh.bounds();
  json doc;
  doc["asset"] = {{"version", "2.0"}, {"generator", "pt gen instances"}};
  doc["buffers"] = {{{"byteLength", bin.size()}}};
  doc["bufferViews"] = {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", mesh.positions.size() * sizeof(Vec3f)}, {"target", 34962}},
                        {{"buffer", 0}, {"byteOffset", position_bytes}, {"byteLength", mesh.indices.size() * sizeof(uint32_t)}, {"target", 34963}}};
  doc["accessors"] = {{{"bufferView", 0}, {"componentType", 5126}, {"count", mesh.positions.size()}, {"type", "VEC3"},
                       {"min", {b.lo.x, b.lo.y, b.lo.z}}, {"max", {b.hi.x, b.hi.y, b.hi.z}}},
                      {{"bufferView", 1}, {"componentType", 5125}, {"count", mesh.indices.size()}, {"type", "SCALAR"}}};
  const json primitive = {{"attributes", {{"POSITION", 0}}}, {"indices", 1}};
  doc["meshes"] = json::array();
  for (size_t k = 0; k < (flatten ? placements.size() : 1); ++k) doc["meshes"].push_back({{"primitives", {primitive}}});
  json nodes = json::array(), roots = json::array();
  for (size_t k = 0; k < placements.size(); ++k) {
    nodes.push_back({{"mesh", flatten ? k : 0}, {"matrix", gltf_matrix(placements[k])}});
    roots.push_back(k);
  }
  // The camera looks down its -z: columns right, up, back and the eye.
  Vec3f back = normalize(eye - target), right = normalize(cross(Vec3f(0, 1, 0), back)), up = cross(back, right);
  Transform view;
  for (int i = 0; i < 3; ++i) {
    view.m[i][0] = right[i], view.m[i][1] = up[i], view.m[i][2] = back[i], view.m[i][3] = eye[i];
  }
  nodes.push_back({{"camera", 0}, {"matrix", gltf_matrix(view)}});
  roots.push_back(placements.size());
  doc["nodes"] = nodes;
  doc["cameras"] = {{{"type", "perspective"}, {"perspective", {{"yfov", 40.0 * M_PI / 180.0}, {"znear", 0.01}}}}};
  doc["scenes"] = {{{"nodes", roots}}};
  doc["scene"] = 0;
  return glb_container(doc.dump(), bin);
}

}  // namespace

void write_instance_field(const std::string& path, const InstanceFieldOptions& o) {
  if (o.count < 1) throw Error("pt gen instances: --count must be at least 1");
  const bool glb = ends_with(path, ".glb");
  if (!glb && !ends_with(path, ".json")) throw Error(path, "pt gen instances writes a .json scene or a .glb file");
  // The mesh's bounds set the spacing; the file names it relative to the scene's folder.
  SceneBuilder probe;
  probe.source = o.mesh;
  Mesh mesh;
  load_obj(probe, o.mesh, Transform(), -1, &mesh);
  if (mesh.triangle_count() == 0) throw Error(o.mesh, "has no triangles to place");
  BBox b = mesh.bounds();
  float radius = 0.5f * length(b.extent());
  Vec3f center = b.center();
  fs::path folder = fs::absolute(path).parent_path();
  std::string mesh_name = fs::absolute(o.mesh).lexically_normal().lexically_relative(folder).string();
  if (mesh_name.empty()) mesh_name = fs::absolute(o.mesh).string();

  // A square grid of cells 2.2 radii wide, each copy jittered in its cell, turned about +y, scaled
  // by 0.7 to 1.3 and standing on y = 0.
  int side = static_cast<int>(std::ceil(std::sqrt(static_cast<double>(o.count))));
  float spacing = 2.2f * radius, width = side * spacing;
  Pcg32 rng(o.seed, 0x1f3d);
  std::vector<Transform> placements;
  for (int k = 0; k < o.count; ++k) {
    float s = 0.7f + 0.6f * rng.next_float();
    float turn = 360.0f * rng.next_float();
    float x = (static_cast<float>(k % side) + 0.5f) * spacing - 0.5f * width + (rng.next_float() - 0.5f) * 0.3f * radius;
    float z = (static_cast<float>(k / side) + 0.5f) * spacing - 0.5f * width + (rng.next_float() - 0.5f) * 0.3f * radius;
    float lift = s * (center.y - b.lo.y);
    placements.push_back(Transform::translate({x, lift, z}) * Transform::rotate_axis(1, turn) * Transform::scale(Vec3f(s)) *
                         Transform::translate(-center));
  }

  const Vec3f eye(0.0f, 0.4f * width, 0.75f * width), target(0.0f, 0.0f, -0.1f * width);
  if (glb) {
    if (mesh.positions.size() > UINT32_MAX / sizeof(Vec3f) || mesh.indices.size() > UINT32_MAX / 8) {
      throw Error(o.mesh, "is too large for one glTF buffer");
    }
    OutputFile out(path);
    out.write(field_glb(mesh, placements, o.flatten, eye, target));
    out.commit();
    return;
  }
  std::string text = "{\n";
  char buf[256];
  std::snprintf(buf, sizeof buf, "  \"camera\": {\"position\": [%.9g, %.9g, %.9g], \"look_at\": [0, 0, %.9g], \"fov\": 40},\n",
                0.0, 0.4 * width, 0.75 * width, -0.1 * width);
  text += buf;
  text += "  \"objects\": [\n";
  if (o.flatten) {
    for (size_t k = 0; k < placements.size(); ++k) {
      text += "    {\"file\": " + json_string(mesh_name) + ", \"matrix\": " + matrix_json(placements[k]) + "}";
      text += k + 1 < placements.size() ? ",\n" : "\n";
    }
  } else {
    text += "    {\"file\": " + json_string(mesh_name) + ", \"instances\": [\n";
    for (size_t k = 0; k < placements.size(); ++k) {
      text += "      {\"matrix\": " + matrix_json(placements[k]) + "}";
      text += k + 1 < placements.size() ? ",\n" : "\n";
    }
    text += "    ]}\n";
  }
  text += "  ]\n}\n";
  OutputFile out(path);
  out.write(text);
  out.commit();
}

}  // namespace pt
