// glossy: kd Lambertian plus a normalised modified-Phong lobe ks (n+2)/(2 pi) cos^n(alpha) around
// the mirror direction (Lafortune & Willems 1994), n = MTL Ns. Energy conserving as long as
// kd + ks <= 1 per channel, which the loaders enforce.
#pragma once
#include <cmath>

#include "core/material/bsdf_sample.h"
#include "core/material/describe.h"
#include "core/material/texture_lookup.h"
#include "core/math/frame.h"
#include "core/math/sampling.h"

namespace pt {

struct GlossyBsdf {
  Spectrum kd, ks;
  float exponent = 1.0f;

  static constexpr uint8_t kFlags = kBsdfReflection | kBsdfDiffuse | kBsdfGlossy;
  uint8_t flags() const { return kFlags; }
  Spectrum albedo() const { return kd; }

  // Probability of choosing the Phong lobe when sampling.
  float glossy_weight() const {
    float d = luminance(kd), s = luminance(ks);
    return d + s > 0 ? s / (d + s) : 0.0f;
  }

  Spectrum eval(const Vec3f& wo, const Vec3f& wi) const {
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    float cos_alpha = dot(reflect(wo, {0, 0, 1}), wi);
    Spectrum f = kd * kInvPi;
    if (cos_alpha > 0) f += ks * ((exponent + 2.0f) / (2.0f * kPi) * std::pow(cos_alpha, exponent));
    return f;
  }
  float pdf(const Vec3f& wo, const Vec3f& wi) const {
    if (wo.z <= 0 || wi.z <= 0) return 0.0f;
    float g = glossy_weight();
    float cos_alpha = dot(reflect(wo, {0, 0, 1}), wi);
    return (1 - g) * cosine_hemisphere_pdf(wi.z) + g * phong_lobe_pdf(cos_alpha, exponent);
  }
  // The reflection vector and the power computed once for both.
  Spectrum eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    pdf_out = 0.0f;
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    float g = glossy_weight();
    float cos_alpha = dot(reflect(wo, {0, 0, 1}), wi);
    Spectrum f = kd * kInvPi;
    pdf_out = (1 - g) * cosine_hemisphere_pdf(wi.z);
    if (cos_alpha > 0) {
      float lobe = std::pow(cos_alpha, exponent);
      f += ks * ((exponent + 2.0f) / (2.0f * kPi) * lobe);
      pdf_out += g * (exponent + 1.0f) / (2.0f * kPi) * lobe;  // phong_lobe_pdf
    }
    return f;
  }
  // u_lobe chooses the Phong lobe (with probability glossy_weight) or the Lambertian one.
  bool sample(const Vec3f& wo, float u_lobe, Vec2f u, BsdfSample& s) const {
    if (wo.z <= 0) return false;
    float g = glossy_weight();
    if (u_lobe < g) {
      Vec3f r = reflect(wo, {0, 0, 1});
      Frame lobe(r);
      s.wi = lobe.to_world(square_to_phong_lobe(u, exponent));
    } else {
      s.wi = square_to_cosine_hemisphere(u);
    }
    if (s.wi.z <= 0) return false;
    s.pdf = pdf(wo, s.wi);
    if (!(s.pdf > 0)) return false;
    s.weight = eval(wo, s.wi) * (s.wi.z / s.pdf);
    s.specular = false;
    return true;
  }
};

struct Glossy {
  using Bsdf = GlossyBsdf;
  static constexpr const char* kName = "glossy";
  static constexpr uint8_t kFlags = GlossyBsdf::kFlags;
  Spectrum kd{0.8f};
  int kd_texture = -1;  // index into Scene::textures(), or -1
  Spectrum ks{0.2f};
  float exponent = 50.0f;  // Phong exponent of the glossy lobe

  bool reads_textures() const { return kd_texture >= 0; }
  std::string describe() const {
    return describe_colour("kd", kd, kd_texture) + " " + describe_colour("ks", ks) + " " + describe_value("exponent", exponent);
  }
  GlossyBsdf at(const TextureLookup& tex) const { return {tex.base(kd_texture, kd), ks, exponent}; }
};

}  // namespace pt
