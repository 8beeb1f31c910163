// The scene after loading: world-space geometry, materials, lights, the scene file's camera and
// settings. Made once from a SceneBuilder and immutable after; both backends and every integrator
// read it.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/geometry/ray.h"
#include "core/image/texture.h"
#include "core/material/material.h"
#include "core/scene/camera.h"
#include "core/scene/environment.h"
#include "core/scene/interaction.h"
#include "core/scene/lights/light_set.h"
#include "core/scene/mirror_planes.h"
#include "core/scene/render_settings.h"
#include "core/scene/scene_builder.h"

namespace pt {

// The largest coordinate of anything in a scene (vertices, spheres, lights, the file's camera), and
// of the camera pt chooses. Embree asserts on rays whose origin lies beyond 1.8e18 (FLT_LARGE), the
// default camera stands up to tens of thousands of scene radii away at extreme aspect ratios, and
// float geometry that far out has lost its shape long before.
constexpr float kMaxCoordinate = 1e15f;
constexpr float kMaxCameraCoordinate = 1e17f;
inline bool within_extent(const Vec3f& p, float limit) {
  return std::abs(p.x) <= limit && std::abs(p.y) <= limit && std::abs(p.z) <= limit;
}

// What Scene's constructor checks of the geometry, the lights and the camera: something to render,
// finite, within kMaxCoordinate. For the render job, which traces the model before the scene is
// made (the default camera under the studio lighting). Throws pt::Error naming `source` (the
// builder's source moves into the Scene before the checks run). Triangles from
// `studio_first_triangle` on are the studio's ground (StudioInfo), named as such.
void check_geometry(const SceneBuilder& builder, const std::string& source, size_t studio_first_triangle = SIZE_MAX);

class Scene {
 public:
  static constexpr size_t kMaxAutoMirrorPlanes = 8;
  // Validates (non-empty, finite) and builds the light tables. Throws pt::Error naming the source.
  explicit Scene(SceneBuilder&& builder);
  Scene(const Scene&) = delete;  // accelerations structures point into it: it stays where it was made
  Scene& operator=(const Scene&) = delete;

  // The default studio arranged for the camera the job chose on this scene's own geometry (so the
  // acceleration structure that chose it is the one that renders): the sky's sun turns to stand
  // to the left of that camera, and the lights are made again for the new sky. Only for a scene
  // with a studio, before it is shared.
  void arrange_studio(const Camera& camera);

  const Geometry& geometry() const { return geometry_; }
  const Mesh& mesh() const { return geometry_.mesh(); }  // the world-space triangles (not the instances')
  const std::vector<Sphere>& spheres() const { return geometry_.spheres(); }
  const std::vector<Material>& materials() const { return materials_; }
  // The surface textures: the bindings materials' texture slots index, and their cache.
  const SurfaceTextures& textures() const { return textures_; }
  // Whether any material reads a surface texture: only then do interactions carry the surface's
  // derivatives and the ray's footprint (a scene without textures computes neither).
  bool textured() const { return !textures_.empty(); }
  const LightSet& light_set() const { return lights_; }
  const std::optional<Environment>& environment() const { return environment_; }
  const std::optional<Camera>& camera() const { return camera_; }  // the scene file's, if it has one
  const RenderSettings& settings() const { return settings_; }     // the scene file's
  const std::string& source() const { return source_; }
  const std::vector<std::string>& inputs() const { return inputs_; }
  const BBox& bounds() const { return bounds_; }  // of the model: without the studio's ground
  const std::optional<StudioInfo>& studio() const { return studio_; }

  const std::vector<std::string>& notes() const { return notes_; }
  const std::vector<std::string>& contents() const { return contents_; }  // SceneBuilder::contents
  size_t degenerate_triangles() const { return degenerate_triangles_; }

