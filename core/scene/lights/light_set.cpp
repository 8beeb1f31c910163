#include "core/scene/lights/light_set.h"

#include "core/scene/lights/light_tree.h"
#include "core/scene/lights/power_light_sampler.h"

namespace pt {

LightSet::LightSet(const Geometry& geometry, const MaterialEmission& emission, const PunctualLights& punctual,
                   const Environment* environment, float scene_radius, LightSampling triangle_sampling,
                   LightSelection selection)
    : points_(punctual.points),
      spots_(punctual.spots),
      triangles_(geometry, emission, triangle_sampling),
      textures_(emission.textures),
      directionals_(punctual.directionals),
      requested_(selection) {
  auto add = [&](LightType type, size_t index, float power) {
    lights_.push_back({type, static_cast<uint32_t>(index)});
    power_.push_back(power);
  };
  for (size_t i = 0; i < points_.size(); ++i) add(LightType::kPoint, i, points_[i].power());
  for (size_t i = 0; i < spots_.size(); ++i) add(LightType::kSpot, i, spots_[i].power());
  first_triangle_ = static_cast<uint32_t>(lights_.size());
  const Mesh& mesh = geometry.mesh();
  if (!triangles_.empty()) triangle_light_.assign(mesh.triangle_count(), -1);
  for (size_t i = 0; i < triangles_.size(); ++i) {
    const TriangleLight& t = triangles_.lights()[i];
    int32_t light = static_cast<int32_t>(lights_.size());
    if (t.instance == kNoInstance) {
      triangle_light_[t.triangle] = light;
    } else {
      instance_light_[(uint64_t(t.instance) << 32) | t.triangle] = light;
    }
    add(LightType::kTriangle, i, t.power());
  }
  const std::vector<Sphere>& spheres = geometry.spheres();
  for (size_t s = 0; s < spheres.size(); ++s) {
    const Spectrum& e = emission.radiance[spheres[s].material];
    if (!(max_component(e) > 0)) continue;
    if (sphere_light_.empty()) sphere_light_.assign(spheres.size(), -1);
    sphere_light_[s] = static_cast<int32_t>(lights_.size());
    const int texture = emission.texture_of(spheres[s].material);
    // A textured sphere is chosen by the texture's mean (its coarsest level), as a textured
    // triangle is (emission.h).
    Spectrum chosen = texture < 0 ? e : e * textures_->lookup(texture, {0.5f, 0.5f}, {1, 0}, {0, 1}, true);
    spheres_.emplace_back(static_cast<uint32_t>(s), spheres[s], chosen);
    sphere_texture_.push_back(texture);
    sphere_emission_.push_back(e);
    add(LightType::kSphere, spheres_.size() - 1, spheres_.back().power());
  }
  for (size_t i = 0; i < directionals_.size(); ++i) add(LightType::kDirectional, i, directionals_[i].power(scene_radius));
  if (environment && luminance(environment->average()) > 0) {
    environment_.environment = environment;
    environment_light_ = static_cast<int>(lights_.size());
    add(LightType::kEnvironment, 0, environment_.power(scene_radius));
  }
  if (lights_.empty()) return;
  std::vector<LightGroupRange> groups;
  for (const TriangleGroup& g : triangles_.groups()) groups.push_back({first_triangle_ + g.first, g.count});
  emitters_ = points_.size() + spots_.size() + triangles_.groups().size() + spheres_.size();
  // Auto: the tree once there are more than a handful of emitters. Below that, the descent's
  // importance evaluations cost more than the choice can gain (few lights all light most points).
  bool tree = selection == LightSelection::kTree || (selection == LightSelection::kAuto && emitters_ >= kAutoTreeEmitters);
  if (!tree) {
    sampler_ = std::make_unique<PowerLightSampler>(power_, groups);
    return;
  }
  std::vector<LightBounds> bounds;
  for (const LightRef& l : lights_) {
    switch (l.type) {
      case LightType::kPoint: bounds.push_back(points_[l.index].bounds()); break;
      case LightType::kSpot: bounds.push_back(spots_[l.index].bounds()); break;
      case LightType::kTriangle: bounds.push_back(triangles_.lights()[l.index].bounds()); break;
      case LightType::kSphere: bounds.push_back(spheres_[l.index].bounds()); break;
      case LightType::kDirectional:
      case LightType::kEnvironment: bounds.emplace_back(); break;  // infinitely far: outside the tree
    }
  }
  sampler_ = std::make_unique<LightTree>(bounds, power_, groups);
  selection_ = LightSelection::kTree;
}

size_t LightSet::count(LightType type) const {
  size_t n = 0;
  for (const LightRef& l : lights_) n += l.type == type;
  return n;
}

bool LightSet::sample(const Vec3f& p, const Vec3f& n, float u_select, Vec2f u, LightSample& ls) const {
  if (lights_.empty()) return false;
  LightChoice c;
  if (!sampler_->sample(p, n, u_select, c)) return false;
  const LightRef& ref = lights_[c.light];
  switch (ref.type) {
    case LightType::kPoint: return points_[ref.index].sample(p, c.pick, ls);
    case LightType::kSpot: return spots_[ref.index].sample(p, c.pick, ls);
    case LightType::kTriangle: return triangles_.sample(ref.index, c, p, u, ls);
    case LightType::kSphere: {
      if (!spheres_[ref.index].sample(p, c.pick, u, ls)) return false;
      if (int t = sphere_texture_[ref.index]; t >= 0) {
        ls.radiance = sphere_emission_[ref.index] * textures_->lookup(t, sphere_uv(ls.normal), {0, 0}, {0, 0});
      }
      return true;
    }
    case LightType::kDirectional: return directionals_[ref.index].sample(c.pick, ls);
    case LightType::kEnvironment: return environment_.sample(c.pick, u, ls);
  }
  return false;
}

float LightSet::pdf(const Vec3f& p, const Vec3f& n, const SurfaceInteraction& si) const {
  if (si.geom == kGeomTriangles) {
    int32_t found = -1;
    if (si.inst != kNoInstance) {
      auto it = instance_light_.find((uint64_t(si.inst) << 32) | si.prim);
      if (it != instance_light_.end()) found = it->second;
    } else if (!triangle_light_.empty()) {
      found = triangle_light_[si.prim];
    }
    if (found < 0) return 0.0f;
    uint32_t light = static_cast<uint32_t>(found);
    return triangles_.pdf(light - first_triangle_, light, *sampler_, p, n, si.p, si.ng);
  }
  if (sphere_light_.empty() || sphere_light_[si.prim] < 0) return 0.0f;
  uint32_t light = static_cast<uint32_t>(sphere_light_[si.prim]);
  return spheres_[lights_[light].index].pdf(p, sampler_->pdf(p, n, light), si.p, si.ng);
}

float LightSet::environment_pdf(const Vec3f& dir) const {
  if (environment_light_ < 0) return 0.0f;
  return environment_.pdf(sampler_->infinite_pdf(static_cast<uint32_t>(environment_light_)), dir);
}

}  // namespace pt
