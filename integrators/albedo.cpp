// `albedo`: the first surface's reflectance (texture included), black where the ray escapes.
// Noise-free apart from pixel-footprint jitter; a denoiser's albedo input and a check of materials.
#include "integrators/integrator.h"
#include "integrators/visibility.h"

namespace pt {
namespace {

class AlbedoIntegrator final : public Integrator {
 public:
  Spectrum Li(const Ray& camera_ray, const Scene& scene, const Accel& accel, Sampler& sampler,
              SampleInfo& info) const override {
    Ray ray = camera_ray;
    std::optional<Hit> hit = intersect_visible(scene, accel, ray, sampler, info);
    if (!hit) return Spectrum(0.0f);
    return scene.albedo(scene.interaction(ray, *hit));
  }
};

}  // namespace

std::unique_ptr<Integrator> make_albedo_integrator(const IntegratorOptions&) { return std::make_unique<AlbedoIntegrator>(); }

}  // namespace pt
