// metallic-roughness: glTF 2.0's material (specification, Appendix B), which is also Blender's
// Principled BSDF (metallic, roughness, base colour) and the MTL PBR extension (Pr, Pm).
//
// base_color  linear RGB; the diffuse colour of the dielectric and F0 of the metal (texture
//             slot base_color_texture multiplies it, and so does the vertex colour)
// metallic    0 dielectric .. 1 metal; the BSDF is the mix (1 - metallic) dielectric + metallic metal
// roughness   GGX alpha = roughness^2
// ior         the dielectric's index; F0 = ((ior - 1) / (ior + 1))^2 = 0.04 at glTF's 1.5
// Data textures (linear values, core/scene/loader.h data_texture_index) scale metallic and
// roughness: metallic_roughness_texture as glTF packs it (G roughness, B metallic), and
// roughness_texture / metallic_texture (MTL map_Pr / map_Pm: their luminance).
//
// The lobes, with Schlick's Fresnel F(c) = F0 + (1 - F0)(1 - c)^5 on c = wo.h:
//   specular   F D G2 / (4 mu_o mu_i): GGX with height-correlated Smith masking (core/material/ggx.h),
//              F0 mixed between the dielectric's and base_color by metallic (Schlick is linear in F0)
//   multiple   Kulla & Conty 2017's compensation for the light single scattering loses:
//   scattering (1 - E(mu_o))(1 - E(mu_i)) / (pi (1 - E_avg)) Fms, with
//              Fms = F_avg^2 E_avg / (1 - F_avg (1 - E_avg)), F_avg = F0 + (1 - F0)/21, mixed by
//              metallic; E from the tables of ggx_albedo.h
//   diffuse    (1 - metallic) base_color/pi (1 - Es(mu_o))(1 - Es(mu_i)) / (1 - Es_avg), where Es is
//              the dielectric specular's whole albedo (single + multiple scattering): the
//              Lambertian base gets exactly the light the specular layer does not reflect
//              (Kulla & Conty's albedo scaling), and it stays reciprocal.
// Where this departs from Appendix B by design: the specification weights the diffuse base by
// 1 - F(V.H) (its fresnel_mix), which does not hand the base what the specular layer leaves (the
// GGX lobe reflects less than F: masking and the horizon), so a white dielectric does not reflect
// 1; and it has no multiple-scattering term, so a white metal reflects on average 1 - E_avg less
// than it receives: 1.3% at roughness 0.25, 12% at 0.5, 29% at 0.7, 59% at 1 (where E is 0.31 at
// normal incidence).
// So the directional albedo is E_F0(mu_o) + (1 - E(mu_o)) Fms + (1 - metallic) base (1 - Es(mu_o)):
// a metal with base colour 1 reflects 1 at every angle and roughness, and so does a dielectric
// with base colour 1 (it loses nothing to the coupling of the two layers); a dielectric with base
// colour b reflects Es + b (1 - Es). Every term is symmetric in wo and wi. Sampling picks the GGX
// lobe (visible normals) or a cosine lobe (for the diffuse and multiple-scattering lobes) in
// proportion to their albedos at wo.
#pragma once
#include <algorithm>
#include <cmath>

#include "core/material/bsdf_sample.h"
#include "core/material/describe.h"
#include "core/material/ggx.h"
#include "core/material/ggx_albedo.h"
#include "core/material/texture_lookup.h"
#include "core/math/sampling.h"

namespace pt {

struct MetallicRoughnessBsdf {
  Spectrum base_color{1.0f};
  float metallic = 1.0f;
  float roughness = 1.0f;
  float ior = 1.5f;

  static constexpr uint8_t kFlags = kBsdfReflection | kBsdfDiffuse | kBsdfGlossy;
  uint8_t flags() const { return kFlags; }
  Spectrum albedo() const { return base_color; }

