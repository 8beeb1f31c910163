// `normals`: the first surface's shading normal mapped from [-1,1]^3 to [0,1]^3, black where the
// ray escapes. Noise-free apart from pixel-footprint jitter.
#include "integrators/integrator.h"
#include "integrators/visibility.h"

namespace pt {
namespace {

class NormalsIntegrator final : public Integrator {
 public:
  Spectrum Li(const Ray& camera_ray, const Scene& scene, const Accel& accel, Sampler& sampler,
              SampleInfo& info) const override {
    Ray ray = camera_ray;
    std::optional<Hit> hit = intersect_visible(scene, accel, ray, sampler, info);
    if (!hit) return Spectrum(0.0f);
    SurfaceInteraction si = scene.interaction(ray, *hit);
    return si.ns * 0.5f + Vec3f(0.5f);
  }
};

}  // namespace

std::unique_ptr<Integrator> make_normals_integrator(const IntegratorOptions&) { return std::make_unique<NormalsIntegrator>(); }

}  // namespace pt
