// Scene::shading_normal: a material's normal or bump map applied at a shading point.
#include "core/scene/shading_normal.h"

#include "core/scene/scene.h"

namespace pt {
namespace {

Vec3f safe_normalize(const Vec3f& v, const Vec3f& fallback) {
  float l = length(v);
  return l > 1e-12f && std::isfinite(l) ? v / l : fallback;
}

// The tangent frame's tangent and handedness at si: the mesh's (interpolated) where it has them,
// else the direction of increasing u.
void tangent_frame(const SurfaceInteraction& si, Vec3f& tangent, float& sign) {
  if (length_squared(si.tangent) > 0) {
    tangent = si.tangent;
    sign = si.tangent_sign;
  } else {
    tangent = si.dpdu;
    sign = dot(cross(si.ns, si.dpdu), si.dpdv) < 0 ? -1.0f : 1.0f;
  }
}

}  // namespace

Vec3f Scene::shading_normal(const SurfaceInteraction& si, const Vec3f& wo) const {
  const Material& m = materials_[si.material];
  Vec3f n = si.ns;
  auto lookup = [&](int slot, Vec2f uv) { return textures_.lookup(slot, uv, si.duvdx, si.duvdy, si.rough_footprint); };
  if (m.normal_texture >= 0) {
    // Tangent space, glTF: n = normalize((2 c - 1) * (scale, scale, 1)) with x along the tangent,
    // y along the bitangent (increasing v, up in the image), z along the interpolated normal.
    Spectrum c = lookup(m.normal_texture, si.uv);
    Vec3f local{(2.0f * c.x - 1.0f) * m.normal_scale, (2.0f * c.y - 1.0f) * m.normal_scale, 2.0f * c.z - 1.0f};
    Vec3f tangent;
    float sign;
    tangent_frame(si, tangent, sign);
    Vec3f t = tangent - n * dot(n, tangent);
    float tl = length(t);
    if (!(tl > 1e-12f && std::isfinite(tl))) return n;
    t = t / tl;
    Vec3f b = cross(n, t) * sign;
    n = safe_normalize(t * local.x + b * local.y + n * local.z, si.ns);
  } else if (m.bump_texture >= 0 && length_squared(si.dpdu) > 0 && length_squared(si.dpdv) > 0) {
    // The surface displaced by h(u, v) along its normal: p' = p + h n, so dp'/du = dp/du + dh/du n
    // (pbrt 3rd ed. 9.3, without the dn/du term: the base surface is taken as flat at this scale).
    // dh/du by a forward difference over the ray's footprint in u (or a small fixed step).
    float du = 0.5f * (std::abs(si.duvdx.x) + std::abs(si.duvdy.x));
    float dv = 0.5f * (std::abs(si.duvdx.y) + std::abs(si.duvdy.y));
    if (!(du > 0)) du = 0.0005f;
    if (!(dv > 0)) dv = 0.0005f;
    float h = lookup(m.bump_texture, si.uv).x;
    float hu = lookup(m.bump_texture, {si.uv.x + du, si.uv.y}).x;
    float hv = lookup(m.bump_texture, {si.uv.x, si.uv.y + dv}).x;
    Vec3f dpdu = si.dpdu + n * ((hu - h) / du * m.bump_scale);
    Vec3f dpdv = si.dpdv + n * ((hv - h) / dv * m.bump_scale);
    Vec3f bumped = safe_normalize(cross(dpdu, dpdv), si.ns);
    // cross(dpdu, dpdv) faces the side the uv orientation gives; the shading normal's side wins.
    if (dot(cross(si.dpdu, si.dpdv), n) < 0) bumped = -bumped;
    n = bumped;
  } else {
    return n;
  }
  if (dot(n, si.ng) < 0 && dot(si.ns, si.ng) >= 0) {
    // A map tilted past the geometric surface: keep the normal on the side of ng (as si.ns is).
    n = safe_normalize(n - si.ng * (1.001f * dot(n, si.ng)), si.ns);
  }
  return adapt_shading_normal(n, si.ng, wo);
}

}  // namespace pt
