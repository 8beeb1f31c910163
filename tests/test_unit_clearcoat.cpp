// The metallic-roughness material's clear coat (KHR_materials_clearcoat; MetallicRoughnessBsdf::Coat
// in core/material/metallic_roughness.h): chi-square of sampling the coated material against its
// pdf (three GGX-or-cosine lobes picked by albedo); white furnace (a white material under a coat of
// any weight and roughness reflects 1, within 1%); the stated albedo c Ec + (1 - c Ec) E_material;
// energy <= 1; and the one place it is not reciprocal, measured against its closed form. Range as
// test_unit_metallic_roughness.cpp: the sharpest coat tested (roughness 0.02) at 89 degrees is at
// the edge of what chi-square through float directions resolves (with 8M samples p = 0.005-0.06
// there over two seeds; every other case p >= 0.05).
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "chart_chi2.h"
#include "core/material/material.h"
#include "core/math/rng.h"
#include "microfacet_quadrature.h"
#include "stats.h"

using namespace pt;
using test::HalfVectorChart;
using test::at_angle;
using test::kPiQ;

namespace {

MetallicRoughnessBsdf coated(Spectrum base, float metallic, float roughness, float coat, float coat_roughness) {
  return MetallicRoughnessBsdf{base, metallic, roughness, 1.5f, coat, coat_roughness};
}

double alpha_of(float roughness) { return std::max(roughness * roughness, kMinGgxAlpha); }

// The chart of the narrower of the two GGX lobes: the wider one sits at v ~ alpha_narrow /
// alpha_wide there, which the chart's cuts at alpha 2^k bracket.
HalfVectorChart chart_for(const MetallicRoughnessBsdf& b, const Vec3f& wo) {
  return HalfVectorChart(wo, std::min(alpha_of(b.roughness), alpha_of(b.clearcoat_roughness)));
}

test::Values<3> albedo(const MetallicRoughnessBsdf& b, const Vec3f& wo) {
  auto g = [&](const Vec3f& wi) {
    Spectrum f = b.eval(wo, wi);
    return test::Values<3>{double(f.x) * wi.z, double(f.y) * wi.z, double(f.z) * wi.z};
  };
  return chart_for(b, wo).integrate<3>(g, 0, 1, -kPiQ, kPiQ, 1e-9, 1e-6);
}

// (base roughness, coat roughness, coat weight): a rough base under a sharp coat, the reverse, equal.
struct Case {
  float roughness, coat_roughness, coat;
};
const Case kCases[] = {{0.5f, 0.05f, 1.0f}, {0.05f, 0.4f, 0.5f}, {1.0f, 0.02f, 1.0f}, {0.2f, 0.2f, 0.7f}};
const double kAngles[] = {0.0, 45.0, 80.0, 89.0};
constexpr int kChi2Tests = 4 * 4 * 2;
const double kSignificance = stats::sidak(1e-3, kChi2Tests);

}  // namespace

TEST_CASE("clear coat: sampling the coated material matches its pdf (chi-square)") {
  for (const Case& k : kCases) {
    for (double deg : kAngles) {
      for (float metallic : {0.0f, 1.0f}) {
        MetallicRoughnessBsdf b = coated(Spectrum(0.8f, 0.5f, 0.2f), metallic, k.roughness, k.coat, k.coat_roughness);
        Vec3f wo = at_angle(deg);
        auto sample = [&](Pcg32& rng, Vec3f& wi) {
          BsdfSample s;
          float u_lobe = rng.next_float(), u0 = rng.next_float(), u1 = rng.next_float();
          if (!b.sample(wo, u_lobe, {u0, u1}, s)) return false;
          wi = s.wi;
          return true;
        };
        auto pdf = [&](const Vec3f& wi) { return b.pdf(wo, wi); };
        auto res = test::chi2_in_chart(chart_for(b, wo), sample, pdf, 1000000, 31);
        INFO("roughness " << k.roughness << ", coat " << k.coat << " of roughness " << k.coat_roughness << ", metallic "
                          << metallic << ", wo at " << deg << " degrees: " << res.message << ", significance " << kSignificance);
        CHECK(res.p_value > kSignificance);
      }
    }
  }
}

TEST_CASE("clear coat: a sample's weight and pdf are what eval and pdf say") {
  Pcg32 rng(13, 14);
  int bad = 0, total = 0, coat_like = 0;
  for (const Case& k : kCases) {
    for (double deg : kAngles) {
      MetallicRoughnessBsdf b = coated(Spectrum(0.7f, 0.5f, 0.2f), 0.3f, k.roughness, k.coat, k.coat_roughness);
      Vec3f wo = at_angle(deg);
      for (int i = 0; i < 2000; ++i) {
        BsdfSample s;
        float u_lobe = rng.next_float(), u0 = rng.next_float(), u1 = rng.next_float();
        if (!b.sample(wo, u_lobe, {u0, u1}, s)) continue;
        ++total;
        coat_like += u_lobe < 0.05f;
        float pdf = b.pdf(wo, s.wi);
        Spectrum expect = b.eval(wo, s.wi) * (s.wi.z / pdf);
        bool ok = !s.specular && std::abs(s.pdf - pdf) <= 1e-5f * pdf;
        for (int c = 0; c < 3; ++c) ok = ok && std::abs(s.weight[c] - expect[c]) <= 1e-4f * expect[c] + 1e-12f;
        bad += !ok;
      }
    }
  }
  CHECK(total > 25000);
  CHECK(bad == 0);
}

