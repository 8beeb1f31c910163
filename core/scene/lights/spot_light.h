// A spot light: a point light whose intensity falls off with the angle from its axis, as glTF's
// KHR_lights_punctual defines it: full inside the inner cone, nothing outside the outer cone, and
// between them the square of a linear ramp in the cosine (the extension's recommended falloff,
// smooth at the outer edge).
#pragma once
#include <algorithm>

#include "core/math/vec.h"
#include "core/scene/lights/light_bounds.h"
#include "core/scene/lights/light_sample.h"

namespace pt {

class SpotLight {
 public:
  SpotLight() = default;
  // direction: where the cone points (any length > 0); angles in radians, 0 <= inner < outer <= pi/2
  // (the loaders check them).
  SpotLight(const Vec3f& position, const Vec3f& direction, Spectrum intensity, float inner_angle, float outer_angle);

  const Vec3f& position() const { return position_; }
  const Vec3f& direction() const { return direction_; }
  Spectrum intensity() const { return intensity_; }
  float cos_inner() const { return cos_inner_; }
  float cos_outer() const { return cos_outer_; }
  // The emitted power's luminance: I times the falloff integrated over the sphere.
  float power() const;
  // For the light tree: a point whose emission lies within the outer cone (theta_o the inner
  // angle, theta_e the ramp beyond it, as pbrt-v4 bounds its spot lights).
  LightBounds bounds() const;

  // The fraction of the intensity sent at cosine c to the axis.
  float falloff(float c) const {
    float t = std::clamp(c * scale_ + offset_, 0.0f, 1.0f);
    return t * t;
  }
  // The light as seen from p, chosen with probability pick; false outside the cone.
  bool sample(const Vec3f& p, float pick, LightSample& ls) const {
    float d2;
    if (!toward_point(p, position_, &d2, ls)) return false;
    float f = falloff(-dot(ls.wi, direction_));
    if (!(f > 0)) return false;
    ls.radiance = intensity_ * (f / d2);
    ls.pdf = pick;
    return true;
  }

 private:
  Vec3f position_, direction_{0, 0, -1};
  Spectrum intensity_{0};  // W/sr on the axis
  float cos_inner_ = 1, cos_outer_ = 0;
  float scale_ = 1, offset_ = 0;  // the ramp: falloff(c) = clamp(c * scale + offset)^2
};

}  // namespace pt
