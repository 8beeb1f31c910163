// The gradients of a surface's u and v: a step dp along the surface moves uv by
// (dot(u, dp), dot(v, dp)). They turn a ray's footprint into texture space (core/scene/footprint.h)
// with four dot products, where dp/du and dp/dv needed a 2x2 solve at every hit.
#pragma once
#include "core/math/vec.h"

namespace pt {

struct Mesh;

struct UvGradients {
  Vec3f u, v;
};

// A triangle's, over its plane: with e1 = p1 - p0, e2 = p2 - p0 and n = e1 x e2,
// grad u = ((u1 - u0) (e2 x n) + (u2 - u0) (n x e1)) / |n|^2 (dot with e1 gives u1 - u0, with e2
// gives u2 - u0, with n gives 0). Computed in double; zero for a degenerate triangle. A uv map that
// is degenerate in one direction keeps the other.
UvGradients triangle_uv_gradients(const Vec3f& p0, const Vec3f& p1, const Vec3f& p2, Vec2f uv0, Vec2f uv1, Vec2f uv2);

// Fills mesh.uv_gradients (one per triangle) from corner_uvs, or from the barycentric
// parameterisation (uv = (b1, b2)) where the mesh has none, as Scene::interaction reads uv.
void compute_uv_gradients(Mesh& mesh);

}  // namespace pt
