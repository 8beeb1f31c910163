// Direct lighting: emission seen by the camera plus light arriving in one bounce.
//
// shadow_rays  N samples per hit, each averaged in
// strategy     light: sample the lights (chosen by power); bsdf: sample the BSDF and see what it
//              hits; mis: both, combined with the power heuristic (Veach & Guibas 1995).
// Specular surfaces (mirror, glass) follow their one direction, so a light seen in a mirror shows.
#include "integrators/integrator.h"
#include "integrators/visibility.h"

namespace pt {
namespace {

class DirectIntegrator final : public Integrator {
 public:
  explicit DirectIntegrator(const IntegratorOptions& o) : shadow_rays_(o.shadow_rays), strategy_(o.strategy) {}

  Spectrum Li(const Ray& camera_ray, const Scene& scene, const Accel& accel, Sampler& sampler,
              SampleInfo& info) const override {
    Ray ray = camera_ray;
    Spectrum L(0.0f), throughput(1.0f);
    // Specular surfaces pass the ray on (up to a few times), so mirrors and glass show what they see.
    for (int bounce = 0; bounce < kMaxSpecularBounces; ++bounce) {
      std::optional<Hit> hit = intersect_visible(scene, accel, ray, sampler, info);
      if (!hit) {
        Spectrum Le = scene.environment_radiance(ray.d);
        return L + throughput * (bounce == 0 ? info.first_emission(Le) : Le);
      }
      ShadingPoint sp = make_shading_point(scene, ray, *hit);
      Spectrum Le = scene.emitted(sp.si, sp.wo);
      L += throughput * (bounce == 0 ? info.first_emission(Le) : Le);
      if (!sp.bsdf.is_specular()) return L + throughput * direct(sp, scene, accel, sampler, info);
      Bsdf::Sample bs;
      if (!sp.bsdf.sample(sp.wo_local, sampler, bs)) return L;
      Vec3f wi = sp.frame.to_world(bs.wi);
      ray.o = offset_ray_origin(sp.si.p, dot(wi, sp.ng) > 0 ? sp.ng : -sp.ng);
      ray.d = wi;
      ray.tmin = 0;
      ray.tmax = kInf;
      throughput *= bs.weight;
    }
    return L;
  }

 private:
  static constexpr int kMaxSpecularBounces = 8;

  Spectrum direct(const ShadingPoint& sp, const Scene& scene, const Accel& accel, Sampler& sampler,
                  SampleInfo& info) const {
    Spectrum sum(0.0f);
    const Vec3f& wo_local = sp.wo_local;
    for (int i = 0; i < shadow_rays_; ++i) {
      if (strategy_ != Strategy::kBsdf) {
        sum += sample_one_light(scene, accel, sp, sampler, strategy_ == Strategy::kMis, info);
      }
      if (strategy_ != Strategy::kLight) {
        Bsdf::Sample bs;
        if (!sp.bsdf.sample(wo_local, sampler, bs)) continue;
        Vec3f wi = sp.frame.to_world(bs.wi);
        // Below the geometric surface only through a transmissive BSDF.
        const float side = dot(wi, sp.ng);
        if (side == 0 || (side < 0 && !sp.bsdf.is_transmissive())) continue;
        Ray r;
        r.o = offset_ray_origin(sp.si.p, side > 0 ? sp.ng : -sp.ng);
        r.d = wi;
        std::optional<Hit> hit = intersect_visible(scene, accel, r, sampler, info);
        Spectrum Le;
        float light_pdf;
        if (!hit) {
          Le = scene.environment_radiance(wi);
          light_pdf = scene.environment_pdf(wi);
        } else {
          SurfaceInteraction light = scene.interaction(r, *hit);
          Le = scene.emitted(light, -wi);
          if (is_black(Le)) continue;
          light_pdf = scene.light_pdf(sp.si.p, sp.ng, light);
        }
        float weight = strategy_ == Strategy::kMis ? power_heuristic(bs.pdf, light_pdf) : 1.0f;
        sum += bs.weight * Le * weight;
      }
    }
    return sum / static_cast<float>(shadow_rays_);
  }

  int shadow_rays_;
  Strategy strategy_;
};

}  // namespace

std::unique_ptr<Integrator> make_direct_integrator(const IntegratorOptions& options) {
  return std::make_unique<DirectIntegrator>(options);
}

}  // namespace pt
