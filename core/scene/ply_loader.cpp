// A PLY mesh (ply_reader.h) put into a scene: transformed to world space, with per-corner normals,
// texture coordinates and vertex colours where the file has them.
#include <cstdio>

#include "core/scene/loader.h"
#include "core/scene/ply_reader.h"
#include "core/util/error.h"
#include "core/util/input_file.h"
#include "core/util/text.h"

namespace pt {

void load_ply(SceneBuilder& scene, const std::string& path, const Transform& transform, int override_material, Mesh* into) {
  require_regular_file(path, "a PLY file");
  PlyMesh ply = read_ply(path);
  scene.inputs.push_back(path);
  if (!ply.ignored.empty()) scene.notes.push_back(path + ": ignoring PLY data pt does not use: " + join_names(ply.ignored));
  scene.contents.push_back(path + ": PLY (" + ply.format + "): " + std::to_string(ply.positions.size()) + " vertices, " +
                           std::to_string(ply.faces) + " faces, " + std::to_string(ply.strips) + " triangle strips, " +
                           std::to_string(ply.triangles.size() / 3) + " triangles" + (ply.normals.empty() ? "" : "; normals") +
                           (ply.uvs.empty() ? "" : "; uvs") + (ply.colors.empty() ? "" : "; vertex colours"));

  // Vertex colours are the diffuse colour of a white Lambertian material, multiplied in at each
  // shading point (Mesh::corner_colors); an override material (a scene file's "material") keeps
  // its own colour and the file's colours are not used.
  bool use_colors = !ply.colors.empty() && override_material < 0;
  uint32_t material;
  if (override_material >= 0) {
    material = static_cast<uint32_t>(override_material);
  } else if (use_colors) {
    Material m;
    m.name = "vertex colours";
    m.model = Diffuse{Spectrum(1.0f)};
    material = scene.add_material(m);
  } else {
    material = scene.default_material();
  }

  Mesh& mesh = into ? *into : scene.mesh;
  const size_t first_triangle = mesh.triangle_count();
  const uint32_t base = static_cast<uint32_t>(mesh.positions.size());
  for (const Vec3f& p : ply.positions) mesh.positions.push_back(transform.point(p));
  std::vector<Vec3f> normals;
  for (const Vec3f& n : ply.normals) {
    Vec3f w = transform.normal(n);
    float l = length(w);
    normals.push_back(l > 0 && std::isfinite(l) ? w / l : Vec3f(0.0f));  // zero: "no normal" (mesh.h)
  }
  if (!normals.empty() && mesh.corner_normals.empty()) mesh.corner_normals.assign(3 * first_triangle, Vec3f(0.0f));
  if (!ply.uvs.empty() && mesh.corner_uvs.empty()) mesh.corner_uvs.assign(3 * first_triangle, Vec2f(0, 0));
  if (use_colors) mesh.corner_colors.resize(3 * first_triangle, Spectrum(1.0f));

  const bool flip = transform.flips_handedness();
  const size_t triangles = ply.triangles.size() / 3;
  mesh.indices.reserve(mesh.indices.size() + ply.triangles.size());
  mesh.material.reserve(mesh.material.size() + triangles);
  for (size_t t = 0; t < triangles; ++t) {
    const int order[3] = {0, flip ? 2 : 1, flip ? 1 : 2};  // keep the front face under mirroring
    for (int c : order) {
      uint32_t v = ply.triangles[3 * t + c];
      mesh.indices.push_back(base + v);
      if (!normals.empty()) mesh.corner_normals.push_back(normals[v]);
      if (!ply.uvs.empty()) mesh.corner_uvs.push_back(ply.uvs[v]);
      if (use_colors) mesh.corner_colors.push_back(ply.colors[v]);
    }
    mesh.material.push_back(material);
  }
  // Keep the per-corner arrays as long as the triangles when an earlier object had them.
  if (!mesh.corner_normals.empty()) mesh.corner_normals.resize(3 * mesh.triangle_count(), Vec3f(0.0f));
  if (!mesh.corner_uvs.empty()) mesh.corner_uvs.resize(3 * mesh.triangle_count(), Vec2f(0, 0));
}

}  // namespace pt
