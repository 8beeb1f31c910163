// All the lights of a scene and the sampler that chooses among them. One type per kind, each in a
// file of its own in this folder, each sampling itself and answering its own pdf: point, spot and
// directional lights (delta lights), emissive triangles (in groups) and spheres, and the
// environment. The light sampler (light_sampler.h) chooses which one a shading point samples.
#pragma once
#include <cstdint>
#include <memory>
#include <unordered_map>
#include <vector>

#include "core/geometry/ray.h"
#include "core/geometry/geometry.h"
#include "core/scene/environment.h"
#include "core/scene/interaction.h"
#include "core/scene/lights/directional_light.h"
#include "core/scene/lights/environment_light.h"
#include "core/scene/lights/light_sample.h"
#include "core/scene/lights/light_sampler.h"
#include "core/scene/lights/point_light.h"
#include "core/scene/lights/sphere_light.h"
#include "core/scene/lights/spot_light.h"
#include "core/scene/lights/triangle_light.h"
#include "core/util/names.h"

namespace pt {

enum class LightType : uint8_t { kPoint, kSpot, kTriangle, kSphere, kDirectional, kEnvironment };
inline constexpr NameTable<LightType, 6> kLightTypeNames{
    "light type",
    {{{LightType::kPoint, "point"}, {LightType::kSpot, "spot"}, {LightType::kTriangle, "triangle"},
      {LightType::kSphere, "sphere"}, {LightType::kDirectional, "directional"}, {LightType::kEnvironment, "environment"}}}};

// One light of the set: its kind and its index among the lights of that kind.
struct LightRef {
  LightType type = LightType::kPoint;
  uint32_t index = 0;
};

// The lights a loader gives, beside the emissive surfaces the geometry holds.
struct PunctualLights {
  std::vector<PointLight> points;
  std::vector<SpotLight> spots;
  std::vector<DirectionalLight> directionals;
  bool empty() const { return points.empty() && spots.empty() && directionals.empty(); }
};

class LightSet {
 public:
  LightSet() = default;
  // The punctual lights as given, then every emissive triangle and sphere (emission[m]: what
  // material m emits), then the directional lights and the environment (if given: it emits),
  // whose powers are estimated over a disc of the scene's radius.
  LightSet(const Geometry& geometry, const MaterialEmission& emission, const PunctualLights& punctual,
           const Environment* environment, float scene_radius, LightSampling triangle_sampling = LightSampling::kAuto,
           LightSelection selection = LightSelection::kAuto);

  // Auto takes the tree from this many emitters (lights but the infinite ones, a triangle group
  // counting once) on (light_set.cpp says why).
  static constexpr size_t kAutoTreeEmitters = 8;

  const std::vector<LightRef>& lights() const { return lights_; }
  size_t count(LightType type) const;
  bool empty() const { return lights_.empty(); }
  const std::vector<PointLight>& points() const { return points_; }
  const std::vector<SpotLight>& spots() const { return spots_; }
  const TriangleLights& triangles() const { return triangles_; }
  const std::vector<SphereLight>& spheres() const { return spheres_; }
  const std::vector<DirectionalLight>& directionals() const { return directionals_; }
  const std::vector<TriangleGroup>& triangle_groups() const { return triangles_.groups(); }
  LightSampling triangle_sampling() const { return triangles_.sampling(); }
  const LightSampler& sampler() const { return *sampler_; }
  // The sampler in use (kPower or kTree; kPower when there are no lights), what was asked, and the
  // number of emitters the tree would hold.
  LightSelection selection() const { return selection_; }
  LightSelection requested_selection() const { return requested_; }
  size_t emitters() const { return emitters_; }
  // Each light's power (the luminance of what it emits), in lights() order.
  const std::vector<float>& powers() const { return power_; }

  // Chooses a light for the shading point p (surface normal n, or zero: see LightSampler::sample)
  // and samples it. False when there is nothing to sample.
  bool sample(const Vec3f& p, const Vec3f& n, float u_select, Vec2f u, LightSample& ls) const;
  // Solid-angle density with which sample(p, n, ...) picks the emitting surface point si.
  float pdf(const Vec3f& p, const Vec3f& n, const SurfaceInteraction& si) const;
  // Solid-angle density with which sample() picks direction dir of the environment.
  float environment_pdf(const Vec3f& dir) const;

 private:
  std::vector<LightRef> lights_;
  std::vector<float> power_;
  std::vector<PointLight> points_;
  std::vector<SpotLight> spots_;
  TriangleLights triangles_;
  std::vector<SphereLight> spheres_;
  std::vector<int> sphere_texture_;  // per sphere light: its emission texture slot, or -1
  std::vector<Spectrum> sphere_emission_;
  const SurfaceTextures* textures_ = nullptr;
  std::vector<DirectionalLight> directionals_;
  EnvironmentLight environment_;
  uint32_t first_triangle_ = 0;          // lights() index of triangle light 0
  std::vector<int32_t> triangle_light_;  // lights() index per world mesh triangle, or -1 (empty if none emit)
  // lights() index of (instance << 32 | triangle) for the emitting triangles of instanced meshes.
  std::unordered_map<uint64_t, int32_t> instance_light_;
  std::vector<int32_t> sphere_light_;    // lights() index per sphere, or -1
  int environment_light_ = -1;
  std::unique_ptr<const LightSampler> sampler_;
  LightSelection selection_ = LightSelection::kPower, requested_ = LightSelection::kAuto;
  size_t emitters_ = 0;
};

}  // namespace pt
