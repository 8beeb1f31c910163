// metallic-roughness: glTF 2.0's material (specification, Appendix B), which is also Blender's
// Principled BSDF (metallic, roughness, base colour) and the MTL PBR extension (Pr, Pm).
//
// base_color  linear RGB; the diffuse colour of the dielectric and F0 of the metal (texture
//             slot base_color_texture multiplies it, and so does the vertex colour)
// metallic    0 dielectric .. 1 metal; the BSDF is the mix (1 - metallic) dielectric + metallic metal
// roughness   GGX alpha = roughness^2
// ior         the dielectric's index; F0 = ((ior - 1) / (ior + 1))^2 = 0.04 at glTF's 1.5
// clearcoat, clearcoat_roughness  an optional coat over it all (KHR_materials_clearcoat; below,
//             MetallicRoughnessBsdf::Coat)
// Data textures (linear values: registered as TextureEncoding::kData) scale metallic and
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
#include "core/material/rough_dielectric.h"
#include "core/material/texture_lookup.h"
#include "core/math/sampling.h"

namespace pt {

struct MetallicRoughnessBsdf {
  Spectrum base_color{1.0f};
  float metallic = 1.0f;
  float roughness = 1.0f;
  float ior = 1.5f;
  float clearcoat = 0.0f;            // the coat's weight c (KHR_materials_clearcoat)
  float clearcoat_roughness = 0.0f;  // its GGX alpha is clearcoat_roughness^2
  float transmission = 0.0f;         // KHR_materials_transmission's factor (below: transmissive_eval_pdf)

  static constexpr uint8_t kFlags = kBsdfReflection | kBsdfDiffuse | kBsdfGlossy;
  // With transmission the surface has an inside (it is not shaded two-sided).
  uint8_t flags() const { return transmission > 0 ? kFlags | kBsdfTransmission : kFlags; }
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

  // The clear coat (KHR_materials_clearcoat): a dielectric GGX layer of F0 0.04 over the material,
  // with its own multiple-scattering lobe, weighted by c. Its directional albedo is
  // Ec(mu) = 0.04 E + 0.96 E_schlick + (1 - E) Fms at its roughness, and the material under it
  // gets (1 - c Ec(mu_o)) of the light (albedo scaling on the outgoing side, Kulla & Conty 2017):
  //   f = c f_coat + (1 - c Ec(mu_o)) f_material,
  // so a coated white furnace stays white and the albedo is c Ec + (1 - c Ec) E_material. The
  // price: f(wo, wi) - f(wi, wo) = c (Ec(mu_i) - Ec(mu_o)) f_material(wo, wi), not reciprocal
  // (a scaling by both directions' factors would be, but conserves energy only over a
  // Lambertian base). A path tracer evaluates f in one direction only.
  struct Coat {
    Ggx ggx;
    TableCoord r;
    float fms;       // Fms of F0 0.04 at the coat's roughness
    float ms_norm;   // 1 / (pi (1 - E_avg)) of the coat's roughness
  };
  static constexpr float kCoatF0 = 0.04f;  // ior 1.5, as KHR_materials_clearcoat fixes it
  Coat coat() const {
    Coat c{Ggx{std::max(clearcoat_roughness * clearcoat_roughness, kMinGgxAlpha)}, TableCoord(clearcoat_roughness), 0, 0};
    float e_avg = table_lookup(kGgxAlbedoAvg, c.r);
    float f_avg = kCoatF0 + (1.0f - kCoatF0) / 21.0f;
    c.fms = f_avg * f_avg * e_avg / (1.0f - f_avg * (1.0f - e_avg));
    c.ms_norm = 1.0f - e_avg > 1e-6f ? kInvPi / (1.0f - e_avg) : 0.0f;
    return c;
  }
  static float coat_albedo(const Coat& c, float mu, float e) {
    return kCoatF0 * e + (1.0f - kCoatF0) * table_lookup(kGgxAlbedoSchlick, c.r, mu) + (1.0f - e) * c.fms;
  }

