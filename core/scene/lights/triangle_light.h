// Emissive triangles, and the groups they form. A triangle light is sampled uniformly over its
// area, or, near its TriangleGroup, uniformly over the solid angle the group subtends
// (core/math/spherical_triangle.h).
#pragma once
#include <cstdint>
#include <vector>

#include "core/geometry/geometry.h"
#include "core/geometry/mesh.h"
#include "core/math/spherical_triangle.h"
#include "core/math/vec.h"
#include "core/scene/lights/emission.h"
#include "core/scene/lights/light_bounds.h"
#include "core/scene/lights/light_sample.h"
#include "core/scene/lights/light_sampler.h"
#include "core/scene/render_settings.h"
#include "core/util/names.h"

namespace pt {

// One emissive triangle, precomputed so that sampling it costs no square root.
struct TriangleLight {
  uint32_t triangle = 0;   // the mesh's triangle (what a hit's prim names)
  uint32_t instance = kNoInstance;  // the instance placing it (an instanced mesh: one light per instance)
  Vec3f v0, edge1, edge2;  // the first vertex and the edges from it
  Vec3f normal, centroid;  // unit normal (the side it emits to), centroid
  float area = 0;
  Spectrum radiance{0};    // with an emission texture: the mean over the triangle, for choosing it
  uint32_t group = 0;      // its TriangleGroup
  int texture = -1;        // the emission texture's slot, or -1
  Spectrum emission{0};    // the material's radiance the texture multiplies
  Vec2f uv0, duv1, duv2;   // the uv at v0 and along the edges

  float power() const { return kPi * area * luminance(radiance); }
  // For the light tree: its box, emitting into the hemisphere of its normal.
  LightBounds bounds() const {
    LightBounds b;
    b.box.expand(v0);
    b.box.expand(v0 + edge1);
    b.box.expand(v0 + edge2);
    b.phi = power();
    b.axis = normal;
    b.cos_o = 1.0f;
    return b;
  }
};

// Coplanar triangles of the same emission that touch, in a row in the mesh: the two halves of
// a quad light, the fan of a polygon. Near a group, a light sample chooses a member in proportion
// to the solid angle it subtends, so the group is sampled uniformly over its whole solid angle;
// choosing by power alone, the halves of a quad seen from beside it subtend very different solid
// angles and the choice itself was most of the variance (scenes/panel-floor).
struct TriangleGroup {
  static constexpr uint32_t kMaxTriangles = 8;  // each near light sample computes every member's solid angle
  uint32_t first = 0, count = 0;                // the members: triangle lights first .. first + count - 1
  float area = 0;
  Vec3f centroid, normal, point;                // area-weighted centroid; the plane's normal and a point on it
};

// Emitting triangles of instanced meshes are lights once per instance; a scene that would make more
// of them than this is refused rather than let the light table outgrow memory.
constexpr size_t kMaxInstancedLights = size_t(1) << 22;

// Every emissive triangle of the world mesh, in mesh order, then those of each instance of an
// emitting instanced mesh, in world space; grouped (a group never spans two instances).
class TriangleLights {
 public:
  TriangleLights() = default;
  // emission[m]: the radiance material m emits (zero: none). Throws Error (no file named) past
  // kMaxInstancedLights instanced lights.
  TriangleLights(const Geometry& geometry, const MaterialEmission& emission, LightSampling sampling);

  const std::vector<TriangleLight>& lights() const { return lights_; }
  const std::vector<TriangleGroup>& groups() const { return groups_; }
  LightSampling sampling() const { return sampling_; }
  size_t size() const { return lights_.size(); }
  bool empty() const { return lights_.empty(); }

  // Samples triangle light i, chosen as `choice` says, as seen from p.
  bool sample(uint32_t i, const LightChoice& choice, const Vec3f& p, Vec2f u, LightSample& ls) const;
  // The density sample() gives the point q (normal n) of triangle light i seen from p (and n_p,
  // the shading point's normal the sampler chose with).
  float pdf(uint32_t i, uint32_t light, const LightSampler& sampler, const Vec3f& p, const Vec3f& n_p, const Vec3f& q,
            const Vec3f& n) const;

 private:
  // Adds triangle t of `mesh` (world-space, or placed by instance `inst`) if it emits.
  void add(const Geometry& geometry, const Mesh& mesh, size_t t, uint32_t inst, const MaterialEmission& emission);
  // The radiance light l sends from its point q: its radiance, or its emission times its texture at q.
  Spectrum radiance_at(const TriangleLight& l, const Vec3f& q) const;
  void add_to_group(const Geometry& geometry, size_t index);
  // For a group near p: each member's spherical triangle and their summed solid angle, or false
  // when the group is left to area sampling. The sample and the pdf of the same p decide alike.
  bool near_solid_angles(const TriangleGroup& g, const Vec3f& p, SphericalTriangle* st, float& total) const;

  std::vector<TriangleLight> lights_;
  std::vector<TriangleGroup> groups_;
  const SurfaceTextures* textures_ = nullptr;  // for emission textures
  LightSampling sampling_ = LightSampling::kAuto;
};

}  // namespace pt
