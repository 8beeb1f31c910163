#include "renderer/scene_options.h"

#include <cstdio>
#include <filesystem>
#include <regex>

#include "core/util/error.h"
#include "renderer/render.h"

namespace pt {
namespace fs = std::filesystem;

void SceneOptions::apply(RenderSettings& s) const {
  if (spp) s.spp = *spp;
  if (shadow_rays) s.shadow_rays = *shadow_rays;
  if (max_depth) s.max_depth = *max_depth;
  if (seed) s.seed = *seed;
  if (integrator) s.integrator = *integrator;
  if (strategy) s.strategy = *strategy;
  if (sampler) s.sampler = *sampler;
  if (resolution) {
    std::smatch m;
    if (!std::regex_match(*resolution, m, std::regex(R"((\d{1,9})x(\d{1,9}))"))) {
      throw Error("--res '" + *resolution + "': expected WIDTHxHEIGHT, e.g. 640x480");
    }
    long w = std::stol(m[1]), h = std::stol(m[2]);
    if (!RenderSettings::valid_resolution(w, h)) {
      throw Error("--res '" + *resolution + "': each side must be 1 to " + std::to_string(RenderSettings::kMaxSide) +
                  " and the image at most " + std::to_string(RenderSettings::kMaxPixels >> 20) + " Mpixels");
    }
    s.width = static_cast<int>(w);
    s.height = static_cast<int>(h);
  }
  // Validate names now, before any rendering work is spent on them. A name the command line did
  // not set came from the scene file, and the error must say so.
  auto from = [&](bool on_command_line, const char* option, const char* key) {
    if (on_command_line) return std::string(option);
    fs::path file = fs::is_directory(path) ? fs::path(path) / "scene.json" : fs::path(path);
    return file.string() + ": " + key;
  };
  try {
    make_integrator(s.integrator, IntegratorOptions{});
  } catch (const Error& e) {
    throw Error(from(integrator.has_value(), "--integrator", "/render/integrator"), e.what());
  }
  try {
    parse_strategy(s.strategy);
  } catch (const Error& e) {
    throw Error(from(strategy.has_value(), "--strategy", "/render/strategy"), e.what());
  }
  try {
    parse_sampler(s.sampler);
  } catch (const Error& e) {
    throw Error(from(sampler.has_value(), "--sampler", "/render/sampler"), e.what());
  }
}

AccelOptions SceneOptions::accel_options() const {
  return parse_accel_options(backend, triangle_test, embree_robust);
}

void add_scene_options(CLI::App& cmd, SceneOptions& o, bool with_render_settings) {
  cmd.add_option("scene", o.path, "Scene: an .obj file, a .json scene file, or a folder holding scene.json")->required();
  cmd.add_option("--backend", o.backend, "Ray tracing backend: embree or bvh")->check(CLI::IsMember({"embree", "bvh"}));
  cmd.add_option("--triangle-test", o.triangle_test, "BVH triangle test: mt (Möller-Trumbore) or watertight")
      ->check(CLI::IsMember({"mt", "watertight"}));
  cmd.add_flag("--embree-robust", o.embree_robust, "Build Embree's scene with RTC_SCENE_FLAG_ROBUST");
  if (!with_render_settings) return;
  cmd.add_option("--spp", o.spp, "Samples per pixel")->check(CLI::Range(1, 1 << 24));
  cmd.add_option("--res", o.resolution, "Resolution WIDTHxHEIGHT");
  cmd.add_option("--seed", o.seed, "Random seed");
  cmd.add_option("--integrator", o.integrator, "direct, path, normals or albedo");
  cmd.add_option("--shadow-rays", o.shadow_rays, "Light samples per hit (direct)")->check(CLI::Range(1, 1024));
  cmd.add_option("--strategy", o.strategy, "Direct lighting strategy: light, bsdf or mis")
      ->check(CLI::IsMember({"light", "bsdf", "mis"}));
  cmd.add_option("--max-depth", o.max_depth, "Maximum bounces (path)")->check(CLI::Range(1, 1024));
  cmd.add_option("--sampler", o.sampler, "sobol (Owen-scrambled, default) or independent")
      ->check(CLI::IsMember({"sobol", "independent"}));
}

IntegratorOptions integrator_options(const RenderSettings& s) {
  IntegratorOptions o;
  o.shadow_rays = s.shadow_rays;
  o.max_depth = s.max_depth;
  o.strategy = parse_strategy(s.strategy);
  return o;
}

std::string settings_summary(const RenderSettings& s) {
  char buf[256];
  std::snprintf(buf, sizeof buf, "%dx%d spp=%d integrator=%s strategy=%s shadow_rays=%d max_depth=%d sampler=%s seed=%llu",
                s.width, s.height, s.spp, s.integrator.c_str(), s.strategy.c_str(), s.shadow_rays, s.max_depth,
                s.sampler.c_str(), static_cast<unsigned long long>(s.seed));
  return buf;
}

}  // namespace pt