  SurfaceInteraction interaction(const Ray& ray, const Hit& hit) const;
  // The same into `si` (every field set): the integrators' hot path, which keeps one interaction
  // per path instead of copying one per vertex.
  void interaction(const Ray& ray, const Hit& hit, SurfaceInteraction& si) const;
  Spectrum albedo(const SurfaceInteraction& si) const;
  Bsdf bsdf(const SurfaceInteraction& si) const;
  // The shading normal at si seen from wo, with its material's normal or bump map applied and then
  // kept facing wo (core/scene/shading_normal.h); si.ns where the material has neither.
  Vec3f shading_normal(const SurfaceInteraction& si, const Vec3f& wo) const;
  // Whether the material at si perturbs its normal by a map.
  bool normal_mapped(const SurfaceInteraction& si) const { return materials_[si.material].has_normal_map(); }
  // Radiance emitted from si toward direction w (unit, pointing away from the surface).
  Spectrum emitted(const SurfaceInteraction& si, const Vec3f& w) const;

  // Chooses a light for the shading point p and samples it. n is the point's geometric normal on
  // the side light must arrive from (zero: from any side), which a light sampler may use to
  // prefer the lights in front. False when there is nothing to sample.
  bool sample_light(const Vec3f& p, const Vec3f& n, float u_select, Vec2f u, LightSample& ls) const {
    return lights_.sample(p, n, u_select, u, ls);
  }
  // Solid-angle density with which sample_light(p, n, ...) picks the emitting surface si (for MIS).
  float light_pdf(const Vec3f& p, const Vec3f& n, const SurfaceInteraction& si) const { return lights_.pdf(p, n, si); }
  float environment_pdf(const Vec3f& dir) const { return lights_.environment_pdf(dir); }
  Spectrum environment_radiance(const Vec3f& dir) const {
    return environment_ ? environment_->eval(dir) : Spectrum(0.0f);
  }
  bool has_lights() const { return !lights_.empty(); }

  // The environment is a light that sample_light chooses. Off for a constant environment unless
  // settings().sky_sampling asks for it: every direction is then equally likely to see the sky, so
  // cosine-weighted BSDF samples find it as well as light samples would, and light sampling would
  // spend a shadow ray on the half of the sphere below the surface (Cycles likewise leaves a
  // uniform world to BSDF sampling).
  bool environment_sampled() const { return environment_sampled_; }
  // Flat mirrors through which the path tracer samples lights (empty when that is off), and the
  // plane of a hit triangle (-1 if it is none of them).
  const std::vector<MirrorPlane>& mirror_planes() const { return mirror_planes_; }
  int mirror_plane_of(uint32_t geom, uint32_t prim, uint32_t inst) const { return mirror_plane_of_.of(geom, prim, inst); }
  // Mirror spheres through which the path tracer samples lights (integrators/sphere_mirror.h): the
  // indices of the geometry's spheres whose material is a perfect mirror (empty when that is off).
  const std::vector<uint32_t>& mirror_spheres() const { return mirror_spheres_; }
  // The mirrors light sampling goes through, planes first: mirror j < mirror_planes().size() is a
  // plane, else mirror sphere j - mirror_planes().size(). The mirror a hit is on, or -1.
  size_t mirror_count() const { return mirror_planes_.size() + mirror_spheres_.size(); }
  bool has_mirrors() const { return !mirror_planes_.empty() || !mirror_spheres_.empty(); }
  int mirror_of(uint32_t geom, uint32_t prim, uint32_t inst) const {
    if (geom == kGeomSpheres) {
      return inst == kNoInstance && prim < mirror_sphere_of_.size() && mirror_sphere_of_[prim] >= 0
                 ? static_cast<int>(mirror_planes_.size()) + mirror_sphere_of_[prim]
                 : -1;
    }
    return mirror_plane_of_.of(geom, prim, inst);
  }
  // Whether some light reaches a path only through a bounce ray whose hit counts at full weight:
  // a sky left to BSDF sampling, or a light seen via a mirror or through glass (a specular bounce is
  // never light-sampled). Where there is none, every light a bounce ray can hit is also light-sampled
  // and its hit MIS-weighted, so Russian roulette may cut the bounce ray before it is traced
  // (RussianRoulette::kAuto in integrators/integrator.h).
  // Lit by a sky (an environment that emits) and no emitting surface: an open scene, whose paths
  // escape after a few bounces, where splitting at the first hit pays (IntegratorOptions::splits).
  bool sky_lit() const { return environment_emits() && !surface_lights_; }
  // Some triangle or sphere emits: the camera may see an emitter's edge (renderer/render/emitter_edges.h).
  bool surface_lights() const { return surface_lights_; }
  bool bounce_only_light() const { return specular_surfaces_ || (environment_emits() && !environment_sampled_); }
  // An environment that sends any light into the scene.
  bool environment_emits() const { return environment_ && luminance(environment_->average()) > 0; }
  // One line on each choice above and why, for `pt info` and the render's header.
  std::vector<std::string> sampling_choices() const;

