#include "core/geometry/uv_gradients.h"

#include <cmath>

#include "core/geometry/mesh.h"

namespace pt {
namespace {

struct Vec3d {
  double x, y, z;
};
Vec3d to_double(const Vec3f& v) { return {v.x, v.y, v.z}; }
Vec3d sub(const Vec3d& a, const Vec3d& b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec3d cross(const Vec3d& a, const Vec3d& b) {
  return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x};
}

}  // namespace

UvGradients triangle_uv_gradients(const Vec3f& p0, const Vec3f& p1, const Vec3f& p2, Vec2f uv0, Vec2f uv1, Vec2f uv2) {
  const Vec3d o = to_double(p0), e1 = sub(to_double(p1), o), e2 = sub(to_double(p2), o);
  const Vec3d n = cross(e1, e2);
  const double n2 = n.x * n.x + n.y * n.y + n.z * n.z;
  UvGradients g{Vec3f(0.0f), Vec3f(0.0f)};
  if (!(n2 > 0) || !std::isfinite(n2)) return g;
  const Vec3d a = cross(e2, n), b = cross(n, e1);  // dot(a, e1) = dot(b, e2) = |n|^2
  auto gradient = [&](double d1, double d2) {
    const Vec3f r(static_cast<float>((d1 * a.x + d2 * b.x) / n2), static_cast<float>((d1 * a.y + d2 * b.y) / n2),
                  static_cast<float>((d1 * a.z + d2 * b.z) / n2));
    return is_finite(r) ? r : Vec3f(0.0f);
  };
  g.u = gradient(static_cast<double>(uv1.x) - uv0.x, static_cast<double>(uv2.x) - uv0.x);
  g.v = gradient(static_cast<double>(uv1.y) - uv0.y, static_cast<double>(uv2.y) - uv0.y);
  return g;
}

void compute_uv_gradients(Mesh& mesh) {
  const size_t tris = mesh.triangle_count();
  mesh.uv_gradients.assign(tris, UvGradients{Vec3f(0.0f), Vec3f(0.0f)});
  for (size_t t = 0; t < tris; ++t) {
    mesh.uv_gradients[t] = triangle_uv_gradients(mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2),
                                                 mesh.corner_uv(t, 0), mesh.corner_uv(t, 1), mesh.corner_uv(t, 2));
  }
}

}  // namespace pt
