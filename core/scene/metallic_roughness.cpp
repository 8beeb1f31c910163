#include "core/scene/metallic_roughness.h"

#include <algorithm>

namespace pt {

Material metallic_roughness_material(const MetallicRoughness& p) {
  float metallic = std::clamp(p.metallic, 0.0f, 1.0f);
  float roughness = std::clamp(p.roughness, 0.0f, 1.0f);
  Material out;
  Spectrum ks = Spectrum(kDielectricF0 * (1.0f - metallic)) + p.base * metallic;
  if (metallic >= 0.5f && roughness < kMirrorRoughness) {
    out.model = Mirror{ks};
    return out;
  }
  Glossy g;
  g.ks = ks;
  g.kd = p.base * ((1.0f - metallic) * (1.0f - kDielectricF0));
  float alpha = roughness * roughness;
  float a2 = alpha * alpha;
  // 2 / a2 - 2 only where it stays below the cap (a2 near 0 would overflow to inf).
  g.exponent = a2 * (kPhongExponentMax + 2.0f) > 2.0f ? std::max(1.0f, 2.0f / a2 - 2.0f) : kPhongExponentMax;
  out.model = g;
  return out;
}

}  // namespace pt
