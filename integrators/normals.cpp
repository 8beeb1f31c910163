// `normals`: the first surface's shading normal mapped from [-1,1]^3 to [0,1]^3, black where the
// ray escapes. Noise-free apart from pixel-footprint jitter.
#include "integrators/integrator.h"

namespace pt {
namespace {

class NormalsIntegrator final : public Integrator {
 public:
  Spectrum Li(const Ray& ray, const Scene& scene, const Accel& accel, Sampler&, SampleInfo& info) const override {
    ++info.rays;
    std::optional<Hit> hit = accel.intersect(ray);
    if (!hit) return Spectrum(0.0f);
    SurfaceInteraction si = scene.interaction(ray, *hit);
    return si.ns * 0.5f + Vec3f(0.5f);
  }
};

}  // namespace

std::unique_ptr<Integrator> make_normals_integrator(const IntegratorOptions&) { return std::make_unique<NormalsIntegrator>(); }

}  // namespace pt
