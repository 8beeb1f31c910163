#include "integrators/mirror_light.h"

#include <cmath>

#include "integrators/visibility.h"

namespace pt {
namespace {

// A point closer to the plane than this (relative to the scene's coordinates) has a degenerate
// image; both the sampler and the pdf treat it as not served, so the estimators stay consistent.
bool usable_distance(float dist, const Vec3f& x) {
  return std::abs(dist) > 1e-5f * std::max(1.0f, max_component(vabs(x)));
}

}  // namespace

Spectrum sample_light_via_mirror(const Scene& scene, const Accel& accel, const ShadingPoint& sp, Sampler& sampler,
                                 SampleInfo& info) {
  const std::vector<MirrorPlane>& planes = scene.mirror_planes();
  float u_plane = sampler.next1d();
  float u_select = sampler.next1d();
  Vec2f u = sampler.next2d();
  if (planes.empty()) return Spectrum(0.0f);
  const int count = static_cast<int>(planes.size());
  const int j = std::min(static_cast<int>(u_plane * count), count - 1);
  const MirrorPlane& plane = planes[j];
  const Vec3f& x = sp.si.p;
  float dist_x = plane.signed_distance(x);
  if (!usable_distance(dist_x, x)) return Spectrum(0.0f);
  LightSample ls;
  if (!scene.sample_light(plane.reflect_point(x), plane.reflect_direction(sp.ng), u_select, u, ls)) return Spectrum(0.0f);
  if (std::isinf(ls.distance)) return Spectrum(0.0f);  // the sky through a mirror: BSDF sampling's
  // The light must be on x's side of the mirror, and the direction must leave x's surface.
  if (plane.signed_distance(ls.point) * dist_x <= 0) return Spectrum(0.0f);
  Vec3f wi = plane.reflect_direction(ls.wi);
  if (dot(wi, sp.ng) <= 0) return Spectrum(0.0f);
  float toward = dot(plane.n, wi);
  if (toward * dist_x >= 0) return Spectrum(0.0f);  // heading away from the plane
  float t_plane = -dist_x / toward;
  if (!(t_plane < ls.distance)) return Spectrum(0.0f);
  Vec3f wo_local = sp.frame.to_local(sp.wo), wi_local = sp.frame.to_local(wi);
  float bsdf_pdf;
  Spectrum f = sp.bsdf.eval_pdf(wo_local, wi_local, bsdf_pdf);
  if (is_black(f) || is_black(ls.radiance)) return Spectrum(0.0f);

  // x -> m: the first thing along wi must be a triangle of this mirror plane.
  Ray to_mirror;
  to_mirror.o = offset_ray_origin(x, sp.ng);
  to_mirror.d = wi;
  to_mirror.tmin = 0;
  to_mirror.tmax = kInf;
  std::optional<Hit> hit = intersect_visible(scene, accel, to_mirror, sampler, info);  // opaque scenes only
  if (!hit || scene.mirror_plane_of(hit->geom, hit->prim, hit->inst) != j) return Spectrum(0.0f);
  SurfaceInteraction m = scene.interaction(to_mirror, *hit);
  // m -> y: unoccluded, leaving the mirror on x's side.
  Vec3f side = dist_x > 0 ? plane.n : -plane.n;
  if (transmittance(scene, accel, shadow_ray_to(m.p, side, ls.point), info) == 0.0f) return Spectrum(0.0f);
  Spectrum tint = scene.bsdf(m).albedo();  // a flat mirror (MirrorBsdf) reflects its albedo
  float pdf = ls.pdf / static_cast<float>(count);
  float weight = ls.delta ? 1.0f : power_heuristic(pdf, bsdf_pdf);
  return f * tint * ls.radiance * (std::abs(wi_local.z) * weight / pdf);
}

float mirror_light_pdf(const Scene& scene, const Vec3f& x, const Vec3f& n, int plane_index, const SurfaceInteraction& si_light) {
  const std::vector<MirrorPlane>& planes = scene.mirror_planes();
  if (plane_index < 0 || planes.empty()) return 0.0f;
  const MirrorPlane& plane = planes[plane_index];
  float dist_x = plane.signed_distance(x);
  if (!usable_distance(dist_x, x)) return 0.0f;
  return scene.light_pdf(plane.reflect_point(x), plane.reflect_direction(n), si_light) / static_cast<float>(planes.size());
}

}  // namespace pt