  // What depends on the parameters only, found once per shading point.
  struct Terms {
    Ggx ggx;
    TableCoord r;
    float f0_dielectric;
    Spectrum f0;         // mixed by metallic
    float e_avg;         // E_avg of single scattering (Fresnel 1)
    float fms_d;         // Fms of the dielectric
    Spectrum fms;        // Fms, mixed by metallic
    float es_avg;        // the dielectric specular's average albedo
    float ms_norm;       // 1 / (pi (1 - E_avg)), or 0 where single scattering loses nothing
    Spectrum diffuse;    // (1 - metallic) base / (pi (1 - Es_avg))
  };
  Terms terms() const {
    Terms t{Ggx{std::max(roughness * roughness, kMinGgxAlpha)}, TableCoord(roughness), 0, {}, 0, 0, {}, 0, 0, {}};
    float s = (ior - 1.0f) / (ior + 1.0f);
    t.f0_dielectric = s * s;
    t.f0 = Spectrum(t.f0_dielectric) * (1.0f - metallic) + base_color * metallic;
    t.e_avg = table_lookup(kGgxAlbedoAvg, t.r);
    float e5_avg = table_lookup(kGgxAlbedoSchlickAvg, t.r);
    auto fms_of = [&](float f0) {
      float f_avg = f0 + (1.0f - f0) / 21.0f;
      return f_avg * f_avg * t.e_avg / (1.0f - f_avg * (1.0f - t.e_avg));
    };
    t.fms_d = fms_of(t.f0_dielectric);
    Spectrum fms_m{fms_of(base_color.x), fms_of(base_color.y), fms_of(base_color.z)};
    t.fms = Spectrum(t.fms_d) * (1.0f - metallic) + fms_m * metallic;
    t.es_avg = t.f0_dielectric * t.e_avg + (1.0f - t.f0_dielectric) * e5_avg + (1.0f - t.e_avg) * t.fms_d;
    t.ms_norm = 1.0f - t.e_avg > 1e-6f ? kInvPi / (1.0f - t.e_avg) : 0.0f;
    t.diffuse = base_color * ((1.0f - metallic) * kInvPi / std::max(1e-6f, 1.0f - t.es_avg));
    return t;
  }
  // Single scattering's E(mu), and the dielectric specular's whole directional albedo Es(mu).
  static float e_single(const Terms& t, float mu) { return table_lookup(kGgxAlbedo, t.r, mu); }
  static float e_dielectric(const Terms& t, float mu, float e) {
    return t.f0_dielectric * e + (1.0f - t.f0_dielectric) * table_lookup(kGgxAlbedoSchlick, t.r, mu) + (1.0f - e) * t.fms_d;
  }

  // The probability of sampling the GGX lobe at wo.
  float specular_probability(const Terms& t, float mu_o, float e_o) const {
    float e5 = table_lookup(kGgxAlbedoSchlick, t.r, mu_o);
    Spectrum spec = t.f0 * e_o + (Spectrum(1.0f) - t.f0) * e5;
    // The cosine lobe carries the multiple scattering and the diffuse base.
    Spectrum rest = t.fms * (1.0f - e_o) + base_color * ((1.0f - metallic) * (1.0f - e_dielectric(t, mu_o, e_o)));
    float s = luminance(spec), d = luminance(rest);
    return s + d > 0 ? s / (s + d) : 1.0f;
  }

