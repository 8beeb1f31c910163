#include "core/scene/lights/spot_light.h"

#include <cmath>

namespace pt {

SpotLight::SpotLight(const Vec3f& position, const Vec3f& direction, Spectrum intensity, float inner_angle,
                     float outer_angle)
    : position_(position), direction_(normalize(direction)), intensity_(intensity) {
  cos_inner_ = std::cos(inner_angle);
  cos_outer_ = std::cos(outer_angle);
  // KHR_lights_punctual's recommended form; the 0.001 keeps the ramp finite when the cones meet.
  scale_ = 1.0f / std::max(0.001f, cos_inner_ - cos_outer_);
  offset_ = -cos_outer_ * scale_;
}

LightBounds SpotLight::bounds() const {
  LightBounds b;
  b.box.expand(position_);
  b.phi = power();
  b.axis = direction_;
  b.cos_o = cos_inner_;
  b.cos_e = std::cos(std::acos(std::clamp(cos_outer_, -1.0f, 1.0f)) - std::acos(std::clamp(cos_inner_, -1.0f, 1.0f)));
  return b;
}

float SpotLight::power() const {
  // Over the sphere, the falloff is a function of c = cos(angle to the axis), and dw = 2 pi dc:
  // zero below cos_outer, (c - cos_outer)^2 / w^2 over the ramp of width w = 1 / scale, one above.
  double w = 1.0 / scale_, c0 = cos_outer_;
  double integral = c0 + w <= 1.0 ? w / 3.0 + (1.0 - c0 - w) : std::pow(1.0 - c0, 3.0) / (3.0 * w * w);
  return static_cast<float>(2.0 * kPi * integral * luminance(intensity_));
}

}  // namespace pt
