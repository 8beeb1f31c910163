// Inspection integrators: `normals` shows the shading normal mapped to [0,1]^3, `albedo` the
// surface's reflectance. Both are noise-free apart from pixel-footprint jitter.
#include "integrators/integrator.h"

namespace pt {
namespace {

class NormalsIntegrator final : public Integrator {
 public:
  std::string name() const override { return "normals"; }
  Spectrum Li(const Ray& ray, const Scene& scene, const Accel& accel, Sampler&, SampleInfo& info) const override {
    ++info.rays;
    std::optional<Hit> hit = accel.intersect(ray);
    if (!hit) return Spectrum(0.0f);
    SurfaceInteraction si = scene.interaction(ray, *hit);
    return si.ns * 0.5f + Vec3f(0.5f);
  }
};

class AlbedoIntegrator final : public Integrator {
 public:
  std::string name() const override { return "albedo"; }
  Spectrum Li(const Ray& ray, const Scene& scene, const Accel& accel, Sampler&, SampleInfo& info) const override {
    ++info.rays;
    std::optional<Hit> hit = accel.intersect(ray);
    if (!hit) return Spectrum(0.0f);
    return scene.albedo(scene.interaction(ray, *hit));
  }
};

}  // namespace

std::unique_ptr<Integrator> make_normals_integrator() { return std::make_unique<NormalsIntegrator>(); }
std::unique_ptr<Integrator> make_albedo_integrator() { return std::make_unique<AlbedoIntegrator>(); }

}  // namespace pt
