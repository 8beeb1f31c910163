// The metallic-roughness material's sampling (core/material/metallic_roughness.h): chi-square of
// the directions sample() draws against pdf(), for the GGX lobe alone (visible normals, ggx.h) and
// for the whole material (GGX lobe + cosine lobe, picked by their albedos); the sample's weight and
// pdf against eval() and pdf(); reciprocity. Energy, furnaces and the albedo tables are in
// test_unit_metallic_roughness_energy.cpp.
//
// Chi-square cells are laid out in the half-vector chart of tests/microfacet_quadrature.h, where a
// GGX lobe of any width is spread over the whole chart: rows of v at quantiles of a pilot run (a
// separate seed), 16 columns of phi. A cell's probability is the pdf integrated over it by
// adaptive Gauss-Kronrod in that chart, with the horizon as a limit of integration; one more cell
// takes the samples sample() refuses or that fall below the horizon.
//
// Range: roughness 0.01-1 with the outgoing direction up to 80 degrees from the normal, and
// 0.02-1 up to 89 degrees. At roughness 0.01 (alpha 1e-4) and 89 degrees the reflected lobe is
// 2 mu alpha = 3.5e-6 rad wide across the plane of incidence, about 60 float ulps of a direction.
// There, with 8M samples, chi-square fails (roughness 0.01 from 85 degrees, 0.015 from 88) the
// same way whether the sampler and the pdf run in float or in double: the residuals alternate
// between neighbouring phi columns next to the lobe's peak, where h's azimuth is decided by a few
// ulps of wi, i.e. the cells see the float lattice of directions, not the sampler. With 8M
// samples roughness 0.02 passes at 80-89 degrees (p >= 0.04).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/material/material.h"
#include "core/math/rng.h"
#include "chart_chi2.h"
#include "microfacet_quadrature.h"
#include "stats.h"

using namespace pt;
using test::HalfVectorChart;
using test::at_angle;
using test::kPiQ;

namespace {

// The chi-square tests below, together, fail with this probability when the sampler is right.
constexpr double kFamilyAlpha = 1e-3;
constexpr int kChi2Tests = 23 + 23 * 3;  // the (roughness, angle) pairs in range, x 3 metallic values for the whole material
const double kSignificance = stats::sidak(kFamilyAlpha, kChi2Tests);

const float kRoughness[] = {0.01f, 0.02f, 0.05f, 0.2f, 0.5f, 1.0f};
const double kAngles[] = {0.0, 45.0, 80.0, 89.0};
bool in_range(float roughness, double degrees) { return roughness >= 0.02f || degrees <= 80.0; }
constexpr int kSamples = 1000000;

double ggx_alpha(float roughness) { return std::max(roughness * roughness, kMinGgxAlpha); }

MetallicRoughnessBsdf material(Spectrum base, float metallic, float roughness) {
  return MetallicRoughnessBsdf{base, metallic, roughness, 1.5f};
}

}  // namespace

TEST_CASE("metallic-roughness: visible-normal sampling of the GGX lobe matches its pdf (chi-square)") {
  int tested = 0;
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      if (!in_range(r, deg)) continue;
      Ggx ggx{static_cast<float>(ggx_alpha(r))};
      Vec3f wo = at_angle(deg);
      HalfVectorChart chart(wo, ggx.alpha);
      auto sample = [&](Pcg32& rng, Vec3f& wi) {
        float u0 = rng.next_float(), u1 = rng.next_float();
        Vec3f h = ggx.sample_visible_normal(wo, {u0, u1});
        wi = h * (2.0f * dot(wo, h)) - wo;
        return true;
      };
      auto pdf = [&](const Vec3f& wi) { return ggx.reflection_pdf(wo, normalize(wo + wi)); };
      auto res = test::chi2_in_chart(chart, sample, pdf, kSamples, 17);
      INFO("roughness " << r << ", wo at " << deg << " degrees: " << res.message << ", significance " << kSignificance);
      CHECK(res.p_value > kSignificance);
      ++tested;
    }
  }
  CHECK(tested == 23);
}

