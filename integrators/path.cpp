// Unidirectional path tracing with next-event estimation and multiple importance sampling.
//
// max_depth  bounces; 1 gives direct lighting only (the PBRT convention)
// rr_depth   Russian roulette from this many bounces on: a path survives with probability
//            max(0.05, min(1, sqrt(max throughput component))) and is reweighted by its inverse, so the
//            estimator stays unbiased (PBRT 3rd ed. 13.7). Where: see RussianRoulette.
// Light hits found by BSDF sampling are weighted against NEE with the power heuristic; specular
// bounces skip NEE and count emission at full weight (Veach 1997, ch. 9), except the one chain NEE
// also samples: a diffuse vertex, one mirror (flat or a sphere), an emitter (mirror_light.h), weighted against
// that sampler's density.
#include "integrators/mirror_light.h"
#include "integrators/visibility.h"
#include "core/scene/footprint.h"

#include <algorithm>

namespace pt {
namespace {

class PathIntegrator final : public Integrator {
 public:
  // prepare_job resolves --rr auto per scene; an integrator made without a job plays it safe.
  explicit PathIntegrator(const IntegratorOptions& o)
      : max_depth_(o.max_depth),
        rr_depth_(o.rr_depth),
        rr_(o.rr == RussianRoulette::kAuto ? RussianRoulette::kNextHit : o.rr),
        splits_(std::clamp(o.splits, 1, kMaxSplits)) {}

  Spectrum Li(const Ray& camera_ray, const Scene& scene, const Accel& accel, Sampler& sampler,
              SampleInfo& info) const override {
    PathState st;
    st.ray = camera_ray;
    Spectrum L(0.0f);
    // The shading points (some 400 bytes each) are this thread's, reused by every camera sample:
    // make_shading_point sets every field before anything reads one, and zeroing two of them per
    // camera sample was some 35 instructions, 1.7% of a one-bounce render's (the horizon with
    // --splits 1; docs/textures.md).
    static thread_local ShadingPoint sp, next;
    if (!next_vertex(scene, accel, sampler, info, 0, st, L, sp)) return L;
    // The vertices after the first are made in place in `next`: one shading point for all the
    // continuations, not one each.
    if (splits_ <= 1 || sp.bsdf.is_specular()) return L + continue_path(scene, accel, sampler, info, sp, st, next);
    // Splitting at the first vertex: the camera ray and the first hit are shared by `splits_`
    // continuations, each an estimate of the light leaving that point (stratified among themselves
    // by Sampler::split), averaged.
    const uint64_t dimension = sampler.dimension();
    Spectrum sum(0.0f);
    for (int k = 0; k < splits_; ++k) {
      sampler.split(dimension, static_cast<uint32_t>(k), static_cast<uint32_t>(splits_));
      sum += continue_path(scene, accel, sampler, info, sp, st, next);
    }
    return L + sum / static_cast<float>(splits_);
  }

 private:
  // What a path carries from one vertex to the next.
  struct PathState {
    Ray ray;
    Spectrum beta{1.0f};
    int depth = 0;
    bool specular = true;  // the camera "bounce" counts emission at full weight
    float prev_pdf = 0.0f;
    Vec3f prev_p, prev_n;  // the last vertex and its geometric normal, as its light sample saw them
    // The last diffuse vertex, the mirror the path has since reflected in and the point it did, when
    // the path is x -> mirror -> (this segment): the chain mirror light sampling also finds.
    int via_mirror = -1;
    Vec3f mirror_x, mirror_n, mirror_m;
    float mirror_x_pdf = 0.0f;
  };

  // Traces st.ray to the vertex at st.depth and adds what it sees (the sky, emission) to L. True,
  // with the vertex in sp, when the path goes on from it: within max_depth and past Russian roulette.
  bool next_vertex(const Scene& scene, const Accel& accel, Sampler& sampler, SampleInfo& info, int depth,
                   PathState& st, Spectrum& L, ShadingPoint& sp) const {
    st.depth = depth;
    std::optional<Hit> hit = intersect_visible(scene, accel, st.ray, sampler, info);
    if (!hit) {
      Spectrum Le = scene.environment_radiance(st.ray.d);
      if (depth == 0) Le = info.first_emission(Le);
      if (!is_black(Le)) {
        float w = st.specular ? 1.0f : power_heuristic(st.prev_pdf, scene.environment_pdf(st.ray.d));
        L += st.beta * Le * w;
      }
      return false;
    }
    make_shading_point(scene, st.ray, *hit, sp);
    Spectrum Le = scene.emitted(sp.si, sp.wo);
    if (depth == 0) Le = info.first_emission(Le);
    if (!is_black(Le)) {
      float w = 1.0f;
      if (!st.specular) {
        w = power_heuristic(st.prev_pdf, scene.light_pdf(st.prev_p, st.prev_n, sp.si));
      } else if (st.via_mirror >= 0) {
        w = power_heuristic(st.mirror_x_pdf,
                            mirror_light_pdf(scene, st.mirror_x, st.mirror_n, st.via_mirror, st.mirror_m, sp.si));
      }
      L += st.beta * Le * w;
    }
    if (depth >= max_depth_) return false;
    return rr_ != RussianRoulette::kNextHit || roulette(depth, sampler, st.beta);
  }

