#include "integrators/integrator.h"

#include "core/util/error.h"
#include "integrators/visibility.h"

namespace pt {

std::unique_ptr<Integrator> make_direct_integrator(const IntegratorOptions& options);
std::unique_ptr<Integrator> make_path_integrator(const IntegratorOptions& options);
std::unique_ptr<Integrator> make_normals_integrator(const IntegratorOptions& options);
std::unique_ptr<Integrator> make_albedo_integrator(const IntegratorOptions& options);

std::unique_ptr<Integrator> make_integrator(IntegratorKind kind, const IntegratorOptions& options) {
  switch (kind) {
    case IntegratorKind::kDirect: return make_direct_integrator(options);
    case IntegratorKind::kPath: return make_path_integrator(options);
    case IntegratorKind::kNormals: return make_normals_integrator(options);
    case IntegratorKind::kAlbedo: return make_albedo_integrator(options);
  }
  throw Error("unknown integrator");
}

ShadingPoint make_shading_point(const Scene& scene, const Ray& ray, const Hit& hit) {
  ShadingPoint sp;
  make_shading_point(scene, ray, hit, sp);
  return sp;
}

void make_shading_point(const Scene& scene, const Ray& ray, const Hit& hit, ShadingPoint& sp) {
  scene.interaction(ray, hit, sp.si);
  sp.wo = -ray.d;
  sp.bsdf = scene.bsdf(sp.si);
  sp.ng = sp.si.ng;
  Vec3f ns = scene.normal_mapped(sp.si) ? scene.shading_normal(sp.si, sp.wo) : sp.si.ns;
  // Transmissive BSDFs need to know inside from outside; every other one is shaded two-sided.
  if (!sp.bsdf.is_transmissive() && dot(sp.wo, sp.ng) < 0) {
    sp.ng = -sp.ng;
    ns = -ns;
  }
  sp.frame = Frame(ns);
  sp.wo_local = sp.frame.to_local(sp.wo);
}

Spectrum seen_emission(const Scene& scene, const Accel& accel, Ray ray, Sampler& sampler, SampleInfo& info) {
  std::optional<Hit> hit = intersect_visible(scene, accel, ray, sampler, info);
  if (!hit) return scene.environment_radiance(ray.d);
  return scene.emitted(scene.interaction(ray, *hit), -ray.d);
}

Spectrum sample_one_light(const Scene& scene, const Accel& accel, const ShadingPoint& sp, Sampler& sampler,
                          bool mis, SampleInfo& info) {
  float u_select = sampler.next1d();
  Vec2f u = sampler.next2d();
  LightSample ls;
  if (!scene.sample_light(sp.si.p, sp.ng, u_select, u, ls)) return Spectrum(0.0f);
  // Light from below the geometric surface reaches only a transmissive BSDF (a rough one: smooth
  // glass is never light-sampled).
  const bool below = dot(ls.wi, sp.ng) <= 0;
  if (below && !sp.bsdf.is_transmissive()) return Spectrum(0.0f);
  const Vec3f n = below ? -sp.ng : sp.ng;
  Vec3f wi_local = sp.frame.to_local(ls.wi);
  float bsdf_pdf;
  Spectrum f = sp.bsdf.eval_pdf(sp.wo_local, wi_local, bsdf_pdf);
  if (is_black(f) || is_black(ls.radiance)) return Spectrum(0.0f);
  // Made in place: a Ray carries its differentials (some 100 bytes), and assigning one made two.
  const Ray shadow =
      std::isinf(ls.distance) ? Ray{offset_ray_origin(sp.si.p, n), ls.wi} : shadow_ray_to(sp.si.p, n, ls.point);
  float carried = transmittance(scene, accel, shadow, info);
  if (carried == 0.0f) return Spectrum(0.0f);
  float weight = 1.0f;
  if (mis && !ls.delta) weight = power_heuristic(ls.pdf, bsdf_pdf);
  return f * ls.radiance * (carried * std::abs(wi_local.z) * weight / ls.pdf);
}

}  // namespace pt
