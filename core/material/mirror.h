// mirror: perfect specular reflection tinted by ks.
#pragma once
#include "core/material/bsdf_sample.h"
#include "core/material/describe.h"
#include "core/material/texture_lookup.h"

namespace pt {

struct MirrorBsdf {
  Spectrum ks;

  static constexpr uint8_t kFlags = kBsdfReflection | kBsdfDelta;
  static constexpr bool kDrawsLobe = false, kDrawsDirection = false;  // one direction
  uint8_t flags() const { return kFlags; }
  // A perfect mirror reflects ks at every angle; mirror light sampling uses this as the tint.
  Spectrum albedo() const { return ks; }

  Spectrum eval(const Vec3f&, const Vec3f&) const { return Spectrum(0.0f); }
  float pdf(const Vec3f&, const Vec3f&) const { return 0.0f; }
  Spectrum eval_pdf(const Vec3f&, const Vec3f&, float& pdf_out) const {
    pdf_out = 0.0f;
    return Spectrum(0.0f);
  }
  bool sample(const Vec3f& wo, float /*u_lobe*/, Vec2f /*u*/, BsdfSample& s) const {
    if (wo.z <= 0) return false;
    s.wi = {-wo.x, -wo.y, wo.z};
    s.weight = ks;
    s.pdf = 0;
    s.specular = true;
    return true;
  }
};

struct Mirror {
  using Bsdf = MirrorBsdf;
  static constexpr const char* kName = "mirror";
  static constexpr uint8_t kFlags = MirrorBsdf::kFlags;
  Spectrum ks{1.0f};

  std::string describe() const { return describe_colour("ks", ks); }
  bool reads_textures() const { return false; }
  MirrorBsdf at(const TextureLookup&) const { return {ks}; }
};

}  // namespace pt
