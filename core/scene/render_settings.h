// Render settings as a scene file or the command line writes them. Names (integrator, strategy,
// sampler) stay text here: the layer that owns each name table parses it, once, when a render job
// is prepared (renderer/job.h), and can say whether a bad name came from the file or the command line.
#pragma once
#include <cstdint>
#include <string>

namespace pt {

struct RenderSettings {
  int width = 640, height = 480;
  int spp = 16;
  std::string integrator = "direct";
  uint64_t seed = 0;
  int shadow_rays = 1;
  int max_depth = 8;
  std::string strategy = "mis";   // direct lighting: light | bsdf | mis
  std::string sampler = "sobol";  // independent | sobol
  // Strategies chosen per scene when the Scene is made (`pt info` says which): "auto" decides from
  // the scene, the others force the choice.
  std::string sky_sampling = "auto";     // auto | light | bsdf: light-sample the environment?
  std::string mirror_sampling = "auto";  // auto | on | off: sample lights through flat mirrors?
  std::string light_sampling = "auto";   // auto | area | solid-angle: how triangle lights are sampled (light.h)
  std::string rr = "auto";               // path: where Russian roulette is played (integrator.h)
  std::string splits = "auto";           // path: continuations per camera sample (integrator.h): auto | 1-64

  // Largest image the film is allowed to allocate (~3.5 GB of per-pixel sums): the same limit for
  // --res and for a scene file's "resolution", so an absurd size is refused before any work.
  static constexpr long kMaxSide = 16384;
  static constexpr long kMaxPixels = 1L << 26;
  static bool valid_resolution(long w, long h) {
    return w >= 1 && h >= 1 && w <= kMaxSide && h <= kMaxSide && w * h <= kMaxPixels;
  }
};

}  // namespace pt
