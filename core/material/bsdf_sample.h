// What every BSDF model shares: its lobe flags and the result of sampling it. A model's BSDF at a
// shading point (DiffuseBsdf, GlossyBsdf ...) works in the local shading frame (z = normal) and
// provides
//   uint8_t  flags() const                          the lobes it has (BsdfFlags)
//   Spectrum albedo() const                         the reflectance shown in the albedo AOV
//   Spectrum eval(wo, wi) const                     f(wo, wi) without the cosine; 0 for delta lobes
//   float    pdf(wo, wi) const                      the solid-angle density sample() draws wi with
//   Spectrum eval_pdf(wo, wi, float& pdf) const     both at once (light sampling needs both)
//   bool     sample(wo, u_lobe, u, BsdfSample&) const
// and, where sample() ignores u_lobe or u, `static constexpr bool kDrawsLobe = false` or
// `kDrawsDirection = false`, so that no sampler dimension is drawn for it (Bsdf::sample).
// core/material/bsdf.h dispatches to them.
#pragma once
#include <cstdint>

#include "core/math/vec.h"

namespace pt {

// Lobe flags, as pbrt-v4's BxDFFlags: where light goes (reflection, transmission) and how
// (diffuse, glossy, delta). The integrators decide from these, never from the model.
enum BsdfFlags : uint8_t {
  kBsdfReflection = 1,
  kBsdfTransmission = 2,
  kBsdfDiffuse = 4,
  kBsdfGlossy = 8,
  kBsdfDelta = 16,  // a Dirac distribution: eval and pdf are 0, only sample() finds it
};

struct BsdfSample {
  Vec3f wi;
  Spectrum weight;  // f * |cos| / pdf
  float pdf = 0;    // 0 for specular events (a delta distribution)
  bool specular = false;
};

// Whether B::sample reads u_lobe / u: true unless B says otherwise.
template <class B>
constexpr bool bsdf_draws_lobe() {
  if constexpr (requires { B::kDrawsLobe; }) {
    return B::kDrawsLobe;
  } else {
    return true;
  }
}
template <class B>
constexpr bool bsdf_draws_direction() {
  if constexpr (requires { B::kDrawsDirection; }) {
    return B::kDrawsDirection;
  } else {
    return true;
  }
}

}  // namespace pt
