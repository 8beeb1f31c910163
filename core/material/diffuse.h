// diffuse: Lambertian reflection, albedo kd (optionally textured).
#pragma once
#include "core/material/bsdf_sample.h"
#include "core/material/describe.h"
#include "core/material/texture_lookup.h"
#include "core/math/sampling.h"

namespace pt {

struct DiffuseBsdf {
  Spectrum kd;

  static constexpr uint8_t kFlags = kBsdfReflection | kBsdfDiffuse;
  static constexpr bool kDrawsLobe = false;  // one lobe
  uint8_t flags() const { return kFlags; }
  Spectrum albedo() const { return kd; }

  Spectrum eval(const Vec3f& wo, const Vec3f& wi) const {
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    return kd * kInvPi;
  }
  float pdf(const Vec3f& wo, const Vec3f& wi) const {
    if (wo.z <= 0 || wi.z <= 0) return 0.0f;
    return cosine_hemisphere_pdf(wi.z);
  }
  Spectrum eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    pdf_out = 0.0f;
    if (wo.z <= 0 || wi.z <= 0) return Spectrum(0.0f);
    pdf_out = cosine_hemisphere_pdf(wi.z);
    return kd * kInvPi;
  }
  bool sample(const Vec3f& wo, float /*u_lobe*/, Vec2f u, BsdfSample& s) const {
    if (wo.z <= 0) return false;
    s.wi = square_to_cosine_hemisphere(u);
    s.pdf = cosine_hemisphere_pdf(s.wi.z);
    s.weight = kd;
    s.specular = false;
    return s.pdf > 0;
  }
};

// The material as loaded.
struct Diffuse {
  using Bsdf = DiffuseBsdf;
  static constexpr const char* kName = "diffuse";
  static constexpr uint8_t kFlags = DiffuseBsdf::kFlags;
  Spectrum kd{0.8f};
  int kd_texture = -1;  // index into Scene::textures(), or -1

  std::string describe() const { return describe_colour("kd", kd, kd_texture); }
  bool reads_textures() const { return kd_texture >= 0; }
  DiffuseBsdf at(const TextureLookup& tex) const { return {tex.base(kd_texture, kd)}; }
};

}  // namespace pt
