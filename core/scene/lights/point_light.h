// A point light: intensity I (W/sr) in every direction from one point; a delta light, never hit by
// BSDF sampling, so it has no pdf.
#pragma once
#include "core/math/vec.h"
#include "core/scene/lights/light_bounds.h"
#include "core/scene/lights/light_sample.h"

namespace pt {

struct PointLight {
  Vec3f position;
  Spectrum intensity{0};  // W/sr

  float power() const { return 4.0f * kPi * luminance(intensity); }
  // For the light tree: a point, emitting every way.
  LightBounds bounds() const {
    LightBounds b;
    b.box.expand(position);
    b.phi = power();
    b.cos_o = -1.0f;
    return b;
  }

  // The light as seen from p, chosen with probability pick.
  bool sample(const Vec3f& p, float pick, LightSample& ls) const {
    float d2;
    if (!toward_point(p, position, &d2, ls)) return false;
    ls.radiance = intensity / d2;
    ls.pdf = pick;
    return true;
  }
};

}  // namespace pt
