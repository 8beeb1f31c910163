#include "core/geometry/instance.h"

#include <cmath>

namespace pt {

std::string instance_transform_problem(const Transform& t) {
  for (const auto& row : t.m) {
    for (float v : row) {
      if (!std::isfinite(v)) return "the transform has a non-finite entry";
    }
  }
  // Singular (or so near it that the inverse would not be finite in float): compare the volume the
  // transform gives a unit cube with the product of its axes' lengths, which is scale-free.
  double a[3][3];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) a[i][j] = t.m[i][j];
  }
  auto column = [&](int j) { return std::sqrt(a[0][j] * a[0][j] + a[1][j] * a[1][j] + a[2][j] * a[2][j]); };
  double scale = column(0) * column(1) * column(2);
  double det = a[0][0] * (a[1][1] * a[2][2] - a[1][2] * a[2][1]) - a[0][1] * (a[1][0] * a[2][2] - a[1][2] * a[2][0]) +
               a[0][2] * (a[1][0] * a[2][1] - a[1][1] * a[2][0]);
  if (!(scale > 0) || !(std::abs(det) > 1e-6 * scale)) return "the transform is singular: it flattens the object";
  Transform inv = t.inverse();
  for (const auto& row : inv.m) {
    for (float v : row) {
      if (!std::isfinite(v)) return "the transform cannot be inverted in float precision";
    }
  }
  return {};
}

BBox transform_bounds(const BBox& box, const Transform& t) {
  BBox out;
  if (box.empty()) return out;
  for (int c = 0; c < 8; ++c) {
    Vec3f corner{(c & 1) ? box.hi.x : box.lo.x, (c & 2) ? box.hi.y : box.lo.y, (c & 4) ? box.hi.z : box.lo.z};
    out.expand(t.point(corner));
  }
  for (int a = 0; a < 3; ++a) {
    out.lo[a] = std::nextafter(out.lo[a], -kInf);
    out.hi[a] = std::nextafter(out.hi[a], kInf);
  }
  return out;
}

BBox transformed_mesh_bounds(const Mesh& mesh, const Transform& t) {
  BBox out;
  for (const Vec3f& p : mesh.positions) out.expand(t.point(p));
  return out;
}

BBox instances_bounds(const std::vector<const Mesh*>& meshes, const std::vector<Instance>& instances) {
  size_t points = 0;
  for (const Instance& i : instances) points += meshes[i.mesh]->positions.size();
  BBox out;
  if (points <= kExactBoundsPoints) {
    for (const Instance& i : instances) out.expand(transformed_mesh_bounds(*meshes[i.mesh], i.to_world));
    return out;
  }
  std::vector<BBox> boxes;
  for (const Mesh* m : meshes) boxes.push_back(m->bounds());
  for (const Instance& i : instances) out.expand(transform_bounds(boxes[i.mesh], i.to_world));
  return out;
}

void append_transformed(Mesh& world, const Mesh& object, const Transform& t) {
  const size_t first_tri = world.triangle_count();
  const uint32_t base = static_cast<uint32_t>(world.positions.size());
  for (const Vec3f& p : object.positions) world.positions.push_back(t.point(p));
  const bool flip = t.flips_handedness();
  const int order[3] = {0, flip ? 2 : 1, flip ? 1 : 2};
  for (size_t tri = 0; tri < object.triangle_count(); ++tri) {
    for (int c : order) world.indices.push_back(base + object.indices[3 * tri + c]);
  }
  world.material.insert(world.material.end(), object.material.begin(), object.material.end());
  // Per-corner arrays stay either empty or one entry per corner of every triangle.
  if (!object.corner_normals.empty() || !world.corner_normals.empty()) {
    world.corner_normals.resize(3 * first_tri, Vec3f(0.0f));
    for (size_t tri = 0; tri < object.triangle_count(); ++tri) {
      for (int c : order) {
        Vec3f n = object.corner_normals.empty() ? Vec3f(0.0f) : t.normal(object.corner_normals[3 * tri + c]);
        float l = length(n);
        world.corner_normals.push_back(l > 0 && std::isfinite(l) ? n / l : Vec3f(0.0f));
      }
    }
  }
  if (!object.corner_uvs.empty() || !world.corner_uvs.empty()) {
    world.corner_uvs.resize(3 * first_tri, Vec2f(0, 0));
    for (size_t tri = 0; tri < object.triangle_count(); ++tri) {
      for (int c : order) world.corner_uvs.push_back(object.corner_uvs.empty() ? Vec2f(0, 0) : object.corner_uvs[3 * tri + c]);
    }
  }
  if (!object.corner_tangents.empty() || !world.corner_tangents.empty()) {
    world.corner_tangents.resize(3 * first_tri, Vec3f(0.0f));
    world.corner_tangent_signs.resize(3 * first_tri, 1.0f);
    // A mirroring transform reverses the bitangent's side of the tangent: the sign follows.
    const float mirror = flip ? -1.0f : 1.0f;
    for (size_t tri = 0; tri < object.triangle_count(); ++tri) {
      for (int c : order) {
        bool has = !object.corner_tangents.empty();
        world.corner_tangents.push_back(has ? t.vector(object.corner_tangents[3 * tri + c]) : Vec3f(0.0f));
        world.corner_tangent_signs.push_back(has ? object.corner_tangent_signs[3 * tri + c] * mirror : 1.0f);
      }
    }
  }
  // Vertex colours cover a prefix of the triangles (mesh.h): padded with white up to this mesh.
  if (!object.corner_colors.empty()) {
    world.corner_colors.resize(3 * first_tri, Vec3f(1.0f));
    for (size_t tri = 0; tri < object.triangle_count(); ++tri) {
      for (int c : order) {
        world.corner_colors.push_back(3 * tri + c < object.corner_colors.size() ? object.corner_colors[3 * tri + c] : Vec3f(1.0f));
      }
    }
  }
}

}  // namespace pt