  // The luminances of the GGX lobe's albedo at wo and of the cosine-sampled lobes' (the multiple
  // scattering and the diffuse base).
  void lobe_albedos(const Terms& t, float mu_o, float e_o, float& s, float& d) const {
    float e5 = table_lookup(kGgxAlbedoSchlick, t.r, mu_o);
    Spectrum spec = t.f0 * e_o + (Spectrum(1.0f) - t.f0) * e5;
    Spectrum rest = t.fms * (1.0f - e_o) + base_color * ((1.0f - metallic) * (1.0f - e_dielectric(t, mu_o, e_o)));
    s = luminance(spec);
    d = luminance(rest);
  }
  // The probability of sampling the GGX lobe at wo (else the cosine lobe).
  float specular_probability(const Terms& t, float mu_o, float e_o) const {
    float s, d;
    lobe_albedos(t, mu_o, e_o, s, d);
    return s + d > 0 ? s / (s + d) : 1.0f;
  }
  // The probability of sampling the coat at wo, whose albedo there is coat_o = c Ec(mu_o).
  float coat_probability(const Terms& t, float mu_o, float coat_o) const {
    float s, d;
    lobe_albedos(t, mu_o, e_single(t, mu_o), s, d);
    float under = (1.0f - coat_o) * (s + d);
    return coat_o + under > 0 ? coat_o / (coat_o + under) : 1.0f;
  }

