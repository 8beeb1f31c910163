// The isotropic GGX (Trowbridge-Reitz) microfacet distribution in the local shading frame
// (z = normal), with Smith's height-correlated masking-shadowing (Heitz 2014, "Understanding the
// Masking-Shadowing Function in Microfacet-Based BRDFs", eq. 99) and visible-normal sampling by
// spherical caps (Dupuy & Benyoub 2023, "Sampling Visible GGX Normals with Spherical Caps").
// alpha is the GGX width (glTF: roughness squared).
#pragma once
#include <algorithm>
#include <cmath>

#include "core/math/vec.h"

namespace pt {

// Below this width the lobe is narrower than float directions resolve; clamped there.
inline constexpr float kMinGgxAlpha = 1e-4f;

struct Ggx {
  float alpha;

  // D(h): written with the tangent components so that it stays exact for tiny alpha, where
  // 1 - cos^2 would cancel.
  float d(const Vec3f& h) const {
    if (h.z <= 0) return 0.0f;
    float a2 = alpha * alpha;
    float t = (h.x * h.x + h.y * h.y) / a2 + h.z * h.z;
    return 1.0f / (kPi * a2 * t * t);
  }
  // Smith's Lambda for a direction w (Heitz 2014, eq. 72).
  float lambda(const Vec3f& w) const {
    float z2 = w.z * w.z;
    if (z2 <= 0) return 1e30f;
    float tan2 = std::max(0.0f, w.x * w.x + w.y * w.y) / z2;
    return 0.5f * (std::sqrt(1.0f + alpha * alpha * tan2) - 1.0f);
  }
  float g1(const Vec3f& w) const { return 1.0f / (1.0f + lambda(w)); }
  // Height-correlated masking-shadowing G2(wo, wi) for both directions above the surface.
  float g2(const Vec3f& wo, const Vec3f& wi) const { return 1.0f / (1.0f + lambda(wo) + lambda(wi)); }

  // A visible normal for wo (wo.z > 0) from u in [0,1)^2: the half vector h with density
  // D_wo(h) = G1(wo) max(0, wo.h) D(h) / wo.z (Dupuy & Benyoub 2023, listing 3).
  Vec3f sample_visible_normal(const Vec3f& wo, Vec2f u) const {
    Vec3f wo_std = normalize(Vec3f(wo.x * alpha, wo.y * alpha, wo.z));  // to the hemisphere config
    float phi = 2.0f * kPi * u.x;
    float z = std::fma(1.0f - u.y, 1.0f + wo_std.z, -wo_std.z);
    float sin_theta = std::sqrt(std::clamp(1.0f - z * z, 0.0f, 1.0f));
    Vec3f c{sin_theta * std::cos(phi), sin_theta * std::sin(phi), z};
    Vec3f h_std = c + wo_std;
    return normalize(Vec3f(h_std.x * alpha, h_std.y * alpha, std::max(h_std.z, 0.0f)));
  }
  // The density of wi = reflect(wo, h) when h is drawn by sample_visible_normal: D_wo(h) / (4 wo.h).
  float reflection_pdf(const Vec3f& wo, const Vec3f& h) const {
    if (wo.z <= 0) return 0.0f;
    return g1(wo) * d(h) / (4.0f * wo.z);
  }
};

// Schlick's Fresnel weight (1 - c)^5.
inline float schlick_weight(float cos_theta) {
  float m = std::clamp(1.0f - cos_theta, 0.0f, 1.0f);
  float m2 = m * m;
  return m2 * m2 * m;
}

}  // namespace pt
