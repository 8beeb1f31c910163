// The integrator interface: radiance along one camera ray. Integrators are chosen from an explicit
// table (kIntegratorNames in core/scene/render_settings.h, make_integrator), not by self-registration.
#pragma once
#include <memory>
#include <string>
#include <vector>

#include "core/accel/accel.h"
#include "core/math/sampler.h"
#include "core/scene/scene.h"
#include "core/util/names.h"

namespace pt {

// Per-sample bookkeeping between the renderer and the integrator.
struct SampleInfo {
  uint64_t rays = 0;  // out: rays traced, for the rays/s figure
  // In: what `views` other camera rays through the pixel saw emitted (seen_emission), summed
  // (renderer/render/emitter_edges.h). With views > 0 the integrator counts their mean in place of
  // what its own camera ray sees emitted at its first hit; the path goes on from its own ray.
  Spectrum seen_sum{0.0f};
  int views = 0;
  // The camera ray's own first-hit emission (or sky), or the views' mean in its place.
  Spectrum first_emission(const Spectrum& own) const { return views > 0 ? seen_sum / static_cast<float>(views) : own; }
};

class Integrator {
 public:
  virtual ~Integrator() = default;
  virtual Spectrum Li(const Ray& ray, const Scene& scene, const Accel& accel, Sampler& sampler,
                      SampleInfo& info) const = 0;
};

struct IntegratorOptions {
  int shadow_rays = 1;
  int max_depth = 8;
  Strategy strategy = Strategy::kMis;
  int rr_depth = 3;           // path: Russian roulette starts after this many bounces (0 = never)
  RussianRoulette rr = RussianRoulette::kNextHit;
  // path: continuations traced from each camera sample's first (non-specular) hit, averaged. The
  // camera ray and first hit are shared, so where the variance lies in what the continuations
  // gather and they are cheap (a sky, paths that escape), a sample's cost grows less than its
  // variance falls. --splits auto chooses kAutoSplits for a scene lit by a sky alone, else 1.
  int splits = 1;
};

std::unique_ptr<Integrator> make_integrator(IntegratorKind kind, const IntegratorOptions& options);

// Shading helpers shared by the integrators.
struct ShadingPoint {
  SurfaceInteraction si;
  Frame frame;   // shading frame, normal on the side of wo (two-sided shading)
  Vec3f ng;      // geometric normal on the side of wo
  Vec3f wo;      // world direction toward the viewer
  Vec3f wo_local;  // wo in the shading frame: read by every BSDF call, and by each split continuation
  Bsdf bsdf;
};
ShadingPoint make_shading_point(const Scene& scene, const Ray& ray, const Hit& hit);
// The same into `sp` (every field set), for a path that keeps one shading point per vertex it
// reaches instead of copying one (a ShadingPoint is some 400 bytes).
void make_shading_point(const Scene& scene, const Ray& ray, const Hit& hit, ShadingPoint& sp);

// What a camera ray sees emitted at its first hit (the integrators count it at full weight): the
// surface's emission toward the camera, or the sky where the ray escapes.
Spectrum seen_emission(const Scene& scene, const Accel& accel, Ray ray, Sampler& sampler, SampleInfo& info);

// Radiance from one light sample at a non-specular point, weighted for MIS when `mis` is set.
Spectrum sample_one_light(const Scene& scene, const Accel& accel, const ShadingPoint& sp, Sampler& sampler,
                          bool mis, SampleInfo& info);

}  // namespace pt
