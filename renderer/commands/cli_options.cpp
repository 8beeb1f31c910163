#include "renderer/commands/cli_options.h"

#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "core/math/sampler.h"
#include "core/scene/lights/light_set.h"
#include "core/scene/lights/triangle_light.h"
#include "renderer/farm/part.h"

namespace pt {

void add_view_options(CLI::App& cmd, ViewOptions& v) {
  cmd.add_option("--look-from", v.look_from, "Camera position X,Y,Z (replaces the scene file's or the default camera's)");
  cmd.add_option("--look-at", v.look_at, "The point the camera looks at, X,Y,Z");
  cmd.add_option("--up", v.up, "The camera's up vector X,Y,Z");
  cmd.add_option("--fov", v.fov, "Vertical field of view in degrees (makes the camera perspective)");
  cmd.add_option("--ortho-height", v.ortho_height,
                 "An orthographic camera whose film is H scene units tall (replaces the camera's projection)")
      ->check(finite_number(0, 1e15, true));
  add_name_option(cmd, "--up-axis", v.up_axis, kUpAxisNames,
                  "y (default) or z: the up axis of the default camera and lighting (z for Z-up models)");
  add_name_option(cmd, "--studio", v.studio, kStudioNames,
                  "Lighting where nothing in the scene emits: sun (default: ground, sky and sun), sky (ground and sky), "
                  "none (a plain white sky)");
  cmd.add_option("--camera", v.camera, "Use camera N of a glTF file (from 0) instead of its first")->check(CLI::Range(0, 1 << 30));
  cmd.add_option("--env", v.env, "Light the scene with this environment map (lat-long .exr or .hdr), replacing the scene's");
  cmd.add_option("--env-rotate", v.env_rotate, "Turn the --env map about the up axis (+y) by DEG degrees")
      ->check(finite_number(-1e6, 1e6, false));
  cmd.add_option("--env-strength", v.env_strength, "Multiply the --env map's radiance by S")->check(finite_number(0, 1e30, false));
  add_name_option(cmd, "--texture-filter", v.textures.filter, kTextureFilterNames,
                  "Surface texture lookups: mipmap (default: filtered over each ray's footprint) or bilinear (the finest "
                  "level only, unfiltered, for comparisons)");
  cmd.add_option("--texture-cache", v.textures.max_memory_mb,
                 "The texture tile cache's bound in MB (default 512): the texels of surface textures held in memory at once")
      ->check(finite_number(16, 1 << 20, false));
}

CLI::Validator finite_number(double lo, double hi, bool lo_exclusive) {
  char range_text[64];
  std::snprintf(range_text, sizeof range_text, "%s%g, %g]", lo_exclusive ? "(" : "[", lo, hi);
  std::string range = range_text;
  return CLI::Validator(
      [lo, hi, lo_exclusive, range](std::string& value) -> std::string {
        const char* begin = value.c_str();
        char* end = nullptr;
        double v = std::strtod(begin, &end);
        if (end == begin || *end != '\0' || !std::isfinite(v)) return "'" + value + "' is not a finite number";
        if (v < lo || v > hi || (lo_exclusive && v == lo)) return "'" + value + "' is outside " + range;
        return "";
      },
      "NUMBER in " + range);
}

CLI::Validator unsigned_64() {
  return CLI::Validator(
      [](std::string& value) -> std::string {
        static const std::string kMax = "18446744073709551615";
        bool digits = !value.empty() && value.size() <= kMax.size();
        for (char c : value) digits = digits && c >= '0' && c <= '9';
        if (!digits || (value.size() == kMax.size() && value > kMax)) {
          return "'" + value.substr(0, 32) + (value.size() > 32 ? "..." : "") + "' is not an integer from 0 to " + kMax;
        }
        return "";
      },
      "UINT64");
}

std::optional<int> parse_splits(const std::string& text) {
  if (text == "auto") return kSplitsAuto;
  int n = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (ec != std::errc() || end != text.data() + text.size() || n < 1 || n > kMaxSplits) return std::nullopt;
  return n;
}

std::optional<int> parse_emitter_edges(const std::string& text) {
  if (text == "auto") return kEmitterEdgesAuto;
  if (text == "off") return 0;
  int n = 0;
  auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), n);
  if (ec != std::errc() || end != text.data() + text.size() || n < 0 || n > kMaxEmitterEdges) return std::nullopt;
  return n;
}