TEST_CASE("metallic-roughness: sampling the whole material matches its pdf (chi-square)") {
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      if (!in_range(r, deg)) continue;
      for (float metallic : {0.0f, 0.5f, 1.0f}) {
        MetallicRoughnessBsdf b = material(Spectrum(0.9f, 0.6f, 0.3f), metallic, r);
        Vec3f wo = at_angle(deg);
        HalfVectorChart chart(wo, ggx_alpha(r));
        auto sample = [&](Pcg32& rng, Vec3f& wi) {
          BsdfSample s;
          float u_lobe = rng.next_float(), u0 = rng.next_float(), u1 = rng.next_float();
          if (!b.sample(wo, u_lobe, {u0, u1}, s)) return false;
          wi = s.wi;
          return true;
        };
        auto pdf = [&](const Vec3f& wi) { return b.pdf(wo, wi); };
        auto res = test::chi2_in_chart(chart, sample, pdf, kSamples, 29);
        INFO("roughness " << r << ", metallic " << metallic << ", wo at " << deg << " degrees: " << res.message
                          << ", significance " << kSignificance);
        CHECK(res.p_value > kSignificance);
      }
    }
  }
}

TEST_CASE("metallic-roughness: a sample's weight and pdf are what eval and pdf say") {
  Pcg32 rng(3, 4);
  int bad = 0, total = 0;
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      MetallicRoughnessBsdf b = material(Spectrum(0.7f, 0.5f, 0.2f), 0.3f, r);
      Vec3f wo = at_angle(deg);
      for (int i = 0; i < 2000; ++i) {
        BsdfSample s;
        float u_lobe = rng.next_float(), u0 = rng.next_float(), u1 = rng.next_float();
        if (!b.sample(wo, u_lobe, {u0, u1}, s)) continue;
        ++total;
        float pdf = b.pdf(wo, s.wi);
        Spectrum expect = b.eval(wo, s.wi) * (s.wi.z / pdf);
        bool ok = !s.specular && s.wi.z > 0 && std::abs(s.pdf - pdf) <= 1e-5f * pdf;
        for (int c = 0; c < 3; ++c) ok = ok && std::abs(s.weight[c] - expect[c]) <= 1e-4f * expect[c] + 1e-12f;
        bad += !ok;
      }
    }
  }
  CHECK(total > 35000);
  CHECK(bad == 0);
}

TEST_CASE("metallic-roughness: reciprocity f(wo, wi) = f(wi, wo), compensation lobes included") {
  // Every term is symmetric in wo and wi: the GGX lobe (Schlick on wo.h = wi.h, height-correlated
  // G2), the multiple-scattering lobe (1 - E(mu_o)) (1 - E(mu_i)) and the diffuse base
  // (1 - Es(mu_o)) (1 - Es(mu_i)) (the same table lookups on both sides). Only float rounding
  // separates the two evaluations.
  Pcg32 rng(9, 2);
  int mismatches = 0, compared = 0;
  for (float r : {0.01f, 0.05f, 0.2f, 0.5f, 1.0f}) {
    for (float metallic : {0.0f, 0.4f, 1.0f}) {
      MetallicRoughnessBsdf b = material(Spectrum(0.8f, 0.4f, 0.1f), metallic, r);
      for (int i = 0; i < 3000; ++i) {
        // Uniform over the hemisphere, down to grazing.
        float z1 = rng.next_float(), z2 = rng.next_float(), p1 = 2 * kPi * rng.next_float(), p2 = 2 * kPi * rng.next_float();
        float s1 = std::sqrt(1 - z1 * z1), s2 = std::sqrt(1 - z2 * z2);
        Vec3f a{s1 * std::cos(p1), s1 * std::sin(p1), z1}, c{s2 * std::cos(p2), s2 * std::sin(p2), z2};
        if (a.z <= 0 || c.z <= 0) continue;
        Spectrum f = b.eval(a, c), g = b.eval(c, a);
        ++compared;
        for (int k = 0; k < 3; ++k) mismatches += std::abs(f[k] - g[k]) > 1e-4f * std::max(f[k], g[k]) + 1e-7f;
      }
    }
  }
  CHECK(compared > 40000);
  CHECK(mismatches == 0);
}

TEST_CASE("metallic-roughness: nothing below the surface, and nothing from below") {
  MetallicRoughnessBsdf b = material(Spectrum(0.8f), 0.5f, 0.3f);
  Vec3f up = at_angle(30), down{0.3f, 0.1f, -0.9f};
  float pdf = 1;
  CHECK(max_component(b.eval_pdf(up, down, pdf)) == 0);
  CHECK(pdf == 0);
  CHECK(max_component(b.eval(down, up)) == 0);
  BsdfSample s;
  CHECK_FALSE(b.sample(down, 0.5f, {0.3f, 0.7f}, s));
}