  // The light leaving vertex `first` toward the previous one: light samples there, then the bounces.
  // The vertices after the first are made in place in `next`.
  Spectrum continue_path(const Scene& scene, const Accel& accel, Sampler& sampler, SampleInfo& info,
                         const ShadingPoint& first, PathState st, ShadingPoint& next) const {
    Spectrum L(0.0f);
    const ShadingPoint* at = &first;  // the vertex the loop is at
    const bool mirrors = scene.has_mirrors();
    // A scene lit only by light that bounce rays find (a constant sky) has nothing to light-sample.
    const bool lights = scene.has_lights();
    for (;;) {
      const ShadingPoint& sp = *at;
      // Which chain the next segment continues: x -> mirror only when this hit is on a mirror
      // (flat or a sphere) reached straight from a diffuse vertex.
      int mirror = mirrors && !st.specular ? scene.mirror_of(sp.si.geom, sp.si.prim, sp.si.inst) : -1;
      if (mirror >= 0) {
        st.mirror_x = st.prev_p;
        st.mirror_n = st.prev_n;
        st.mirror_m = sp.si.p;
        st.mirror_x_pdf = st.prev_pdf;
      }
      st.via_mirror = mirror;
      if (lights && !sp.bsdf.is_specular()) {
        L += st.beta * sample_one_light(scene, accel, sp, sampler, true, info);
        // Through a mirror the light is two segments away: BSDF sampling reaches it only if the
        // path may take one more bounce, and both strategies must cover the same paths.
        if (mirrors && st.depth + 1 < max_depth_) L += st.beta * sample_light_via_mirror(scene, accel, sp, sampler, info);
      }

      Bsdf::Sample bs;
      if (!sp.bsdf.sample(sp.wo_local, sampler, bs)) break;
      Vec3f wi = sp.frame.to_world(bs.wi);
      // A sampled direction on the wrong side of the geometric surface would leak through it.
      bool below = dot(wi, sp.ng) < 0;
      if (!sp.bsdf.is_transmissive() && below) break;
      if (is_black(bs.weight)) break;
      st.beta *= bs.weight;
      st.specular = bs.specular;
      st.prev_pdf = bs.pdf;
      st.prev_p = sp.si.p;
      st.prev_n = sp.ng;
      st.ray.o = offset_ray_origin(sp.si.p, below ? -sp.ng : sp.ng);
      st.ray.d = wi;
      st.ray.tmin = 0;
      st.ray.tmax = kInf;
      if (scene.textured()) st.ray.diff = bounce_differential(st.ray.diff, sp.si, bs.specular ? 0.0f : bs.pdf);

      if (rr_ == RussianRoulette::kBeforeBounce && !roulette(st.depth + 1, sampler, st.beta)) break;
      // sp is not read again before it points at the new vertex (it may be `next` itself).
      if (!next_vertex(scene, accel, sampler, info, st.depth + 1, st, L, next)) break;
      at = &next;
    }
    return L;
  }

  // Russian roulette for a path at `depth` bounces: false to end it; survivors are reweighted.
  bool roulette(int depth, Sampler& sampler, Spectrum& beta) const {
    if (rr_depth_ <= 0 || depth < rr_depth_) return true;
    // Survival follows the square root of the throughput, not the throughput (as Cycles does): a
    // path whose throughput has fallen still carries light worth finding, and ending it early costs
    // more variance than the rays it saves (MSE x rays 3-16% lower on the scenes of docs/cycles.md).
    // The floor of 0.05 bounds the weight a survivor gets.
    float survive = std::min(1.0f, std::max(0.05f, std::sqrt(max_component(beta))));
    if (sampler.next1d() >= survive) return false;
    beta /= survive;
    return true;
  }

  int max_depth_;
  int rr_depth_;
  RussianRoulette rr_;
  int splits_;
};

}  // namespace

std::unique_ptr<Integrator> make_path_integrator(const IntegratorOptions& options) {
  return std::make_unique<PathIntegrator>(options);
}

}  // namespace pt