void add_job_options(CLI::App& cmd, JobOptions& o, bool with_render_settings) {
  cmd.add_option("scene", o.scene_path, "Scene: an .obj, .gltf, .glb or .ply file, a .json scene file, or a folder holding scene.json")->required();
  add_name_option(cmd, "--backend", o.accel.backend, kBackendNames, "Ray tracing backend: embree or bvh");
  add_name_option(cmd, "--triangle-test", o.accel.triangle_test, kTriangleTestNames,
                  "BVH triangle test: watertight (default) or mt (Möller-Trumbore, not watertight)");
  cmd.add_flag("--embree-robust", o.accel.embree_robust, "Build Embree's scene with RTC_SCENE_FLAG_ROBUST");
  add_view_options(cmd, o.view);
  if (!with_render_settings) return;
  cmd.add_option("--spp", o.spp, "Samples per pixel")->check(CLI::Range(1, 1 << 24));
  cmd.add_option("--res", o.resolution, "Resolution WIDTHxHEIGHT");
  cmd.add_option("--seed", o.seed, "Random seed (0 to 2^64-1)")->check(unsigned_64());
  add_name_option(cmd, "--integrator", o.integrator, kIntegratorNames, kIntegratorNames.list());
  cmd.add_option("--shadow-rays", o.shadow_rays, "Light samples per hit (direct)")->check(CLI::Range(1, 1024));
  add_name_option(cmd, "--strategy", o.strategy, kStrategyNames, "Direct lighting strategy: light, bsdf or mis");
  cmd.add_option("--max-depth", o.max_depth, "Maximum bounces (path)")->check(CLI::Range(1, 1024));
  add_name_option(cmd, "--sampler", o.sampler, kSamplerNames, "sobol (Owen-scrambled, default) or independent");
  cmd.add_option("--part", o.part, "Render part K of N (K from 0) of a split frame into an EXR part file for pt merge");
  add_name_option(cmd, "--split", o.split, kSplitNames, "How --part splits the frame: regions (merge is bit-identical) or samples");
  add_name_option(cmd, "--rr", o.rr, kRussianRouletteNames,
                  "Russian roulette (path): auto (default: next-hit where some light is found only by bounce rays, else "
                  "before-bounce), next-hit (after the hit's emission is counted) or before-bounce (before the bounce ray "
                  "is traced)");
  add_name_option(cmd, "--sky-sampling", o.sky_sampling, kSkySamplingNames,
                  "auto (default: light-sample an environment only if it varies with direction), light or bsdf");
  cmd.add_option_function<std::string>(
         "--splits", [&o](const std::string& text) { o.splits = parse_splits(text); },
         "path: continuations of each camera sample from its first hit, averaged: auto (default: " +
             std::to_string(kAutoSplits) + " in a scene lit by a sky and no emitting surface, else 1) or 1-" +
             std::to_string(kMaxSplits) + "; a sample then costs more and is less noisy")
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            return parse_splits(text) ? "" : "expected auto or a count from 1 to " + std::to_string(kMaxSplits);
          },
          "auto|COUNT"));
  cmd.add_option_function<std::string>(
         "--emitter-edges", [&o](const std::string& text) { o.emitter_edges = parse_emitter_edges(text); },
         "Extra camera rays per sample, to the first hit only, in the pixels at the edge of an emitter seen directly: "
         "auto (default: " +
             std::to_string(kAutoEmitterEdges) + " where a surface emits), off, or 0-" + std::to_string(kMaxEmitterEdges))
      ->check(CLI::Validator(
          [](std::string& text) -> std::string {
            return parse_emitter_edges(text) ? "" : "expected auto, off or a count from 0 to " + std::to_string(kMaxEmitterEdges);
          },
          "auto|off|COUNT"));
  add_name_option(cmd, "--mirror-sampling", o.mirror_sampling, kMirrorSamplingNames,
                  "auto (default: sample lights through flat mirrors and mirror spheres, each when there are 1-8), on or off");
  add_name_option(cmd, "--light-sampling", o.light_sampling, kLightSamplingNames,
                  "How triangle lights are sampled: auto (default: by solid angle where a light is near, Arvo 1995; else "
                  "by area), area or solid-angle");
  add_name_option(cmd, "--light-selection", o.light_selection, kLightSelectionNames,
                  "Which light each light sample goes to: auto (default: a light tree from " +
                      std::to_string(LightSet::kAutoTreeEmitters) +
                      " emitters on, else by power), power (in proportion to each light's power) or tree (a BVH of the "
                      "lights weighing power, distance and orientation at the shading point)");
}

}  // namespace pt