TEST_CASE("clear coat: a white material under any coat reflects 1, and the coated albedo is c Ec + (1 - c Ec) E") {
  double worst_white = 0, worst_stated = 0;
  for (float coat_r : {0.02f, 0.1f, 0.5f, 1.0f}) {
    for (float coat : {0.5f, 1.0f}) {
      for (float r : {0.05f, 0.5f, 1.0f}) {
        for (double deg : {0.0, 30.0, 60.0, 80.0, 89.0}) {
          Vec3f wo = at_angle(deg);
          CAPTURE(coat_r);
          CAPTURE(coat);
          CAPTURE(r);
          CAPTURE(deg);
          for (float metallic : {0.0f, 1.0f}) {
            double white = albedo(coated(Spectrum(1.0f), metallic, r, coat, coat_r), wo)[0];
            CHECK(std::abs(white - 1.0) < 0.01);
            worst_white = std::max(worst_white, std::abs(white - 1.0));
          }
          // A coloured dielectric: its albedo E under the coat's Ec from the tables.
          const Spectrum base(0.9f, 0.4f, 0.1f);
          test::Values<3> bare = albedo(coated(base, 0.0f, r, 0.0f, coat_r), wo);
          test::Values<3> with = albedo(coated(base, 0.0f, r, coat, coat_r), wo);
          MetallicRoughnessBsdf b = coated(base, 0.0f, r, coat, coat_r);
          MetallicRoughnessBsdf::Coat c = b.coat();
          double ec = MetallicRoughnessBsdf::coat_albedo(c, wo.z, table_lookup(kGgxAlbedo, c.r, wo.z));
          for (int k = 0; k < 3; ++k) {
            double stated = coat * ec + (1 - coat * ec) * bare[k];
            CHECK(std::abs(with[k] - stated) < 0.003);
            CHECK(with[k] <= 1.0 + 1e-3);
            worst_stated = std::max(worst_stated, std::abs(with[k] - stated));
          }
        }
      }
    }
  }
  MESSAGE("largest |white - 1| " << worst_white << "; largest |albedo - (c Ec + (1 - c Ec) E)| " << worst_stated);
}

TEST_CASE("clear coat: f(wo, wi) - f(wi, wo) = c (Ec(mu_i) - Ec(mu_o)) f_material(wo, wi), and nothing else breaks reciprocity") {
  Pcg32 rng(17, 18);
  int mismatches = 0, compared = 0;
  double largest = 0;
  for (const Case& k : kCases) {
    MetallicRoughnessBsdf b = coated(Spectrum(0.8f, 0.4f, 0.1f), 0.4f, k.roughness, k.coat, k.coat_roughness);
    MetallicRoughnessBsdf bare = b;
    bare.clearcoat = 0;
    MetallicRoughnessBsdf::Coat c = b.coat();
    auto ec = [&](float mu) { return MetallicRoughnessBsdf::coat_albedo(c, mu, table_lookup(kGgxAlbedo, c.r, mu)); };
    for (int i = 0; i < 3000; ++i) {
      float z1 = rng.next_float(), z2 = rng.next_float(), p1 = 2 * kPi * rng.next_float(), p2 = 2 * kPi * rng.next_float();
      float s1 = std::sqrt(1 - z1 * z1), s2 = std::sqrt(1 - z2 * z2);
      Vec3f a{s1 * std::cos(p1), s1 * std::sin(p1), z1}, d{s2 * std::cos(p2), s2 * std::sin(p2), z2};
      if (a.z <= 0 || d.z <= 0) continue;
      Spectrum f = b.eval(a, d), g = b.eval(d, a), base = bare.eval(a, d);
      ++compared;
      for (int n = 0; n < 3; ++n) {
        double expected = k.coat * (ec(d.z) - ec(a.z)) * base[n];
        double scale = std::max({double(f[n]), double(g[n]), 1e-6});
        largest = std::max(largest, std::abs(double(f[n]) - g[n]) / scale);
        mismatches += std::abs((double(f[n]) - g[n]) - expected) > 1e-4 * scale;
      }
    }
  }
  CHECK(compared > 10000);
  CHECK(mismatches == 0);
  MESSAGE("largest relative |f(wo, wi) - f(wi, wo)| with a coat: " << largest);
}
