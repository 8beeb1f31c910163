// Chooses a light in proportion to its power, wherever the shading point is: the simplest
// sampler, and the best where a few lights all light most of the scene.
#pragma once
#include <vector>

#include "core/math/distribution.h"
#include "core/scene/lights/light_sampler.h"

namespace pt {

class PowerLightSampler final : public LightSampler {
 public:
  // power[i]: light i's (LightSet::lights() order); groups: the TriangleGroups' members.
  PowerLightSampler(const std::vector<float>& power, const std::vector<LightGroupRange>& groups);

  bool sample(const Vec3f&, const Vec3f&, float u, LightChoice& c) const override {
    c.light = static_cast<uint32_t>(distribution_.sample_discrete(u, &c.pick, &c.u_rest));
    int32_t g = group_of_[c.light];
    if (g >= 0) {
      c.group_pick = group_pick_[g];
      c.group_offset = group_offset_[c.light];
    }
    return true;
  }
  float pdf(const Vec3f&, const Vec3f&, uint32_t light) const override { return distribution_.discrete_pdf(light); }
  float group_pdf(const Vec3f&, const Vec3f&, uint32_t group) const override { return group_pick_[group]; }
  float infinite_pdf(uint32_t light) const override { return distribution_.discrete_pdf(light); }

 private:
  Distribution1D distribution_;
  std::vector<int32_t> group_of_;     // per light: its group, or -1
  std::vector<float> group_offset_;   // per light: the summed probability of its group's members before it
  std::vector<float> group_pick_;     // per group: the summed probability of its members
};

}  // namespace pt
