#include "integrators/mirror_light.h"

#include <cmath>

#include "integrators/sphere_mirror.h"
#include "integrators/visibility.h"

namespace pt {
namespace {

// A point closer to the plane than this (relative to the scene's coordinates) has a degenerate
// image; both the sampler and the pdf treat it as not served, so the estimators stay consistent.
bool usable_distance(float dist, const Vec3f& x) {
  return std::abs(dist) > 1e-5f * std::max(1.0f, max_component(vabs(x)));
}

// The density over area with which a light point y (normal ny) is chosen from the centre c of a
// mirror sphere: sample_light(c, 0) and its solid-angle density converted.
float area_density_from(const Scene& scene, const Vec3f& c, const SurfaceInteraction& si_light) {
  Vec3f to_c = c - si_light.p;
  float d2 = length_squared(to_c);
  float cos_l = dot(si_light.ng, to_c) / std::sqrt(d2);
  if (!(cos_l > 0) || !(d2 > 0)) return 0.0f;
  return scene.light_pdf(c, Vec3f(0.0f), si_light) * cos_l / d2;
}

Spectrum via_sphere(const Scene& scene, const Accel& accel, const ShadingPoint& sp, Sampler& sampler, SampleInfo& info,
                    int j, int count, float u_select, Vec2f u) {
  const Sphere& sphere = scene.geometry().spheres()[scene.mirror_spheres()[j - scene.mirror_planes().size()]];
  // No direction leaving x's surface meets a sphere wholly below its tangent plane.
  if (dot(sphere.center - sp.si.p, sp.ng) <= -sphere.radius) return Spectrum(0.0f);
  LightSample ls;
  if (!scene.sample_light(sphere.center, Vec3f(0.0f), u_select, u, ls)) return Spectrum(0.0f);
  if (ls.delta || std::isinf(ls.distance) || is_black(ls.radiance)) return Spectrum(0.0f);
  const Vec3f& x = sp.si.p;
  SphereReflection sr;
  if (!reflect_in_sphere(sphere.center, sphere.radius, x, ls.point, sr)) return Spectrum(0.0f);
  Vec3f wi = (sr.m - x) / sr.d;
  if (dot(wi, sp.ng) <= 0) return Spectrum(0.0f);
  // The light's cosine toward m (it emits from its front only, as it does toward the centre).
  float cos_y = dot(ls.normal, sr.m - ls.point) / sr.s;
  if (!(cos_y > 0)) return Spectrum(0.0f);
  float cos_c = -dot(ls.wi, ls.normal);
  float area_pdf = ls.pdf * cos_c / (ls.distance * ls.distance);
  float pdf = area_pdf * sphere_mirror_distance2(sr.s, sr.d, sr.cos_theta, sphere.radius) / cos_y / static_cast<float>(count);
  if (!(pdf > 0) || !std::isfinite(pdf)) return Spectrum(0.0f);
  const Vec3f wo_local = sp.wo_local, wi_local = sp.frame.to_local(wi);
  float bsdf_pdf;
  Spectrum f = sp.bsdf.eval_pdf(wo_local, wi_local, bsdf_pdf);
  if (is_black(f)) return Spectrum(0.0f);
  // x -> m: the first thing along wi must be this sphere; m -> y unoccluded.
  Ray to_mirror;
  to_mirror.o = offset_ray_origin(x, sp.ng);
  to_mirror.d = wi;
  to_mirror.tmin = 0;
  to_mirror.tmax = kInf;
  std::optional<Hit> hit = intersect_visible(scene, accel, to_mirror, sampler, info);
  if (!hit || scene.mirror_of(hit->geom, hit->prim, hit->inst) != j) return Spectrum(0.0f);
  SurfaceInteraction m = scene.interaction(to_mirror, *hit);
  if (transmittance(scene, accel, shadow_ray_to(m.p, m.ng, ls.point), info) == 0.0f) return Spectrum(0.0f);
  Spectrum tint = scene.bsdf(m).albedo();
  float weight = power_heuristic(pdf, bsdf_pdf);
  return f * tint * ls.radiance * (std::abs(wi_local.z) * weight / pdf);
}

}  // namespace

Spectrum sample_light_via_mirror(const Scene& scene, const Accel& accel, const ShadingPoint& sp, Sampler& sampler,
                                 SampleInfo& info) {
  const std::vector<MirrorPlane>& planes = scene.mirror_planes();
  float u_plane = sampler.next1d();
  float u_select = sampler.next1d();
  Vec2f u = sampler.next2d();
  const int count = static_cast<int>(scene.mirror_count());
  if (count == 0) return Spectrum(0.0f);
  const int j = std::min(static_cast<int>(u_plane * count), count - 1);
  if (j >= static_cast<int>(planes.size())) return via_sphere(scene, accel, sp, sampler, info, j, count, u_select, u);
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
  const Vec3f wo_local = sp.wo_local, wi_local = sp.frame.to_local(wi);
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
  if (!hit || scene.mirror_of(hit->geom, hit->prim, hit->inst) != j) return Spectrum(0.0f);
  SurfaceInteraction m = scene.interaction(to_mirror, *hit);
  // m -> y: unoccluded, leaving the mirror on x's side.
  Vec3f side = dist_x > 0 ? plane.n : -plane.n;
  if (transmittance(scene, accel, shadow_ray_to(m.p, side, ls.point), info) == 0.0f) return Spectrum(0.0f);
  Spectrum tint = scene.bsdf(m).albedo();  // a flat mirror (MirrorBsdf) reflects its albedo
  float pdf = ls.pdf / static_cast<float>(count);
  float weight = ls.delta ? 1.0f : power_heuristic(pdf, bsdf_pdf);
  return f * tint * ls.radiance * (std::abs(wi_local.z) * weight / pdf);
}

float mirror_light_pdf(const Scene& scene, const Vec3f& x, const Vec3f& n, int mirror, const Vec3f& m,
                       const SurfaceInteraction& si_light) {
  const std::vector<MirrorPlane>& planes = scene.mirror_planes();
  const size_t count = scene.mirror_count();
  if (mirror < 0 || count == 0) return 0.0f;
  if (mirror >= static_cast<int>(planes.size())) {
    const Sphere& sphere = scene.geometry().spheres()[scene.mirror_spheres()[mirror - planes.size()]];
    // What via_sphere would have needed to produce this path: x outside the sphere, the direction
    // leaving x's surface, the light's front toward m.
    Vec3f to_m = m - x, to_y = si_light.p - m;
    float d = length(to_m), s = length(to_y);
    if (!(d > 0) || !(s > 0) || !(length(x - sphere.center) > sphere.radius * (1 + 1e-6f))) return 0.0f;
    if (dot(to_m, n) <= 0) return 0.0f;
    float cos_y = -dot(si_light.ng, to_y) / s;
    Vec3f nm = (m - sphere.center) / sphere.radius;
    float cos_theta = -dot(nm, to_m) / d;
    if (!(cos_y > 0) || !(cos_theta > 0)) return 0.0f;
    float area_pdf = area_density_from(scene, sphere.center, si_light);
    return area_pdf * sphere_mirror_distance2(s, d, cos_theta, sphere.radius) / cos_y / static_cast<float>(count);
  }
  const MirrorPlane& plane = planes[mirror];
  float dist_x = plane.signed_distance(x);
  if (!usable_distance(dist_x, x)) return 0.0f;
  return scene.light_pdf(plane.reflect_point(x), plane.reflect_direction(n), si_light) / static_cast<float>(count);
}

}  // namespace pt
