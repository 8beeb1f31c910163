// Lights: point lights, emissive triangles and spheres (area lights), and the environment. Every
// emissive surface is a light; the light to sample is chosen in proportion to its power. Each
// kind's sampling routine and its density sit next to each other in light.cpp: MIS weighs a
// BSDF-sampled hit with light_pdf(), and the two must agree exactly with what sample() reports.
#pragma once
#include <cstdint>
#include <optional>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/geometry/ray.h"
#include "core/math/distribution.h"
#include "core/math/spherical_triangle.h"
#include "core/math/vec.h"
#include "core/scene/environment.h"
#include "core/scene/interaction.h"
#include "core/scene/material.h"
#include "core/scene/render_settings.h"
#include "core/util/names.h"

namespace pt {

enum class LightType : uint8_t { kPoint, kTriangle, kSphere, kEnvironment };
inline constexpr NameTable<LightType, 4> kLightTypeNames{
    "light type",
    {{{LightType::kPoint, "point"}, {LightType::kTriangle, "triangle"}, {LightType::kSphere, "sphere"},
      {LightType::kEnvironment, "environment"}}}};

struct Light {
  LightType type = LightType::kPoint;
  uint32_t index = 0;      // triangle or sphere index for area lights
  Vec3f position;          // point lights; the first vertex of a triangle; a sphere's centre
  Spectrum intensity{0};   // point lights: W/sr; area lights: the emitted radiance
  float power = 0;         // luminance of the emitted power, for choosing lights
  // Triangle lights, precomputed so that sampling one costs no square root: edges from the first
  // vertex, unit normal, centroid and area. Sphere lights: radius.
  Vec3f edge1, edge2, normal, centroid;
  float area = 0;
  float radius = 0;
  // Triangle lights: the TriangleGroup this triangle belongs to, and the summed choice probability
  // of the group's members before it.
  uint32_t group = 0;
  float group_offset = 0;
};

// Coplanar triangles of the same emission that touch, in a row in the mesh: the two halves of
// a quad light, the fan of a polygon. Near a group, a light sample chooses a member in proportion
// to the solid angle it subtends, so the group is sampled uniformly over its whole solid angle;
// choosing by power alone, the halves of a quad seen from beside it subtend very different solid
// angles and the choice itself was most of the variance (scenes/panel-floor).
struct TriangleGroup {
  static constexpr uint32_t kMaxTriangles = 8;  // each near light sample computes every member's solid angle
  uint32_t first = 0, count = 0;                // the members: lights first .. first + count - 1
  float pick = 0;                               // the summed choice probability of the members
  float area = 0;
  Vec3f centroid, normal, point;                // area-weighted centroid; the plane's normal and a point on it
};

// A sampled light direction as seen from a shading point.
struct LightSample {
  Spectrum radiance{0};  // arriving along -wi (intensity / r^2 for point lights)
  Vec3f wi;              // unit direction from the shading point toward the light
  Vec3f point, normal;   // point on the light and its normal (area lights)
  float distance = kInf; // along wi; kInf for the environment
  float pdf = 0;         // solid-angle density including the choice of light; 1 for point lights
  bool delta = false;    // point light: cannot be hit by BSDF sampling
};

// The density over solid angle of a point chosen with density weight/area over a light's area,
// seen from d2 away at cosine cos_l to the light's normal (p_w = p_A d^2 / cos). Every area-light
// sample and pdf goes through it, so a sample and the pdf of the same point round alike.
inline float area_to_solid_angle(float weight, float d2, float cos_l, float area) {
  return weight * d2 / (cos_l * area);
}

// All the lights of a scene and the power distribution that chooses among them.
class LightSet {
 public:
  LightSet() = default;
  // Point lights as given, then every emissive triangle and sphere, then the environment (if it
  // emits), whose power is estimated over a disc of the scene's radius.
  LightSet(const Geometry& geometry, const std::vector<Material>& materials, const std::vector<Light>& point_lights,
           const Environment* environment, float scene_radius, LightSampling triangle_sampling = LightSampling::kAuto);

  const std::vector<Light>& lights() const { return lights_; }
  LightSampling triangle_sampling() const { return triangle_sampling_; }
  bool empty() const { return lights_.empty(); }

  // Chooses a light by power and samples it as seen from p. False when there is nothing to sample.
  bool sample(const Environment* environment, const Vec3f& p, float u_select, Vec2f u, LightSample& ls) const;
  // Solid-angle density with which sample() picks the emitting surface point si, seen from p.
  float pdf(const Vec3f& p, const SurfaceInteraction& si) const;
  const std::vector<TriangleGroup>& triangle_groups() const { return groups_; }
  // Solid-angle density with which sample() picks direction dir of the environment.
  float environment_pdf(const Environment& environment, const Vec3f& dir) const;

 private:
  float choice_pdf(int light) const { return distribution_.discrete_pdf(light); }
  void add_triangle_to_group(const Mesh& mesh, size_t light);
  // For a group near p (group_near in light.cpp): each member's spherical triangle and their summed
  // solid angle, or false when the group is left to area sampling. The sample and the pdf of the
  // same p decide alike.
  bool group_solid_angles(const TriangleGroup& g, const Vec3f& p, SphericalTriangle* st, float& total) const;
  bool sample_triangle(size_t index, float pick, float u_rest, const Vec3f& p, Vec2f u, LightSample& ls) const;
  float triangle_pdf(size_t index, const Vec3f& p, const Vec3f& q, const Vec3f& n) const;

  std::vector<Light> lights_;
  std::vector<TriangleGroup> groups_;
  Distribution1D distribution_;
  std::vector<int32_t> triangle_light_;  // light index per triangle, or -1 (empty if none emit)
  std::vector<int32_t> sphere_light_;    // light index per sphere, or -1
  int environment_light_ = -1;
  LightSampling triangle_sampling_ = LightSampling::kAuto;
};

}  // namespace pt
