// A rough dielectric interface: GGX microfacets that reflect with exact Fresnel and refract the
// rest (Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction through Rough
// Surfaces", eqs. 20-21 with the generalised half vector of eq. 16), height-correlated Smith
// masking (core/material/ggx.h) and visible-normal sampling. The transmitted lobe is tinted by
// `tint` (KHR_materials_transmission: the base colour). Single scattering only: light that
// bounces between microfacets more than once is lost, as the metallic-roughness model's own GGX
// lobes would lose it without their tables (tests/test_unit_transmission.cpp measures the albedo).
//
// wo may be on either side (z < 0: inside the object, where the relative index is 1/ior). Radiance
// is compressed by 1/eta^2 crossing into the denser medium, as the smooth dielectric does, so
// f(wo, wi) / eta_i^2 = f(wi, wo) / eta_o^2 (eta_x: the index on the side of x).
#pragma once
#include <cmath>

#include "core/material/bsdf_sample.h"
#include "core/material/dielectric.h"
#include "core/material/ggx.h"

namespace pt {

struct RoughInterface {
  Ggx ggx;
  float ior = 1.5f;
  Spectrum tint{1.0f};

  // eta_t / eta_i for light arriving from wo's side.
  float eta_from(const Vec3f& wo) const { return wo.z > 0 ? ior : 1.0f / ior; }

  Spectrum eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    pdf_out = 0.0f;
    if (wo.z == 0 || wi.z == 0) return Spectrum(0.0f);
    const bool reflect = wo.z * wi.z > 0;
    const float eta = eta_from(wo);
    // The microfacet normal that links wo and wi (eq. 13 for reflection, eq. 16 for refraction),
    // turned to the macro-normal's side.
    Vec3f m = reflect ? wo + wi : wi * eta + wo;
    float len2 = dot(m, m);
    if (!(len2 > 0)) return Spectrum(0.0f);
    m = m / std::sqrt(len2);
    if (m.z < 0) m = -m;
    const float o_m = dot(wo, m), i_m = dot(wi, m);
    // Both directions must see the facet from their own side of the surface.
    if (o_m * wo.z <= 0 || i_m * wi.z <= 0) return Spectrum(0.0f);
    const float fresnel = fresnel_dielectric(std::abs(o_m), eta);
    if (!reflect && fresnel >= 1.0f) return Spectrum(0.0f);  // total internal reflection
    const float d = ggx.d(m);
    const float g = ggx.g2(wo, wi);
    // Density of m drawn as a visible normal of wo (or of -wo inside): G1 |wo.m| D / |wo.z|.
    const float visible = ggx.g1(wo) * std::abs(o_m) * d / std::abs(wo.z);
    if (reflect) {
      pdf_out = fresnel * visible / (4.0f * std::abs(o_m));
      return Spectrum(fresnel * d * g / (4.0f * std::abs(wo.z * wi.z)));
    }
    const float denom = i_m + o_m / eta;
    const float dm_dwi = std::abs(i_m) / (denom * denom);  // Walter eq. 17
    pdf_out = (1.0f - fresnel) * visible * dm_dwi;
    float ft = (1.0f - fresnel) * d * g * std::abs(i_m * o_m / (wi.z * wo.z * denom * denom));
    return tint * (ft / (eta * eta));
  }

  // u_lobe chooses reflection (probability F at the drawn facet) or refraction.
  bool sample(const Vec3f& wo, float u_lobe, Vec2f u, BsdfSample& s) const {
    if (wo.z == 0) return false;
    const float side = wo.z > 0 ? 1.0f : -1.0f;
    Vec3f m = ggx.sample_visible_normal(wo * side, u) * side;  // on wo's side
    const float cos_o = dot(wo, m);
    if (!(cos_o > 0)) return false;
    const float eta = eta_from(wo);
    const float fresnel = fresnel_dielectric(cos_o, eta);
    const bool reflect = u_lobe < fresnel;
    if (reflect) {
      s.wi = m * (2.0f * cos_o) - wo;
    } else {
      float sin2_t = std::max(0.0f, 1.0f - cos_o * cos_o) / (eta * eta);
      if (sin2_t >= 1.0f) return false;  // total internal reflection: fresnel is 1, not reached
      float cos_t = std::sqrt(1.0f - sin2_t);
      s.wi = -wo / eta + m * (cos_o / eta - cos_t);
    }
    // A facet steep enough sends a reflection through the surface or a refraction back out: no
    // such path (eval_pdf gives these pairs to the other event, through another facet).
    if ((s.wi.z * wo.z > 0) != reflect) return false;
    Spectrum f = eval_pdf(wo, s.wi, s.pdf);
    if (!(s.pdf > 0)) return false;
    s.weight = f * (std::abs(s.wi.z) / s.pdf);
    s.specular = false;
    return true;
  }
};

}  // namespace pt
