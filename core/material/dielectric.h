// dielectric: smooth glass, exact Fresnel reflection and refraction, index ior, total internal
// reflection (Walter et al. 2007 notation; PBRT 3rd ed. 8.2). wo may be below the surface: the ray
// is then inside the object.
#pragma once
#include <algorithm>
#include <cmath>

#include "core/material/bsdf_sample.h"
#include "core/material/describe.h"
#include "core/material/texture_lookup.h"

namespace pt {

// Unpolarised Fresnel reflectance of a smooth dielectric; eta = eta_t / eta_i. 1 under total
// internal reflection.
inline float fresnel_dielectric(float cos_i, float eta) {
  float sin2_t = std::max(0.0f, 1.0f - cos_i * cos_i) / (eta * eta);
  if (sin2_t >= 1.0f) return 1.0f;
  float cos_t = std::sqrt(1.0f - sin2_t);
  float r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
  float r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
  return 0.5f * (r_par * r_par + r_perp * r_perp);
}

struct DielectricBsdf {
  float ior = 1.5f;

  static constexpr uint8_t kFlags = kBsdfReflection | kBsdfTransmission | kBsdfDelta;
  static constexpr bool kDrawsDirection = false;  // two directions, chosen by u_lobe
  uint8_t flags() const { return kFlags; }
  Spectrum albedo() const { return Spectrum(1.0f); }

  Spectrum eval(const Vec3f&, const Vec3f&) const { return Spectrum(0.0f); }
  float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
  Spectrum eval_pdf(const Vec3f&, const Vec3f&, float& pdf_out) const {
    pdf_out = 0.0f;
    return Spectrum(0.0f);
  }
  // u_lobe chooses reflection (with probability Fresnel) or refraction.
  bool sample(const Vec3f& wo, float u_lobe, Vec2f /*u*/, BsdfSample& s) const {
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
};

struct Dielectric {
  using Bsdf = DielectricBsdf;
  static constexpr const char* kName = "dielectric";
  static constexpr uint8_t kFlags = DielectricBsdf::kFlags;
  float ior = 1.5f;

  std::string describe() const { return describe_value("ior", ior); }
  bool reads_textures() const { return false; }
  DielectricBsdf at(const TextureLookup&) const { return {ior}; }
};

}  // namespace pt
