#include "renderer/tools/gen_instances.h"

#include <cmath>
#include <cstdio>
#include <filesystem>

#include "core/math/rng.h"
#include "core/math/transform.h"
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

}  // namespace

void write_instance_field(const std::string& path, const InstanceFieldOptions& o) {
  if (o.count < 1) throw Error("pt gen instances: --count must be at least 1");
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
