// An emissive sphere: sampled uniformly over the cone it subtends from outside (PBRT 3rd ed.
// 14.2.2), uniformly over its area from inside (or so close that the cone degenerates).
#pragma once
#include <cstdint>

#include "core/geometry/sphere.h"
#include "core/math/vec.h"
#include "core/scene/lights/light_bounds.h"
#include "core/scene/lights/light_sample.h"

namespace pt {

struct SphereLight {
  uint32_t sphere = 0;  // index in Geometry::spheres()
  Vec3f center;
  float radius = 0, area = 0;
  Spectrum radiance{0};

  SphereLight() = default;
  SphereLight(uint32_t index, const Sphere& s, Spectrum emission)
      : sphere(index), center(s.center), radius(s.radius), area(s.area()), radiance(emission) {}

  float power() const { return kPi * area * luminance(radiance); }
  // For the light tree: its box, emitting every way.
  LightBounds bounds() const {
    LightBounds b;
    b.box.expand(center - Vec3f(radius));
    b.box.expand(center + Vec3f(radius));
    b.phi = power();
    b.cos_o = -1.0f;
    return b;
  }
  // A point of the sphere as seen from p, the sphere chosen with probability pick.
  bool sample(const Vec3f& p, float pick, Vec2f u, LightSample& ls) const;
  // The density sample() gives the point q (normal n) of the sphere seen from p.
  float pdf(const Vec3f& p, float pick, const Vec3f& q, const Vec3f& n) const;

 private:
  bool outside(const Vec3f& p, float* dc2, float* r2) const {
    *dc2 = length_squared(center - p);
    *r2 = radius * radius;
    return *dc2 > *r2 * 1.0001f;
  }
};

}  // namespace pt
