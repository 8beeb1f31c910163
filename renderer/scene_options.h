// Command-line options shared by `pt render`, `pt info` and `pt bench`: the scene, its settings
// overrides (the command line wins over the scene file) and the backend.
#pragma once
#include <CLI/CLI.hpp>

#include <optional>
#include <string>

#include "core/accel/accel.h"
#include "core/scene/scene.h"
#include "integrators/integrator.h"

namespace pt {

struct SceneOptions {
  std::string path;
  std::optional<int> spp, shadow_rays, max_depth;
  std::optional<uint64_t> seed;
  std::optional<std::string> resolution, integrator, strategy, sampler;
  std::string backend = "embree";
  std::string triangle_test = "mt";
  bool embree_robust = false;

  void apply(RenderSettings& s) const;  // throws pt::Error on a bad value
  AccelOptions accel_options() const;
};

void add_scene_options(CLI::App& cmd, SceneOptions& o, bool with_render_settings = true);
IntegratorOptions integrator_options(const RenderSettings& s);
std::string settings_summary(const RenderSettings& s);

}  // namespace pt
