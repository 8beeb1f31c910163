// The scene's triangles, in world space, in the layout Embree can share without a copy.
#pragma once
#include <cstdint>
#include <vector>

#include "core/geometry/uv_gradients.h"
#include "core/math/bbox.h"
#include "core/math/vec.h"

namespace pt {

struct Mesh {
  // Embree reads vertices with 16-byte loads, so one float past the last vertex must be readable:
  // finalize() keeps capacity for one extra element.
  std::vector<Vec3f> positions;
  std::vector<uint32_t> indices;          // 3 per triangle
  std::vector<uint32_t> material;         // 1 per triangle
  std::vector<Vec3f> corner_normals;      // 3 per triangle, or empty; a zero normal means "none"
  std::vector<Vec2f> corner_uvs;          // 3 per triangle, or empty
  // Vertex colours (PLY, glTF COLOR_0), multiplying the material's diffuse colour: 3 per triangle
  // for the triangles up to some count, or empty. Loaders that write none leave it short; a
  // loader that writes some pads it with white first; triangles past its end are white.
  std::vector<Vec3f> corner_colors;
  // Tangent frames for normal maps, 3 per triangle or empty: the tangent (along increasing u) and
  // the bitangent's handedness, bitangent = sign * cross(normal, tangent) (along increasing v, up in
  // the image; the glTF TANGENT attribute's w). From the file where it has them, else made once at
  // load for meshes with normal-mapped materials (core/geometry/tangents.h).
  std::vector<Vec3f> corner_tangents;
  std::vector<float> corner_tangent_signs;
  // The gradients of u and v over each triangle, 1 per triangle or empty: made once at load for
  // meshes whose materials look textures up over a footprint (core/geometry/uv_gradients.h).
  std::vector<UvGradients> uv_gradients;

  size_t triangle_count() const { return indices.size() / 3; }
  Vec3f vertex(size_t tri, int corner) const { return positions[indices[3 * tri + corner]]; }
  // A corner's uv: the file's, else the barycentric parameterisation's ((0, 0), (1, 0), (0, 1)),
  // as Scene::interaction reads uv.
  Vec2f corner_uv(size_t tri, int corner) const {
    if (!corner_uvs.empty()) return corner_uvs[3 * tri + corner];
    return corner == 0 ? Vec2f(0.0f, 0.0f) : corner == 1 ? Vec2f(1.0f, 0.0f) : Vec2f(0.0f, 1.0f);
  }
  Vec3f geometric_normal(size_t tri) const {  // not normalised; length = 2 * area
    Vec3f p0 = vertex(tri, 0);
    return cross(vertex(tri, 1) - p0, vertex(tri, 2) - p0);
  }
  float area(size_t tri) const { return 0.5f * length(geometric_normal(tri)); }
  BBox bounds() const {
    BBox b;
    for (const Vec3f& p : positions) b.expand(p);
    return b;
  }
  void finalize() { positions.reserve(positions.size() + 1); }
};

}  // namespace pt
