// The scene after loading: world-space geometry, materials, lights, camera and settings.
// Immutable once loaded; both backends and every integrator read it.
#pragma once
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/geometry/mesh.h"
#include "core/geometry/ray.h"
#include "core/geometry/sphere.h"
#include "core/math/distribution.h"
#include "core/math/frame.h"
#include "core/scene/camera.h"
#include "core/scene/environment.h"
#include "core/scene/light.h"
#include "core/scene/material.h"
#include "core/scene/texture.h"

namespace pt {

// Render settings a scene file may carry; the command line overrides them.
struct RenderSettings {
  int width = 640, height = 480;
  int spp = 16;
  std::string integrator = "direct";
  uint64_t seed = 0;
  int shadow_rays = 1;
  int max_depth = 8;
  std::string strategy = "mis";   // direct lighting: light | bsdf | mis
  std::string sampler = "sobol";  // independent | sobol

  // Largest image the film is allowed to allocate (~3.5 GB of per-pixel sums): the same limit for
  // --res and for a scene file's "resolution", so an absurd size is refused before any work.
  static constexpr long kMaxSide = 16384;
  static constexpr long kMaxPixels = 1L << 26;
  static bool valid_resolution(long w, long h) {
    return w >= 1 && h >= 1 && w <= kMaxSide && h <= kMaxSide && w * h <= kMaxPixels;
  }
};

struct SurfaceInteraction {
  Vec3f p;
  Vec3f ng;  // unit geometric normal, front face (triangle winding / sphere outside)
  Vec3f ns;  // unit shading normal, on the same side as ng
  Vec2f uv;
  uint32_t material = 0;
  uint32_t geom = 0, prim = 0;
};

class Scene {
 public:
  // Building blocks, filled by the loaders; finalize() validates and builds the light tables.
  Mesh& mesh_mut() { return mesh_; }
  std::vector<Sphere>& spheres_mut() { return spheres_; }
  std::vector<Material>& materials_mut() { return materials_; }
  std::vector<std::shared_ptr<const Texture>>& textures_mut() { return textures_; }
  std::vector<Light>& point_lights_mut() { return point_lights_; }
  void set_environment(std::optional<Environment> env) { environment_ = std::move(env); }
  void set_camera(const Camera& c) { camera_ = c; has_camera_ = true; }
  // Replaces the framing default chosen at finalize() (see default_camera.h); has_camera() stays false.
  void set_default_camera(const Camera& c) { camera_ = c; }
  RenderSettings& settings_mut() { return settings_; }
  void set_source(const std::string& path) { source_ = path; }
  std::vector<std::string>& notes_mut() { return notes_; }
  // The grey Lambertian used where the input names no material; created on first use.
  uint32_t default_material();

  // Validates (non-empty, finite) and builds the light list. Throws pt::Error naming `source`.
  void finalize();

  const Mesh& mesh() const { return mesh_; }
  const std::vector<Sphere>& spheres() const { return spheres_; }
  const std::vector<Material>& materials() const { return materials_; }
  const std::vector<std::shared_ptr<const Texture>>& textures() const { return textures_; }
  const std::vector<Light>& lights() const { return lights_; }
  const std::optional<Environment>& environment() const { return environment_; }
  const Camera& camera() const { return camera_; }
  bool has_camera() const { return has_camera_; }
  const RenderSettings& settings() const { return settings_; }
  const std::string& source() const { return source_; }
  const BBox& bounds() const { return bounds_; }
  const std::vector<std::string>& notes() const { return notes_; }
  size_t degenerate_triangles() const { return degenerate_triangles_; }

  SurfaceInteraction interaction(const Ray& ray, const Hit& hit) const;
  Spectrum albedo(const SurfaceInteraction& si) const;
  Bsdf bsdf(const SurfaceInteraction& si) const;
  // Radiance emitted from si toward direction w (unit, pointing away from the surface).
  Spectrum emitted(const SurfaceInteraction& si, const Vec3f& w) const;

  // Chooses a light by power and samples it as seen from p. False when there is nothing to sample.
  bool sample_light(const Vec3f& p, float u_select, Vec2f u, LightSample& ls) const;
  // Solid-angle density with which sample_light picks the emitting surface si from p (for MIS).
  float light_pdf(const Vec3f& p, const SurfaceInteraction& si) const;
  float environment_pdf(const Vec3f& dir) const;
  Spectrum environment_radiance(const Vec3f& dir) const {
    return environment_ ? environment_->eval(dir) : Spectrum(0.0f);
  }
  bool has_lights() const { return !lights_.empty(); }

 private:
  float light_choice_pdf(int light) const { return light_distribution_.discrete_pdf(light); }

  Mesh mesh_;
  std::vector<Sphere> spheres_;
  std::vector<Material> materials_;
  std::vector<std::shared_ptr<const Texture>> textures_;
  std::vector<Light> point_lights_;
  std::optional<Environment> environment_;
  Camera camera_;
  bool has_camera_ = false;
  RenderSettings settings_;
  std::string source_;
  std::vector<std::string> notes_;

  BBox bounds_;
  float scene_radius_ = 1.0f;
  size_t degenerate_triangles_ = 0;
  std::vector<Light> lights_;
  Distribution1D light_distribution_;
  std::vector<int32_t> triangle_light_;  // light index per triangle, or -1 (empty if none emit)
  std::vector<int32_t> sphere_light_;    // light index per sphere, or -1
  int environment_light_ = -1;
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
