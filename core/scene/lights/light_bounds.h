// What the light hierarchy (light_tree.h) knows of an emitter or a cluster of them: a bounding box,
// the emitted power, and an orientation cone, as in Conty Estevez & Kulla, "Importance Sampling of
// Many Lights with Adaptive Tree Splitting" (HPG 2018), section 4: every emitting normal lies within
// theta_o of `axis`, and each emits within theta_e of its normal.
#pragma once
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/math/bbox.h"
#include "core/math/vec.h"

namespace pt {

struct LightBounds {
  BBox box;
  float phi = 0;          // power (the luminance of the emitted flux)
  Vec3f axis{0, 0, 1};    // unit
  float cos_o = 1;        // cos theta_o: the normals' spread around the axis (-1: every direction)
  float cos_e = 0;        // cos theta_e: the emission's spread around each normal (0: a hemisphere)

  bool empty() const { return box.empty(); }
};

// The union of two bounds: boxes and powers add, cones merge into the smallest cone the
// construction of the paper's appendix gives (the cone around both, its axis turned from a's
// toward b's), emission spreads take the larger.
LightBounds merge(const LightBounds& a, const LightBounds& b);

// The paper's orientation measure M_Omega (section 4.4): the solid angle the cone's emission can
// reach, weighted by the cosine falloff at its rim; the build's cost is phi * M_Omega * area.
float orientation_measure(const LightBounds& b);

// What the descent reads of a cluster, precomputed from its LightBounds: the centre, radius and
// squared radius of its box's bounding sphere, and the sine of theta_o beside its cosine.
struct LightCone {
  Vec3f center;
  float radius2 = 0;
  Vec3f axis{0, 0, 1};
  float phi = 0;
  float cos_o = 1, sin_o = 0, cos_e = 0, radius = 0;
  // Where every emitter faces the axis exactly (theta_o = 0) and none emits behind itself
  // (theta_e <= 90 degrees), they light only points p with dot(p - center, axis) >= -behind: the
  // box's depth along the axis below its centre (and a hair). Infinite otherwise.
  float behind = std::numeric_limits<float>::infinity();
};
LightCone light_cone(const LightBounds& b);

// The importance of a cluster for a shading point p with unit normal n (zero: no normal): the power
// over the squared distance (no closer than the box's bounding sphere), times the cosine of the
// smallest angle any of its emitters could send toward p at, times the cosine of the smallest
// angle a direction into the box makes with n; zero when no emitter of the cluster can light p
// (section 4.3, with the normal's bound as in pbrt-v4's LightBounds::Importance). Light arriving
// below the surface counts for nothing: pt's integrators drop it (integrators/integrator.cpp).
// Inline: the descent evaluates it twice per level of every light sample.
inline float importance(const LightCone& b, const Vec3f& p, const Vec3f& n) {
  constexpr float kMaxImportance = 1e30f;  // two siblings' importances still add up to a finite sum
  if (!(b.phi > 0)) return 0.0f;
  Vec3f to_p = p - b.center;
  float dist2 = length_squared(to_p);
  // Behind a cluster of one-sided emitters that all face one way: nothing, even inside its
  // bounding sphere, where the cone bound says nothing (the lit windows of a facade, seen from the
  // wall around them; a ceiling of panels, from the ceiling).
  if (dot(b.axis, to_p) < -b.behind) return 0.0f;
  if (!(dist2 > b.radius2)) {
    // Inside the bounding sphere: every direction is possible, and the distance is the radius.
    return std::min(b.phi / std::max(b.radius2, 1e-30f), kMaxImportance);
  }
  // theta_b: the half-angle of the cone of directions from p into the bounding sphere. One
  // division and two or three square roots in all: this runs twice per level of every descent.
  float inv_dist = 1.0f / std::sqrt(dist2);
  Vec3f wi = to_p * inv_dist;
  float sin_b = b.radius * inv_dist, cos_b = std::sqrt(std::max(0.0f, 1.0f - sin_b * sin_b));
  // cos theta': the smallest angle between an emitter's normal and the direction to p,
  // max(0, theta_w - theta_o - theta_b), through the cosines and sines of the angles.
  float cos_p = 1.0f;
  if (b.cos_o > -1.0f) {
    float cos_w = dot(b.axis, wi);
    if (cos_w < b.cos_o) {  // theta_w > theta_o: x = theta_w - theta_o
      float sin_w = std::sqrt(std::max(0.0f, 1.0f - cos_w * cos_w));
      float cos_x = cos_w * b.cos_o + sin_w * b.sin_o, sin_x = sin_w * b.cos_o - cos_w * b.sin_o;
      if (cos_x < cos_b) cos_p = cos_x * cos_b + sin_x * sin_b;  // x > theta_b
    }
  }
  if (cos_p < b.cos_e) return 0.0f;  // (a spot whose cone has no ramp has cos_e = 1)
  float result = b.phi * cos_p * (inv_dist * inv_dist);
  if (n.x != 0 || n.y != 0 || n.z != 0) {
    // The smallest angle between n and a direction from p into the sphere: max(0, theta_i - theta_b).
    float cos_i = -dot(n, wi);
    if (cos_i < cos_b) {
      float sin_i = std::sqrt(std::max(0.0f, 1.0f - cos_i * cos_i));
      float cos_ip = cos_i * cos_b + sin_i * sin_b;
      if (cos_ip <= 0) return 0.0f;
      result *= cos_ip;
    }
  }
  return std::min(result, kMaxImportance);
}

}  // namespace pt
