#include "core/scene/lights/power_light_sampler.h"

namespace pt {

PowerLightSampler::PowerLightSampler(const std::vector<float>& power, const std::vector<LightGroupRange>& groups)
    : distribution_(power), group_of_(power.size(), -1), group_offset_(power.size(), 0.0f), group_pick_(groups.size(), 0.0f) {
  for (size_t g = 0; g < groups.size(); ++g) {
    float pick = 0;
    for (uint32_t m = groups[g].first; m < groups[g].first + groups[g].count; ++m) {
      group_of_[m] = static_cast<int32_t>(g);
      group_offset_[m] = pick;
      pick += distribution_.discrete_pdf(m);
    }
    group_pick_[g] = pick;
  }
}

}  // namespace pt