  Spectrum eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    pdf_out = 0.0f;
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    Terms t = terms();
    Vec3f h = normalize(wo + wi);
    float wo_h = dot(wo, h);
    float e_o = e_single(t, wo.z), e_i = e_single(t, wi.z);
    float w = schlick_weight(wo_h);
    Spectrum fresnel = t.f0 + (Spectrum(1.0f) - t.f0) * w;
    float d = t.ggx.d(h);
    Spectrum f = fresnel * (d * t.ggx.g2(wo, wi) / (4.0f * wo.z * wi.z));
    f += t.fms * ((1.0f - e_o) * (1.0f - e_i) * t.ms_norm);
    f += t.diffuse * ((1.0f - e_dielectric(t, wo.z, e_o)) * (1.0f - e_dielectric(t, wi.z, e_i)));
    float p = specular_probability(t, wo.z, e_o);
    pdf_out = p * t.ggx.g1(wo) * d / (4.0f * wo.z) + (1.0f - p) * cosine_hemisphere_pdf(wi.z);
    return f;
  }
  Spectrum eval(const Vec3f& wo, const Vec3f& wi) const {
    float pdf_unused;
    return eval_pdf(wo, wi, pdf_unused);
  }
  float pdf(const Vec3f& wo, const Vec3f& wi) const {
    float p;
    eval_pdf(wo, wi, p);
    return p;
  }
  // u_lobe picks the GGX lobe (visible normals) or the cosine lobe.
  bool sample(const Vec3f& wo, float u_lobe, Vec2f u, BsdfSample& s) const {
    if (wo.z <= 0) return false;
    Terms t = terms();
    float p = specular_probability(t, wo.z, e_single(t, wo.z));
    if (u_lobe < p) {
      Vec3f h = t.ggx.sample_visible_normal(wo, u);
      s.wi = h * (2.0f * dot(wo, h)) - wo;
    } else {
      s.wi = square_to_cosine_hemisphere(u);
    }
    if (s.wi.z <= 0) return false;
    Spectrum f = eval_pdf(wo, s.wi, s.pdf);
    if (!(s.pdf > 0)) return false;
    s.weight = f * (s.wi.z / s.pdf);
    s.specular = false;
    return true;
  }
};

// The material as loaded. glTF's defaults: base colour 1, metallic 1, roughness 1.
struct MetallicRoughness {
  using Bsdf = MetallicRoughnessBsdf;
  static constexpr const char* kName = "metallic-roughness";
  static constexpr uint8_t kFlags = MetallicRoughnessBsdf::kFlags;
  Spectrum base_color{1.0f};
  float metallic = 1.0f;
  float roughness = 1.0f;
  float ior = 1.5f;
  // Indices into Scene::textures(), or -1.
  int base_color_texture = -1;
  int metallic_roughness_texture = -1;  // G: roughness, B: metallic (linear data)
  int roughness_texture = -1;           // luminance multiplies roughness (linear data)
  int metallic_texture = -1;            // luminance multiplies metallic (linear data)

  std::string describe() const {
    bool mr_textured = metallic_roughness_texture >= 0 || roughness_texture >= 0 || metallic_texture >= 0;
    return describe_colour("base", base_color, base_color_texture) + " " + describe_value("metallic", metallic) + " " +
           describe_value("roughness", roughness) + (mr_textured ? " textured" : "") + " " + describe_value("ior", ior);
  }
  MetallicRoughnessBsdf at(const TextureLookup& tex) const {
    // Clamped: a float (EXR) texture may hold more than 1, which would create energy.
    Spectrum base = vmin(vmax(tex.base(base_color_texture, base_color), Spectrum(0.0f)), Spectrum(1.0f));
    MetallicRoughnessBsdf b{base, metallic, roughness, ior};
    if (metallic_roughness_texture >= 0) {
      Spectrum mr = tex.data(metallic_roughness_texture);
      b.roughness = std::clamp(b.roughness * mr.y, 0.0f, 1.0f);
      b.metallic = std::clamp(b.metallic * mr.z, 0.0f, 1.0f);
    }
    if (roughness_texture >= 0) b.roughness = std::clamp(b.roughness * luminance(tex.data(roughness_texture)), 0.0f, 1.0f);
    if (metallic_texture >= 0) b.metallic = std::clamp(b.metallic * luminance(tex.data(metallic_texture)), 0.0f, 1.0f);
    return b;
  }
};

}  // namespace pt