  // Whether any surface has partial coverage (Material::opacity < 1); without, rays need no
  // stochastic transparency and shadow rays stay plain occlusion queries.
  bool has_partial_coverage() const { return partial_coverage_; }
  // The coverage of the surface `ray` found at `hit` (a point lookup of an alpha texture).
  float opacity(const Ray& ray, const Hit& hit) const {
    uint32_t m = hit.geom == kGeomSpheres        ? spheres()[hit.prim].material
                 : hit.inst == kNoInstance ? mesh().material[hit.prim]
                                           : geometry_.instance_mesh(hit.inst).material[hit.prim];
    const Material& mat = materials_[m];
    if (mat.alpha_texture < 0) return mat.opacity;
    return textured_opacity(mat, interaction(ray, hit).uv);
  }
  float textured_opacity(const Material& m, Vec2f uv) const {
    float a = m.opacity * textures_.lookup_alpha(m.alpha_texture, uv, {0, 0}, {0, 0});
    return m.alpha_cutoff > 0 ? (a >= m.alpha_cutoff ? 1.0f : 0.0f) : a;
  }

 private:
  std::string source_;
  std::vector<std::string> inputs_;
  Geometry geometry_;
  std::vector<Material> materials_;
  // Per material, what its hits need of the surface's texture-space geometry (kTextureLookups,
  // kTangentFrame in scene.cpp); empty in a scene without textures.
  std::vector<uint8_t> texture_use_;
  SurfaceTextures textures_;
  std::optional<Environment> environment_;
  std::optional<Camera> camera_;
  RenderSettings settings_;
  std::vector<std::string> notes_;
  std::vector<std::string> contents_;
  std::optional<StudioInfo> studio_;

  BBox bounds_;
  size_t degenerate_triangles_ = 0;
  bool partial_coverage_ = false;
  bool specular_surfaces_ = false;
  LightSet lights_;
  bool environment_sampled_ = false;
  bool surface_lights_ = false;
  std::vector<MirrorPlane> mirror_planes_;
  MirrorPlaneIndex mirror_plane_of_;
  size_t flat_mirror_planes_found_ = 0;
  std::vector<uint32_t> mirror_spheres_;
  std::vector<int32_t> mirror_sphere_of_;  // by sphere: its index in mirror_spheres_, or -1
  size_t mirror_spheres_found_ = 0;

  // The light set of the geometry, the materials' emission, the punctual lights and the sky.
  void make_lights(PunctualLights punctual);
};

// Moves a ray origin off a surface along the geometric normal by an amount that scales with the
// magnitude of the coordinates (Wächter & Binder, "A Fast and Robust Method for Avoiding
// Self-Intersection", Ray Tracing Gems ch. 6, 2019): a few float ulps far from the origin, a fixed
// tiny distance near it. n must point to the side the new ray leaves toward.
Vec3f offset_ray_origin(const Vec3f& p, const Vec3f& n);

// A shadow ray from p (on a surface with normal n facing the light) to the point q; tmax stops just
// short of q so the light's own surface is not counted as an occluder.
Ray shadow_ray_to(const Vec3f& p, const Vec3f& n, const Vec3f& q);

}  // namespace pt
