#include "core/geometry/tangents.h"

#include <bit>
#include <cmath>
#include <unordered_map>

namespace pt {
namespace {

struct CornerKey {
  uint32_t position;
  uint32_t bits[5];  // normal xyz, uv
  bool flipped;
  bool operator==(const CornerKey&) const = default;
};
struct CornerKeyHash {
  size_t operator()(const CornerKey& k) const {
    uint64_t h = k.position * 0x9E3779B97F4A7C15ull + k.flipped;
    for (uint32_t b : k.bits) h = (h ^ b) * 0x100000001B3ull;
    return static_cast<size_t>(h ^ (h >> 29));
  }
};

Vec3f project(const Vec3f& v, const Vec3f& n) { return v - n * dot(n, v); }
Vec3f safe_normalize(const Vec3f& v) {
  float l = length(v);
  return l > 0 && std::isfinite(l) ? v / l : Vec3f(0.0f);
}

}  // namespace

void compute_tangents(Mesh& mesh) {
  const size_t tris = mesh.triangle_count();
  std::vector<Vec3f> corner_normal(3 * tris);
  std::vector<Vec2f> corner_uv(3 * tris);
  std::vector<Vec3f> tri_tangent(tris);
  std::vector<float> tri_sign(tris, 1.0f);
  for (size_t t = 0; t < tris; ++t) {
    Vec3f p[3] = {mesh.vertex(t, 0), mesh.vertex(t, 1), mesh.vertex(t, 2)};
    Vec3f ng = safe_normalize(mesh.geometric_normal(t));
    Vec2f uv[3];
    for (int c = 0; c < 3; ++c) {
      uv[c] = mesh.corner_uv(t, c);
      corner_uv[3 * t + c] = uv[c];
      Vec3f n = mesh.corner_normals.empty() ? Vec3f(0.0f) : safe_normalize(mesh.corner_normals[3 * t + c]);
      corner_normal[3 * t + c] = length_squared(n) > 0 ? n : ng;
    }
    // dp/du and dp/dv of the triangle (as Scene::interaction computes them).
    Vec2f duv02 = uv[0] - uv[2], duv12 = uv[1] - uv[2];
    Vec3f dp02 = p[0] - p[2], dp12 = p[1] - p[2];
    float det = duv02.x * duv12.y - duv02.y * duv12.x;
    if (!(std::abs(det) > 1e-20f)) continue;
    Vec3f dpdu = (dp02 * duv12.y - dp12 * duv02.y) / det, dpdv = (dp12 * duv02.x - dp02 * duv12.x) / det;
    tri_tangent[t] = is_finite(dpdu) ? dpdu : Vec3f(0.0f);
    tri_sign[t] = dot(cross(ng, dpdu), dpdv) < 0 ? -1.0f : 1.0f;
  }
  auto key_of = [&](size_t t, int c) {
    CornerKey k{};
    k.position = mesh.indices[3 * t + c];
    const Vec3f& n = corner_normal[3 * t + c];
    const Vec2f& uv = corner_uv[3 * t + c];
    k.bits[0] = std::bit_cast<uint32_t>(n.x), k.bits[1] = std::bit_cast<uint32_t>(n.y);
    k.bits[2] = std::bit_cast<uint32_t>(n.z), k.bits[3] = std::bit_cast<uint32_t>(uv.x);
    k.bits[4] = std::bit_cast<uint32_t>(uv.y);
    k.flipped = tri_sign[t] < 0;
    return k;
  };
  std::unordered_map<CornerKey, Vec3f, CornerKeyHash> sums;
  sums.reserve(3 * tris);
  for (size_t t = 0; t < tris; ++t) {
    for (int c = 0; c < 3; ++c) {
      const Vec3f& n = corner_normal[3 * t + c];
      Vec3f tangent = safe_normalize(project(tri_tangent[t], n));
      // The angle at the corner, between its two edges in the plane of the normal.
      Vec3f p = mesh.vertex(t, c);
      Vec3f e1 = safe_normalize(project(mesh.vertex(t, (c + 1) % 3) - p, n));
      Vec3f e2 = safe_normalize(project(mesh.vertex(t, (c + 2) % 3) - p, n));
      float angle = std::acos(std::clamp(dot(e1, e2), -1.0f, 1.0f));
      sums[key_of(t, c)] += tangent * angle;
    }
  }
  mesh.corner_tangents.assign(3 * tris, Vec3f(0.0f));
  mesh.corner_tangent_signs.assign(3 * tris, 1.0f);
  for (size_t t = 0; t < tris; ++t) {
    for (int c = 0; c < 3; ++c) {
      const Vec3f& n = corner_normal[3 * t + c];
      Vec3f tangent = safe_normalize(project(sums[key_of(t, c)], n));
      if (length_squared(tangent) == 0) {
        // No uv direction at all here: any tangent in the plane keeps the frame well defined.
        Vec3f a = std::abs(n.x) < 0.9f ? Vec3f(1, 0, 0) : Vec3f(0, 1, 0);
        tangent = safe_normalize(project(a, n));
      }
      mesh.corner_tangents[3 * t + c] = tangent;
      mesh.corner_tangent_signs[3 * t + c] = tri_sign[t];
    }
  }
}

}  // namespace pt
