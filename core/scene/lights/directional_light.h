// A directional light: parallel light from infinitely far away along one direction (glTF's
// directional light, a distant sun). A delta light, like the point light; what it delivers is an
// irradiance E (W/m^2 on a surface facing it), so a sample's distance is infinite and its radiance
// is E itself.
#pragma once
#include "core/math/vec.h"
#include "core/scene/lights/light_sample.h"

namespace pt {

struct DirectionalLight {
  Vec3f direction{0, -1, 0};  // unit: the direction the light travels
  Spectrum irradiance{0};     // W/m^2 on a surface facing the light

  // Its power falling on a disc of the scene's radius, to choose it against the other lights.
  float power(float scene_radius) const { return kPi * scene_radius * scene_radius * luminance(irradiance); }

  bool sample(float pick, LightSample& ls) const {
    ls.wi = -direction;
    ls.distance = kInf;
    ls.point = Vec3f(0.0f);
    ls.normal = direction;
    ls.radiance = irradiance;
    ls.pdf = pick;
    ls.delta = true;
    return true;
  }
};

}  // namespace pt
