// Render settings as typed values. The command line (renderer/commands/cli_options.cpp) and the scene file
// (scene_file.cpp) parse names through the name tables below, once, where they read them; nothing
// below those parsers compares a setting's text.
#pragma once
#include <cstdint>
#include <string>

#include "core/math/sampler.h"
#include "core/util/names.h"

namespace pt {

enum class IntegratorKind : uint8_t { kDirect, kPath, kNormals, kAlbedo };
inline constexpr NameTable<IntegratorKind, 4> kIntegratorNames{
    "integrator",
    {{{IntegratorKind::kDirect, "direct"}, {IntegratorKind::kPath, "path"}, {IntegratorKind::kNormals, "normals"},
      {IntegratorKind::kAlbedo, "albedo"}}}};

// Direct lighting's strategy: sample the lights, the BSDF, or both weighted by MIS.
enum class Strategy : uint8_t { kLight, kBsdf, kMis };
inline constexpr NameTable<Strategy, 3> kStrategyNames{
    "strategy", {{{Strategy::kLight, "light"}, {Strategy::kBsdf, "bsdf"}, {Strategy::kMis, "mis"}}}};

// Where the path tracer plays Russian roulette (both unbiased):
// next-hit      at a vertex, after the emission found there is counted and before its light sample
//               and bounce (Cycles' placement): a traced ray's hit always counts, so light only the
//               bounce ray can find (a constant sky, a light seen in a mirror) is never thrown away.
// before-bounce after sampling the bounce, before tracing it: a ray that is cut is never traced,
//               which saves about a tenth of the rays where every light a bounce ray can reach is
//               also light-sampled (its hit would only be MIS-weighted; scenes/cornell-box: equal MSE).
// auto          chosen per scene by prepare_job (Scene::bounce_only_light): next-hit where some light
//               is found only by a bounce ray, before-bounce elsewhere. Never reaches an integrator.
enum class RussianRoulette : uint8_t { kNextHit, kBeforeBounce, kAuto };
inline constexpr NameTable<RussianRoulette, 3> kRussianRouletteNames{
    "Russian roulette placement",
    {{{RussianRoulette::kAuto, "auto"}, {RussianRoulette::kNextHit, "next-hit"}, {RussianRoulette::kBeforeBounce, "before-bounce"}}}};

// Whether the environment is a light that light sampling chooses (Scene::environment_sampled):
// auto does so only for an environment that varies with direction.
enum class SkySampling : uint8_t { kAuto, kLight, kBsdf };
inline constexpr NameTable<SkySampling, 3> kSkySamplingNames{
    "sky sampling", {{{SkySampling::kAuto, "auto"}, {SkySampling::kLight, "light"}, {SkySampling::kBsdf, "bsdf"}}}};

// Whether lights are sampled through flat mirrors and mirror spheres (Scene::mirror_planes,
// Scene::mirror_spheres): auto for up to Scene::kMaxAutoMirrorPlanes of each.
enum class MirrorSampling : uint8_t { kAuto, kOn, kOff };
inline constexpr NameTable<MirrorSampling, 3> kMirrorSamplingNames{
    "mirror sampling", {{{MirrorSampling::kAuto, "auto"}, {MirrorSampling::kOn, "on"}, {MirrorSampling::kOff, "off"}}}};

// How a triangle light is sampled from a shading point: uniformly over its area, or uniformly over
// the solid angle its TriangleGroup subtends (core/math/spherical_triangle.h), which removes the
// variance of cos / distance^2 across the light but costs more per sample. Auto takes the solid
// angle where that variance is large: when the group is near, its area more than kNearSolidAngle
// (core/scene/lights/triangle_light.cpp) times the squared distance to its centroid.
enum class LightSampling : uint8_t { kAuto, kArea, kSolidAngle };
inline constexpr NameTable<LightSampling, 3> kLightSamplingNames{
    "light sampling",
    {{{LightSampling::kAuto, "auto"}, {LightSampling::kArea, "area"}, {LightSampling::kSolidAngle, "solid-angle"}}}};

// Which light a light sample goes to (core/scene/lights/light_sampler.h): in proportion to each
// light's power, or through a light tree (light_tree.h) that weighs clusters of lights by power,
// distance and orientation at the shading point. Auto takes the tree from
// LightSet::kAutoTreeEmitters emitters on.
enum class LightSelection : uint8_t { kAuto, kPower, kTree };
inline constexpr NameTable<LightSelection, 3> kLightSelectionNames{
    "light selection",
    {{{LightSelection::kAuto, "auto"}, {LightSelection::kPower, "power"}, {LightSelection::kTree, "tree"}}}};

// The path tracer's continuations per camera sample (IntegratorOptions::splits): kAutoSplits for a
// scene lit by a sky alone, else 1, or a count from 1 to kMaxSplits.
inline constexpr int kAutoSplits = 8;
inline constexpr int kMaxSplits = 64;
inline constexpr int kSplitsAuto = 0;  // RenderSettings::splits: choose per scene

// Extra camera rays per sample in the pixels at the edge of an emitter seen directly
// (renderer/render/emitter_edges.h): kAutoEmitterEdges where some surface emits and the integrator
// counts what the camera sees emitted (direct, path), else none; or a count from 0 (off) to
// kMaxEmitterEdges.
inline constexpr int kAutoEmitterEdges = 8;
inline constexpr int kMaxEmitterEdges = 64;
inline constexpr int kEmitterEdgesAuto = -1;  // RenderSettings::emitter_edges: choose per scene

// The choices made once, when the Scene is made (Scene::sampling_choices says which).
struct SceneChoices {
  SkySampling sky_sampling = SkySampling::kAuto;
  MirrorSampling mirror_sampling = MirrorSampling::kAuto;
  LightSampling light_sampling = LightSampling::kAuto;
  LightSelection light_selection = LightSelection::kAuto;
  bool operator==(const SceneChoices&) const = default;
};

struct RenderSettings {
  int width = 640, height = 480;
  int spp = 16;
  IntegratorKind integrator = IntegratorKind::kDirect;
  uint64_t seed = 0;
  int shadow_rays = 1;
  int max_depth = 8;
  Strategy strategy = Strategy::kMis;
  SamplerKind sampler = SamplerKind::kSobol;
  RussianRoulette rr = RussianRoulette::kAuto;
  int splits = kSplitsAuto;  // or a count from 1 to kMaxSplits
  int emitter_edges = kEmitterEdgesAuto;  // or a count from 0 (off) to kMaxEmitterEdges
  SceneChoices choices;

  // Largest image the film is allowed to allocate (~3.5 GB of per-pixel sums): the same limit for
  // --res and for a scene file's "resolution", so an absurd size is refused before any work.
  static constexpr long kMaxSide = 16384;
  static constexpr long kMaxPixels = 1L << 26;
  static bool valid_resolution(long w, long h) {
    return w >= 1 && h >= 1 && w <= kMaxSide && h <= kMaxSide && w * h <= kMaxPixels;
  }
};

// --splits and its text in settings: "auto" or the count.
inline std::string splits_name(int splits) { return splits == kSplitsAuto ? "auto" : std::to_string(splits); }
// --emitter-edges and its text in settings: "auto", "off" or the count.
inline std::string emitter_edges_name(int views) {
  return views == kEmitterEdgesAuto ? "auto" : views == 0 ? "off" : std::to_string(views);
}

}  // namespace pt