  Spectrum eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    if (transmission > 0) return transmissive_eval_pdf(wo, wi, pdf_out);
    pdf_out = 0.0f;
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    Terms t = terms();
    if (clearcoat > 0) return coated_eval_pdf(t, wo, wi, pdf_out);
    return base_eval_pdf(t, wo, wi, pdf_out);
  }
  // The material without its coat (both directions above the surface).
  Spectrum base_eval_pdf(const Terms& t, const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
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
  // The coat lobe, and the material under it scaled by 1 - c Ec(mu_o).
  Spectrum coated_eval_pdf(const Terms& t, const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    Coat c = coat();
    float ec_o = table_lookup(kGgxAlbedo, c.r, wo.z), ec_i = table_lookup(kGgxAlbedo, c.r, wi.z);
    float coat_o = clearcoat * coat_albedo(c, wo.z, ec_o);
    Vec3f h = normalize(wo + wi);
    float d = c.ggx.d(h);
    float fresnel = kCoatF0 + (1.0f - kCoatF0) * schlick_weight(dot(wo, h));
    float f_coat = fresnel * d * c.ggx.g2(wo, wi) / (4.0f * wo.z * wi.z) + c.fms * (1.0f - ec_o) * (1.0f - ec_i) * c.ms_norm;
    float base_pdf;
    Spectrum f = base_eval_pdf(t, wo, wi, base_pdf) * (1.0f - coat_o) + Spectrum(clearcoat * f_coat);
    float p = coat_probability(t, wo.z, coat_o);
    pdf_out = p * c.ggx.g1(wo) * d / (4.0f * wo.z) + (1.0f - p) * base_pdf;
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
  // u_lobe picks the coat (if any), the GGX lobe (visible normals) or the cosine lobe.
  bool sample(const Vec3f& wo, float u_lobe, Vec2f u, BsdfSample& s) const {
    if (transmission > 0) return transmissive_sample(wo, u_lobe, u, s);
    if (wo.z <= 0) return false;
    Terms t = terms();
    bool drawn = false;
    if (clearcoat > 0) {
      Coat c = coat();
      float coat_o = clearcoat * coat_albedo(c, wo.z, table_lookup(kGgxAlbedo, c.r, wo.z));
      float p_coat = coat_probability(t, wo.z, coat_o);
      if (u_lobe < p_coat) {
        Vec3f h = c.ggx.sample_visible_normal(wo, u);
        s.wi = h * (2.0f * dot(wo, h)) - wo;
        drawn = true;
      } else {
        u_lobe = std::min((u_lobe - p_coat) / (1.0f - p_coat), 0x1.fffffep-1f);
      }
    }
    if (!drawn) {
      float p = specular_probability(t, wo.z, e_single(t, wo.z));
      if (u_lobe < p) {
        Vec3f h = t.ggx.sample_visible_normal(wo, u);
        s.wi = h * (2.0f * dot(wo, h)) - wo;
      } else {
        s.wi = square_to_cosine_hemisphere(u);
      }
    }
    if (s.wi.z <= 0) return false;
    Spectrum f = eval_pdf(wo, s.wi, s.pdf);
    if (!(s.pdf > 0)) return false;
    s.weight = f * (s.wi.z / s.pdf);
    s.specular = false;
    return true;
  }

  // KHR_materials_transmission: of the dielectric part (weight 1 - metallic), the fraction
  // `transmission` is a rough dielectric interface (core/material/rough_dielectric.h: GGX
  // reflection and refraction at this roughness and ior, the refracted light tinted by the base
  // colour) instead of the opaque dielectric (specular over Lambert). With w = (1 - metallic)
  // transmission that is
  //   f = (1 - w) f_opaque(metallic / (1 - w)) + w f_interface,
  // the opaque material (coat included) with the metal's share renormalised. Seen from inside
  // (wo.z < 0) only the interface is there, weighted w; the rest absorbs. The interface is not
  // compensated for multiple scattering (its albedo, R + T, falls below 1 with roughness).
  RoughInterface interface() const {
    // ior 0 (KHR_materials_ior allows it: F0 = 1) reflects everything; kept finite.
    return RoughInterface{Ggx{std::max(roughness * roughness, kMinGgxAlpha)}, std::max(ior, 1e-3f), base_color};
  }
  float interface_weight() const { return std::clamp((1.0f - metallic) * transmission, 0.0f, 1.0f); }
  MetallicRoughnessBsdf opaque_part(float w) const {
    MetallicRoughnessBsdf o = *this;
    o.transmission = 0.0f;
    o.metallic = w < 1.0f ? std::min(1.0f, metallic / (1.0f - w)) : 0.0f;
    return o;
  }
  Spectrum transmissive_eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    pdf_out = 0.0f;
    const float w = interface_weight();
    float p_interface;
    Spectrum f = interface().eval_pdf(wo, wi, p_interface) * w;
    if (wo.z < 0) {  // inside: the interface alone is sampled
      pdf_out = p_interface;
      return f;
    }
    float p_opaque = 0.0f;
    if (w < 1.0f) f += opaque_part(w).eval_pdf(wo, wi, p_opaque) * (1.0f - w);
    pdf_out = (1.0f - w) * p_opaque + w * p_interface;
    return f;
  }
  // The interface with probability w (always from inside), else the opaque material.
  bool transmissive_sample(const Vec3f& wo, float u_lobe, Vec2f u, BsdfSample& s) const {
    if (wo.z == 0) return false;
    const float w = interface_weight();
    bool drawn;
    if (wo.z < 0 || u_lobe < w) {
      float v = wo.z < 0 ? u_lobe : std::min(u_lobe / w, 0x1.fffffep-1f);
      drawn = interface().sample(wo, v, u, s);
    } else {
      drawn = opaque_part(w).sample(wo, std::min((u_lobe - w) / (1.0f - w), 0x1.fffffep-1f), u, s);
    }
    if (!drawn) return false;
    Spectrum f = transmissive_eval_pdf(wo, s.wi, s.pdf);
    if (!(s.pdf > 0)) return false;
    s.weight = f * (std::abs(s.wi.z) / s.pdf);
    s.specular = false;
    return true;
  }
};

// The material as loaded. glTF's defaults: base colour 1, metallic 1, roughness 1.
struct MetallicRoughness {
  using Bsdf = MetallicRoughnessBsdf;
  static constexpr const char* kName = "metallic-roughness";
  // The lobes it may show somewhere: transmission where `transmission` > 0.
  static constexpr uint8_t kFlags = MetallicRoughnessBsdf::kFlags | kBsdfTransmission;
  Spectrum base_color{1.0f};
  float metallic = 1.0f;
  float roughness = 1.0f;
  float ior = 1.5f;
  float clearcoat = 0.0f;            // KHR_materials_clearcoat's clearcoatFactor
  float clearcoat_roughness = 0.0f;  // and clearcoatRoughnessFactor
  float transmission = 0.0f;         // KHR_materials_transmission's transmissionFactor
  // Indices into Scene::textures(), or -1.
  int base_color_texture = -1;
  int metallic_roughness_texture = -1;  // G: roughness, B: metallic (linear data)
  int roughness_texture = -1;           // luminance multiplies roughness (linear data)
  int metallic_texture = -1;            // luminance multiplies metallic (linear data)

  bool reads_textures() const {
    return base_color_texture >= 0 || metallic_roughness_texture >= 0 || roughness_texture >= 0 || metallic_texture >= 0;
  }
  std::string describe() const {
    bool mr_textured = metallic_roughness_texture >= 0 || roughness_texture >= 0 || metallic_texture >= 0;
    return describe_colour("base", base_color, base_color_texture) + " " + describe_value("metallic", metallic) + " " +
           describe_value("roughness", roughness) + (mr_textured ? " textured" : "") + " " + describe_value("ior", ior) +
           (clearcoat > 0 ? " " + describe_value("clearcoat", clearcoat) + " " + describe_value("clearcoat_roughness", clearcoat_roughness)
                          : std::string()) +
           (transmission > 0 ? " " + describe_value("transmission", transmission) : std::string());
  }
  MetallicRoughnessBsdf at(const TextureLookup& tex) const {
    // Clamped: a float (EXR) texture may hold more than 1, which would create energy.
    Spectrum base = vmin(vmax(tex.base(base_color_texture, base_color), Spectrum(0.0f)), Spectrum(1.0f));
    MetallicRoughnessBsdf b{base, metallic, roughness, ior, clearcoat, clearcoat_roughness, transmission};
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
