// Unidirectional path tracing with next-event estimation and multiple importance sampling.
//
// max_depth  bounces; 1 gives direct lighting only (the PBRT convention)
// rr_depth   Russian roulette from this many bounces on: a path survives with probability
//            max(0.05, min(1, max throughput component)) and is reweighted by its inverse, so the
//            estimator stays unbiased (PBRT 3rd ed. 13.7). Where: see RussianRoulette.
// Light hits found by BSDF sampling are weighted against NEE with the power heuristic; specular
// bounces skip NEE and count emission at full weight (Veach 1997, ch. 9), except the one chain NEE
// also samples: a diffuse vertex, one flat mirror, an emitter (mirror_light.h), weighted against
// that sampler's density.
#include "integrators/mirror_light.h"
#include "integrators/visibility.h"

namespace pt {
namespace {

class PathIntegrator final : public Integrator {
 public:
  // prepare_job resolves --rr auto per scene; an integrator made without a job plays it safe.
  explicit PathIntegrator(const IntegratorOptions& o)
      : max_depth_(o.max_depth),
        rr_depth_(o.rr_depth),
        rr_(o.rr == RussianRoulette::kAuto ? RussianRoulette::kNextHit : o.rr) {}

  Spectrum Li(const Ray& camera_ray, const Scene& scene, const Accel& accel, Sampler& sampler,
              SampleInfo& info) const override {
    Ray ray = camera_ray;
    Spectrum L(0.0f), beta(1.0f);
    bool specular = true;  // the camera "bounce" counts emission at full weight
    float prev_pdf = 0.0f;
    Vec3f prev_p;
    // The last diffuse vertex and the mirror plane the path has since reflected in, when the path
    // is x -> flat mirror -> (this segment): the chain mirror light sampling also finds.
    int via_plane = -1;
    Vec3f mirror_x;
    float mirror_x_pdf = 0.0f;
    const bool mirrors = !scene.mirror_planes().empty();
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
        float w = 1.0f;
        if (!specular) {
          w = power_heuristic(prev_pdf, scene.light_pdf(prev_p, sp.si));
        } else if (via_plane >= 0) {
          w = power_heuristic(mirror_x_pdf, mirror_light_pdf(scene, mirror_x, via_plane, sp.si));
        }
        L += beta * Le * w;
      }
      if (depth >= max_depth_) break;
      if (rr_ == RussianRoulette::kNextHit && !roulette(depth, sampler, beta)) break;
      // Which chain the next segment continues: x -> mirror plane only when this hit is on a flat
      // mirror reached straight from a diffuse vertex.
      int plane = mirrors && !specular ? scene.mirror_plane_of(sp.si.geom, sp.si.prim) : -1;
      if (plane >= 0) {
        mirror_x = prev_p;
        mirror_x_pdf = prev_pdf;
      }
      via_plane = plane;
      if (!sp.bsdf.is_specular()) {
        L += beta * sample_one_light(scene, accel, sp, sampler, true, info);
        // Through a mirror the light is two segments away: BSDF sampling reaches it only if the
        // path may take one more bounce, and both strategies must cover the same paths.
        if (mirrors && depth + 1 < max_depth_) L += beta * sample_light_via_mirror(scene, accel, sp, sampler, info);
      }

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

      if (rr_ == RussianRoulette::kBeforeBounce && !roulette(depth + 1, sampler, beta)) break;
    }
    return L;
  }

 private:
  // Russian roulette for a path at `depth` bounces: false to end it; survivors are reweighted.
  bool roulette(int depth, Sampler& sampler, Spectrum& beta) const {
    if (rr_depth_ <= 0 || depth < rr_depth_) return true;
    float survive = std::min(1.0f, std::max(0.05f, max_component(beta)));
    if (sampler.next1d() >= survive) return false;
    beta /= survive;
    return true;
  }

  int max_depth_;
  int rr_depth_;
  RussianRoulette rr_;
};

}  // namespace

std::unique_ptr<Integrator> make_path_integrator(const IntegratorOptions& options) {
  return std::make_unique<PathIntegrator>(options);
}

}  // namespace pt
