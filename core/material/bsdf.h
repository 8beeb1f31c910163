// A BSDF at a shading point: one of the registered models' BSDFs (core/material/models.h), held by
// value in a std::variant and dispatched with std::visit. Virtual calls through a pointer to the
// same models measured no faster (docs/architecture.md, "Materials"). The integrators ask its
// flags, never which model it is.
#pragma once
#include <type_traits>
#include <variant>

#include "core/material/models.h"

namespace pt {

class Bsdf {
 public:
  using Sample = BsdfSample;

  Bsdf() : model_(DiffuseBsdf{Spectrum(0.0f)}), flags_(DiffuseBsdf::kFlags) {}
  template <class B>
  Bsdf(const B& b) : model_(b), flags_(b.flags()) {}  // NOLINT: a model's BSDF is a Bsdf

  uint8_t flags() const { return flags_; }
  bool has(uint8_t flag) const { return (flags_ & flag) != 0; }
  // Only delta lobes: light sampling cannot reach it, and a path through it keeps full MIS weight.
  bool is_specular() const { return (flags_ & (kBsdfDiffuse | kBsdfGlossy)) == 0; }
  // Light may pass to the other side: the surface has an inside and is not shaded two-sided.
  bool is_transmissive() const { return has(kBsdfTransmission); }

  Spectrum albedo() const {
    return std::visit([](const auto& b) { return b.albedo(); }, model_);
  }
  // f(wo, wi) without the cosine; zero for delta lobes.
  Spectrum eval(const Vec3f& wo, const Vec3f& wi) const {
    return std::visit([&](const auto& b) { return b.eval(wo, wi); }, model_);
  }
  float pdf(const Vec3f& wo, const Vec3f& wi) const {
    return std::visit([&](const auto& b) { return b.pdf(wo, wi); }, model_);
  }
  Spectrum eval_pdf(const Vec3f& wo, const Vec3f& wi, float& pdf_out) const {
    return std::visit([&](const auto& b) { return b.eval_pdf(wo, wi, pdf_out); }, model_);
  }
  // u_lobe chooses a lobe (or reflection against refraction); u chooses the direction. wo may be
  // below the surface only for a transmissive BSDF.
  bool sample(const Vec3f& wo, float u_lobe, Vec2f u, Sample& s) const {
    return std::visit([&](const auto& b) { return b.sample(wo, u_lobe, u, s); }, model_);
  }

  // The same with the numbers drawn from `sampler` (core/math/sampler.h): the lobe's, then the
  // direction's, each only where the model reads it (bsdf_sample.h, kDrawsLobe and
  // kDrawsDirection). A Lambertian bounce then costs one 2D point, not a 1D and a 2D one; a mirror
  // none. Which dimensions a path uses depends only on the path, so results stay deterministic.
  template <class S>
  bool sample(const Vec3f& wo, S& sampler, Sample& s) const {
    return std::visit(
        [&](const auto& b) {
          using B = std::decay_t<decltype(b)>;
          float u_lobe = 0.5f;
          Vec2f u{0.5f, 0.5f};
          if constexpr (bsdf_draws_lobe<B>()) u_lobe = sampler.next1d();
          if constexpr (bsdf_draws_direction<B>()) u = sampler.next2d();
          return b.sample(wo, u_lobe, u, s);
        },
        model_);
  }

  const MaterialModels::Bsdf& model() const { return model_; }

 private:
  MaterialModels::Bsdf model_;
  uint8_t flags_;
};

}  // namespace pt
