#include "integrators/visibility.h"

#include "core/scene/footprint.h"

namespace pt {
namespace {

// A bound on the work for one ray, not a modelled effect: after this many partial surfaces the
// next one is kept (camera and bounce rays) or blocks (shadow rays).
constexpr int kMaxPassThrough = 256;

// Moves `ray` past the surface it hit, on along the same direction.
void continue_past(const Scene& scene, Ray& ray, const Hit& hit) {
  SurfaceInteraction si = scene.interaction(ray, hit);
  ray.o = offset_ray_origin(si.p, dot(ray.d, si.ng) > 0 ? si.ng : -si.ng);
  if (ray.tmax < kInf) ray.tmax = std::max(0.0f, ray.tmax - hit.t);
  ray.tmin = 0.0f;
  // The neighbouring rays have moved on by as much: their origins' offsets grow with the distance.
  make_direction_differentials(ray);
  ray.diff.dodx += ray.diff.dddx * hit.t;
  ray.diff.dody += ray.diff.dddy * hit.t;
}

}  // namespace

std::optional<Hit> intersect_visible(const Scene& scene, const Accel& accel, Ray& ray, Sampler& sampler,
                                     SampleInfo& info) {
  for (int passed = 0;; ++passed) {
    ++info.rays;
    std::optional<Hit> hit = accel.intersect(ray);
    if (!hit || !scene.has_partial_coverage()) return hit;
    float coverage = scene.opacity(ray, *hit);
    if (coverage >= 1.0f || passed == kMaxPassThrough || sampler.next1d() < coverage) return hit;
    continue_past(scene, ray, *hit);
  }
}

float transmittance(const Scene& scene, const Accel& accel, const Ray& shadow, SampleInfo& info) {
  ++info.rays;
  if (!scene.has_partial_coverage()) return accel.occluded(shadow) ? 0.0f : 1.0f;
  Ray ray = shadow;
  float carried = 1.0f;
  for (int passed = 0; passed <= kMaxPassThrough; ++passed) {
    if (passed > 0) ++info.rays;
    std::optional<Hit> hit = accel.intersect(ray);
    if (!hit) return carried;
    float coverage = scene.opacity(ray, *hit);
    if (coverage >= 1.0f) return 0.0f;
    carried *= 1.0f - coverage;
    continue_past(scene, ray, *hit);
  }
  return 0.0f;
}

}  // namespace pt
