// Normal and bump mapping, and the remedy for what a perturbed shading normal does at grazing views.
//
// A shading normal that tilts away from the viewer puts wo below its hemisphere: a BSDF evaluated in
// that frame is black there (the dark side of a normal map), and a mirror direction about it points
// into the surface (which the integrators drop rather than leak through). pt bends such a normal
// just far enough that the reflection of wo stays above the geometric surface: Keller et al. 2017,
// "The Iray Light Transport Simulation and Rendering System", "local shading normal adaptation":
// the reflected direction is lowered to just above the tangent plane and the normal becomes the half
// vector of wo and it. The result always faces wo, so the surface is never black from the front.
// Light from below the geometric surface is refused as before (integrators/integrator.cpp), so no
// light leaks through; and a Lambertian surface under a uniform sky then reflects
// (1 + cos tilt) / 2 of it, never more than 1 (tests/test_unit_normal_map.cpp). Applied only where a
// map perturbed the normal: interpolated vertex normals keep their images.
#pragma once
#include "core/math/vec.h"

namespace pt {

// Returns ns, or ns bent toward wo as above (ns, ng, wo unit; ns on the side of ng).
inline Vec3f adapt_shading_normal(const Vec3f& ns, const Vec3f& ng, const Vec3f& wo) {
  constexpr float kAbove = 0.01f;  // the lowest a reflected direction may run, as a cosine
  const float side = dot(wo, ng) < 0 ? -1.0f : 1.0f;
  const Vec3f n = ns * side, g = ng * side;  // both on the side of wo
  Vec3f r = n * (2.0f * dot(wo, n)) - wo;
  float up = dot(r, g);
  if (up >= kAbove) return ns;
  Vec3f flat = r - g * up;
  float fl = length(flat);
  Vec3f r2 = fl > 1e-6f ? flat * (std::sqrt(1.0f - kAbove * kAbove) / fl) + g * kAbove : g;
  Vec3f h = wo + r2;
  float hl = length(h);
  if (!(hl > 1e-6f)) return ng;
  return h * (side / hl);
}

}  // namespace pt
