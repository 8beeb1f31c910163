// What the light hierarchy (light_tree.h) knows of an emitter or a cluster of them: a bounding box,
// the emitted power, and an orientation cone, as in Conty Estevez & Kulla, "Importance Sampling of
// Many Lights with Adaptive Tree Splitting" (HPG 2018), section 4: every emitting normal lies within
// theta_o of `axis`, and each emits within theta_e of its normal.
#pragma once
#include <algorithm>
#include <cmath>

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

// The importance of a cluster for a shading point p with unit normal n (zero: no normal): the power
// over the squared distance (no closer than the box's bounding sphere), times the cosine of the
// smallest angle any of its emitters could send toward p at, times the cosine of the smallest
// angle a direction into the box makes with n; zero when no emitter of the cluster can light p
// (section 4.3, with the normal's bound as in pbrt-v4's LightBounds::Importance). Light arriving
// below the surface counts for nothing: pt's integrators drop it (integrators/integrator.cpp).
float importance(const LightBounds& b, const Vec3f& p, const Vec3f& n);

}  // namespace pt
