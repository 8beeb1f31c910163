// The closed set of materials and their BSDFs, evaluated in the local shading frame (z = normal).
//
// diffuse     Lambertian, albedo kd (optionally textured).
// mirror      perfect specular reflection tinted by ks.
// dielectric  smooth glass: exact Fresnel reflection and refraction, index ior, total internal
//             reflection (Walter et al. 2007 notation; PBRT 3rd ed. 8.2).
// glossy      kd Lambertian plus a normalised modified-Phong lobe ks (n+2)/(2 pi) cos^n(alpha)
//             around the mirror direction (Lafortune & Willems 1994), n = MTL Ns. Energy
//             conserving as long as kd + ks <= 1 per channel, which the loaders enforce.
#pragma once
#include <cstdint>
#include <string>

#include "core/math/frame.h"
#include "core/math/sampling.h"
#include "core/math/vec.h"
#include "core/util/names.h"

namespace pt {

enum class MaterialType : uint8_t { kDiffuse, kMirror, kDielectric, kGlossy };
inline constexpr NameTable<MaterialType, 4> kMaterialTypeNames{
    "material type",
    {{{MaterialType::kDiffuse, "diffuse"}, {MaterialType::kMirror, "mirror"}, {MaterialType::kDielectric, "dielectric"},
      {MaterialType::kGlossy, "glossy"}}}};

struct Material {
  std::string name;
  MaterialType type = MaterialType::kDiffuse;
  Spectrum kd{0.8f};
  int kd_texture = -1;  // index into Scene::textures(), or -1
  Spectrum ks{0.0f};
  float exponent = 1.0f;  // Phong exponent of the glossy lobe
  float ior = 1.5f;
  Spectrum emission{0.0f};  // radiance leaving the front face; non-zero makes the surface a light
  // Coverage (MTL `d`): the fraction of the surface that is there. Rays pass the rest unchanged:
  // at a hit they go straight on with probability 1 - opacity (stochastic transparency), and a
  // shadow ray lets 1 - opacity through. Lights are opaque (the loaders enforce it).
  float opacity = 1.0f;
  bool is_emissive() const { return max_component(emission) > 0; }
  bool is_partly_transparent() const { return opacity < 1.0f; }
};

// A BSDF instance at a shading point: the material with its texture already looked up.
struct Bsdf {
  MaterialType type = MaterialType::kDiffuse;
  Spectrum kd, ks;
  float exponent = 1.0f;
  float ior = 1.5f;

  bool is_specular() const { return type == MaterialType::kMirror || type == MaterialType::kDielectric; }
  bool has_diffuse() const { return type == MaterialType::kDiffuse || type == MaterialType::kGlossy; }
  // Probability of choosing the glossy lobe when sampling a glossy material.
  float glossy_weight() const {
    float d = luminance(kd), s = luminance(ks);
    return d + s > 0 ? s / (d + s) : 0.0f;
  }

  // f(wo, wi) without the cosine; zero for the specular types.
  Spectrum eval(const Vec3f& wo, const Vec3f& wi) const {
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    switch (type) {
      case MaterialType::kDiffuse:
        return kd * kInvPi;
      case MaterialType::kGlossy: {
        float cos_alpha = dot(reflect(wo, {0, 0, 1}), wi);
        Spectrum f = kd * kInvPi;
        if (cos_alpha > 0) f += ks * ((exponent + 2.0f) / (2.0f * kPi) * std::pow(cos_alpha, exponent));
        return f;
      }
      default:
        return Spectrum(0.0f);
    }
  }

  float pdf(const Vec3f& wo, const Vec3f& wi) const {
    if (wo.z <= 0 || wi.z <= 0) return 0.0f;
    switch (type) {
      case MaterialType::kDiffuse:
        return cosine_hemisphere_pdf(wi.z);
      case MaterialType::kGlossy: {
        float g = glossy_weight();
        float cos_alpha = dot(reflect(wo, {0, 0, 1}), wi);
        return (1 - g) * cosine_hemisphere_pdf(wi.z) + g * phong_lobe_pdf(cos_alpha, exponent);
      }
      default:
        return 0.0f;
    }
  }

  // eval() and pdf() in one go: the light-sampling path needs both, and the glossy lobe's
  // reflection vector and power are then computed once.
  Spectrum eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    pdf_out = 0.0f;
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    switch (type) {
      case MaterialType::kDiffuse:
        pdf_out = cosine_hemisphere_pdf(wi.z);
        return kd * kInvPi;
      case MaterialType::kGlossy: {
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
      default:
        return Spectrum(0.0f);
    }
  }

  struct Sample {
    Vec3f wi;
    Spectrum weight;  // f * |cos| / pdf
    float pdf = 0;    // 0 for specular events (a delta distribution)
    bool specular = false;
  };

  // wo may be below the surface only for the dielectric (the ray is inside the object).
  // u_lobe chooses a lobe or reflection vs refraction; u chooses the direction.
  bool sample(const Vec3f& wo, float u_lobe, Vec2f u, Sample& s) const {
    switch (type) {
      case MaterialType::kDiffuse: {
        if (wo.z <= 0) return false;
        s.wi = square_to_cosine_hemisphere(u);
        s.pdf = cosine_hemisphere_pdf(s.wi.z);
        s.weight = kd;
        s.specular = false;
        return s.pdf > 0;
      }
      case MaterialType::kGlossy: {
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
      case MaterialType::kMirror: {
        if (wo.z <= 0) return false;
        s.wi = {-wo.x, -wo.y, wo.z};
        s.weight = ks;
        s.pdf = 0;
        s.specular = true;
        return true;
      }
      case MaterialType::kDielectric:
        return sample_dielectric(wo, u_lobe, s);
    }
    return false;
  }

 private:
  bool sample_dielectric(const Vec3f& wo, float u_lobe, Sample& s) const {
    bool entering = wo.z > 0;
    float eta = entering ? ior : 1.0f / ior;  // eta_t / eta_i
    float cos_i = std::abs(wo.z);
    float fr = fresnel_dielectric(cos_i, eta);
    s.pdf = 0;
    s.specular = true;
    if (u_lobe < fr) {
      s.wi = {-wo.x, -wo.y, wo.z};
      s.weight = Spectrum(1.0f);
      return true;
    }
    float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
    float cos_t = std::sqrt(std::max(0.0f, 1.0f - sin2_t));
    // Refracted direction: -wo/eta + (cos_i/eta - cos_t) n, with n on the side of wo.
    Vec3f n{0, 0, entering ? 1.0f : -1.0f};
    s.wi = -wo / eta + n * (cos_i / eta - cos_t);
    // Radiance is compressed by 1/eta^2 crossing into the denser medium (PBRT 3rd ed. 8.2.3).
    s.weight = Spectrum(1.0f / (eta * eta));
    return true;
  }

 public:
  // Unpolarised Fresnel reflectance of a smooth dielectric; eta = eta_t / eta_i. 1 under total
  // internal reflection.
  static float fresnel_dielectric(float cos_i, float eta) {
    float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
    if (sin2_t >= 1.0f) return 1.0f;
    float cos_t = std::sqrt(1.0f - sin2_t);
    float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    return 0.5f * (r_par * r_par + r_perp * r_perp);
  }
};

}  // namespace pt
