// The environment as a light: its own importance sampling (core/scene/environment.h), chosen
// against the other lights by its power over a disc of the scene's radius.
#pragma once
#include "core/scene/environment.h"
#include "core/scene/lights/light_sample.h"

namespace pt {

struct EnvironmentLight {
  const Environment* environment = nullptr;  // the Scene's, which never moves

  float power(float scene_radius) const {
    return kPi * kPi * scene_radius * scene_radius * luminance(environment->average());
  }
  bool sample(float pick, Vec2f u, LightSample& ls) const {
    float pdf;
    ls.wi = environment->sample(u, &pdf);
    if (!(pdf > 0)) return false;
    ls.radiance = environment->eval(ls.wi);
    ls.distance = kInf;
    ls.pdf = pick * pdf;
    ls.delta = false;
    return true;
  }
  float pdf(float pick, const Vec3f& dir) const { return pick * environment->pdf(dir); }
};

}  // namespace pt
