// What sampling a light returns, and the area-light densities every surface light shares. Each
// light kind (one file each in this folder) samples a point or direction of itself as seen from a
// shading point and answers the density of the same point; MIS weighs a BSDF-sampled hit with that
// density, so a kind's sample and pdf must round alike (both go through area_to_solid_angle).
#pragma once
#include <cmath>

#include "core/math/vec.h"

namespace pt {

// A sampled light direction as seen from a shading point.
struct LightSample {
  Spectrum radiance{0};  // arriving along -wi (intensity / r^2 for point and spot lights)
  Vec3f wi;              // unit direction from the shading point toward the light
  Vec3f point, normal;   // point on the light and its normal (area lights)
  float distance = kInf; // along wi; kInf for the environment and directional lights
  float pdf = 0;         // solid-angle density including the choice of light; the choice alone for delta lights
  bool delta = false;    // point, spot and directional lights: cannot be hit by BSDF sampling
};

// The direction and distance from p to a light's point q (a point or spot light's position);
// false when they coincide. Returns the squared distance in *d2.
inline bool toward_point(const Vec3f& p, const Vec3f& q, float* d2, LightSample& ls) {
  Vec3f d = q - p;
  *d2 = length_squared(d);
  if (!(*d2 > 0)) return false;
  ls.distance = std::sqrt(*d2);
  ls.wi = d / ls.distance;
  ls.point = q;
  ls.normal = -ls.wi;
  ls.pdf = 0;
  ls.delta = true;
  return true;
}

// The density over solid angle of a point chosen with density weight/area over a light's area,
// seen from d2 away at cosine cos_l to the light's normal (p_w = p_A d^2 / cos). Every area-light
// sample and pdf goes through it, so a sample and the pdf of the same point round alike.
inline float area_to_solid_angle(float weight, float d2, float cos_l, float area) {
  return weight * d2 / (cos_l * area);
}

// A point q with normal n, chosen with density pick / area on a light's surface, seen from p.
inline bool area_sample(const Vec3f& p, const Vec3f& q, const Vec3f& n, float pick, float area, LightSample& ls) {
  Vec3f d = q - p;
  float d2 = length_squared(d);
  if (!(d2 > 0)) return false;
  ls.distance = std::sqrt(d2);
  ls.wi = d / ls.distance;
  float cos_l = -dot(ls.wi, n);
  if (cos_l <= 0) return false;
  ls.point = q;
  ls.normal = n;
  ls.pdf = area_to_solid_angle(pick, d2, cos_l, area);
  return true;
}

// The density area_sample gives the point q (normal n) seen from p.
inline float area_pdf(const Vec3f& p, const Vec3f& q, const Vec3f& n, float pick, float area) {
  Vec3f d = q - p;
  float d2 = length_squared(d);
  float cos_l = std::abs(dot(d, n)) / std::sqrt(d2);
  return cos_l > 0 ? area_to_solid_angle(pick, d2, cos_l, area) : 0.0f;
}

}  // namespace pt
