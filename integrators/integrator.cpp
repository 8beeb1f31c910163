#include "integrators/integrator.h"

#include "core/util/error.h"

namespace pt {

std::unique_ptr<Integrator> make_direct_integrator(const IntegratorOptions& options);
std::unique_ptr<Integrator> make_path_integrator(const IntegratorOptions& options);
std::unique_ptr<Integrator> make_normals_integrator();
std::unique_ptr<Integrator> make_albedo_integrator();

namespace {
struct Entry {
  const char* name;
  std::unique_ptr<Integrator> (*make)(const IntegratorOptions&);
};
const Entry kIntegrators[] = {
    {"direct", make_direct_integrator},
    {"path", make_path_integrator},
    {"normals", [](const IntegratorOptions&) { return make_normals_integrator(); }},
    {"albedo", [](const IntegratorOptions&) { return make_albedo_integrator(); }},
};
}  // namespace

std::unique_ptr<Integrator> make_integrator(const std::string& name, const IntegratorOptions& options) {
  for (const Entry& e : kIntegrators) {
    if (name == e.name) return e.make(options);
  }
  std::string known;
  for (const Entry& e : kIntegrators) known += (known.empty() ? "" : ", ") + std::string(e.name);
  throw Error("unknown integrator '" + name + "' (" + known + ")");
}

std::vector<std::string> integrator_names() {
  std::vector<std::string> names;
  for (const Entry& e : kIntegrators) names.emplace_back(e.name);
  return names;
}

Strategy parse_strategy(const std::string& name) {
  if (name == "light") return Strategy::kLight;
  if (name == "bsdf") return Strategy::kBsdf;
  if (name == "mis") return Strategy::kMis;
  throw Error("unknown strategy '" + name + "' (light, bsdf, mis)");
}

const char* strategy_name(Strategy s) {
  switch (s) {
    case Strategy::kLight: return "light";
    case Strategy::kBsdf: return "bsdf";
    case Strategy::kMis: return "mis";
  }
  return "?";
}

ShadingPoint make_shading_point(const Scene& scene, const Ray& ray, const Hit& hit) {
  ShadingPoint sp;
  sp.si = scene.interaction(ray, hit);
  sp.wo = -ray.d;
  sp.bsdf = scene.bsdf(sp.si);
  sp.ng = sp.si.ng;
  Vec3f ns = sp.si.ns;
  // Dielectrics need to know inside from outside; every other material is shaded two-sided.
  if (sp.bsdf.type != MaterialType::kDielectric && dot(sp.wo, sp.ng) < 0) {
    sp.ng = -sp.ng;
    ns = -ns;
  }
  sp.frame = Frame(ns);
  return sp;
}

Spectrum sample_one_light(const Scene& scene, const Accel& accel, const ShadingPoint& sp, Sampler& sampler,
                          bool mis, SampleInfo& info) {
  float u_select = sampler.next1d();
  Vec2f u = sampler.next2d();
  LightSample ls;
  if (!scene.sample_light(sp.si.p, u_select, u, ls)) return Spectrum(0.0f);
  if (dot(ls.wi, sp.ng) <= 0) return Spectrum(0.0f);  // light below the geometric surface
  Vec3f wi_local = sp.frame.to_local(ls.wi);
  Spectrum f = sp.bsdf.eval(sp.frame.to_local(sp.wo), wi_local);
  if (is_black(f) || is_black(ls.radiance)) return Spectrum(0.0f);
  Ray shadow;
  if (std::isinf(ls.distance)) {
    shadow.o = offset_ray_origin(sp.si.p, sp.ng);
    shadow.d = ls.wi;
  } else {
    shadow = shadow_ray_to(sp.si.p, sp.ng, ls.point);
  }
  ++info.rays;
  if (accel.occluded(shadow)) return Spectrum(0.0f);
  float weight = 1.0f;
  if (mis && !ls.delta) weight = power_heuristic(ls.pdf, sp.bsdf.pdf(sp.frame.to_local(sp.wo), wi_local));
  return f * ls.radiance * (std::abs(wi_local.z) * weight / ls.pdf);
}

}  // namespace pt
