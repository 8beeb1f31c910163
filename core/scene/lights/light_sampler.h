// The light sampler: which light a shading point samples. It is separate from the lights (which
// sample a point of themselves once chosen), so that a better choice replaces the old one here
// alone (power_light_sampler.h chooses by power). LightSet (light_set.h) owns one and asks it for
// every light sample and every MIS pdf.
#pragma once
#include <cstdint>
#include <vector>

#include "core/math/vec.h"
#include "core/scene/render_settings.h"

namespace pt {

// A chosen light. For a triangle light that belongs to a TriangleGroup (triangle_light.h) it also
// carries the group's share, so that a near group can choose its member by solid angle instead.
struct LightChoice {
  uint32_t light = 0;      // index in LightSet::lights()
  float pick = 0;          // the probability of choosing it at this shading point
  float u_rest = 0;        // the selection number remapped to [0, 1) within the choice
  float group_pick = 0;    // triangle in a group: the probability of choosing any member ...
  float group_offset = 0;  // ... and the summed probability of the members before this one
};

// The members of a TriangleGroup as LightSet lights: first .. first + count - 1.
struct LightGroupRange {
  uint32_t first = 0, count = 0;
};

class LightSampler {
 public:
  virtual ~LightSampler() = default;
  // Chooses a light for the shading point p whose surface has normal n (the side the light must
  // lie on; zero when any direction may receive light), with u uniform in [0, 1). False when no
  // light can be chosen there.
  virtual bool sample(const Vec3f& p, const Vec3f& n, float u, LightChoice& choice) const = 0;
  // The probability that sample(p, n, ...) chooses light; exactly the pick sample() reports.
  virtual float pdf(const Vec3f& p, const Vec3f& n, uint32_t light) const = 0;
  // The probability of choosing any member of triangle group g (TriangleLights::groups()).
  virtual float group_pdf(const Vec3f& p, const Vec3f& n, uint32_t group) const = 0;
  // The probability of an infinitely distant light (the environment, a directional light), which
  // no sampler makes depend on the shading point.
  virtual float infinite_pdf(uint32_t light) const = 0;
};

}  // namespace pt
