// Unidirectional path tracing with next-event estimation and multiple importance sampling.
//
// max_depth  bounces; 1 gives direct lighting only (the PBRT convention)
// rr_depth   Russian roulette after this many bounces: a path survives with probability
//            max(0.05, min(1, max throughput component)) and is reweighted by its inverse, so
//            the estimator stays unbiased (PBRT 3rd ed. 13.7)
// Light hits found by BSDF sampling are weighted against NEE with the power heuristic; specular
// bounces skip NEE and count emission at full weight (Veach 1997, ch. 9).
#include "integrators/integrator.h"
#include "integrators/visibility.h"

namespace pt {
namespace {

class PathIntegrator final : public Integrator {
 public:
  explicit PathIntegrator(const IntegratorOptions& o) : max_depth_(o.max_depth), rr_depth_(o.rr_depth) {}

  Spectrum Li(const Ray& camera_ray, const Scene& scene, const Accel& accel, Sampler& sampler,
              SampleInfo& info) const override {
    Ray ray = camera_ray;
    Spectrum L(0.0f), beta(1.0f);
    bool specular = true;  // the camera "bounce" counts emission at full weight
    float prev_pdf = 0.0f;
    Vec3f prev_p;
    for (int depth = 0;; ++depth) {
      std::optional<Hit> hit = intersect_visible(scene, accel, ray, sampler, info);
      if (!hit) {
        Spectrum Le = scene.environment_radiance(ray.d);
        if (!is_black(Le)) {
          float w = specular ? 1.0f : power_heuristic(prev_pdf, scene.environment_pdf(ray.d));
          L += beta * Le * w;
        }
        break;
      }
      ShadingPoint sp = make_shading_point(scene, ray, *hit);
      Spectrum Le = scene.emitted(sp.si, sp.wo);
      if (!is_black(Le)) {
        float w = specular ? 1.0f : power_heuristic(prev_pdf, scene.light_pdf(prev_p, sp.si));
        L += beta * Le * w;
      }
      if (depth >= max_depth_) break;
      if (!sp.bsdf.is_specular()) L += beta * sample_one_light(scene, accel, sp, sampler, true, info);

      Bsdf::Sample bs;
      if (!sp.bsdf.sample(sp.frame.to_local(sp.wo), sampler.next1d(), sampler.next2d(), bs)) break;
      Vec3f wi = sp.frame.to_world(bs.wi);
      // A sampled direction on the wrong side of the geometric surface would leak through it.
      bool below = dot(wi, sp.ng) < 0;
      if (sp.bsdf.type != MaterialType::kDielectric && below) break;
      if (is_black(bs.weight)) break;
      beta *= bs.weight;
      specular = bs.specular;
      prev_pdf = bs.pdf;
      prev_p = sp.si.p;
      ray.o = offset_ray_origin(sp.si.p, below ? -sp.ng : sp.ng);
      ray.d = wi;
      ray.tmin = 0;
      ray.tmax = kInf;

      if (rr_depth_ > 0 && depth + 1 >= rr_depth_) {
        float survive = std::min(1.0f, std::max(0.05f, max_component(beta)));
        if (sampler.next1d() >= survive) break;
        beta /= survive;
      }
    }
    return L;
  }

 private:
  int max_depth_;
  int rr_depth_;
};

}  // namespace

std::unique_ptr<Integrator> make_path_integrator(const IntegratorOptions& options) {
  return std::make_unique<PathIntegrator>(options);
}

}  // namespace pt
