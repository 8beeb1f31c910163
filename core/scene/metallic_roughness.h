// glTF's metallic-roughness material (glTF 2.0 specification, appendix B) put onto pt's closed
// set of materials. pt has no microfacet BSDF yet, so this is the one place that approximates it:
// when the metallic-roughness BSDF lands, it replaces this function and nothing else.
//
// The specification's BRDF mixes a dielectric (a diffuse base under a specular layer of
// reflectance F0 = 0.04) and a metal (specular, F0 = base colour) by `metallic`, with a GGX lobe of
// alpha = roughness^2. Here:
//   specular colour  ks = 0.04 (1 - metallic) + base metallic   (F0, Schlick's Fresnel at normal
//                                                                incidence; no rise at grazing angles)
//   diffuse colour   kd = base (1 - metallic) (1 - 0.04)        (what the specular layer lets through)
//   lobe             a modified-Phong lobe of exponent n = 2 / alpha^2 - 2 (Walter et al. 2007,
//                    eq. 33: the Beckmann width that matches Phong's), at most kMaxPhongExponent
// so kd + ks <= 1 in every channel (the glossy material's energy bound). A smooth metal
// (metallic >= 0.5, roughness < kMirrorRoughness) is a mirror tinted by ks: the lobe would be
// sharper than a pixel anyway and a mirror is sampled exactly.
#pragma once
#include "core/math/vec.h"
#include "core/material/material.h"

namespace pt {

struct MetallicRoughness {
  Spectrum base{1.0f};    // baseColorFactor's RGB, 0..1
  float metallic = 1.0f;  // glTF's defaults: a rough metal
  float roughness = 1.0f;
};

inline constexpr float kMirrorRoughness = 0.05f;
inline constexpr float kPhongExponentMax = 10000.0f;
inline constexpr float kDielectricF0 = 0.04f;  // the specification's dielectric reflectance (ior 1.5)

// The pt material closest to `p` (a Glossy or a Mirror model) (name, textures, opacity and
// emission are the loader's). A base colour texture multiplies kd only.
Material metallic_roughness_material(const MetallicRoughness& p);

}  // namespace pt
