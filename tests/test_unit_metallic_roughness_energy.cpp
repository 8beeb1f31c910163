// The metallic-roughness material's energy (core/material/metallic_roughness.h), by numerical
// integration of eval() over the hemisphere in the half-vector chart (tests/microfacet_quadrature.h):
//   - white furnace: a metal of base colour 1 reflects 1 at every roughness and angle, within 1%;
//   - the dielectric conserves the same way (base colour 1 reflects 1), and with base colour b it
//     reflects Es + b (1 - Es), Es being the specular layer's own albedo (what a black dielectric
//     reflects), which is also what the model computes from its tables;
//   - no material reflects more than it receives, and the pdf integrates to at most 1;
// and the shipped GGX albedo tables (core/material/ggx_albedo.h) against quadratures of the
// BSDF's own single-scattering lobe (ggx.h), at the nodes and between them, against 20-digit
// values from mpmath, and the averages the compensation needs against the tables themselves.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/material/material.h"
#include "core/math/rng.h"
#include "microfacet_quadrature.h"

using namespace pt;
using test::HalfVectorChart;
using test::at_angle;
using test::kPiQ;

namespace {

MetallicRoughnessBsdf material(Spectrum base, float metallic, float roughness) {
  return MetallicRoughnessBsdf{base, metallic, roughness, 1.5f};
}

struct Albedo {
  double rgb[3] = {0, 0, 0};  // integral of f cos over the hemisphere
  double pdf_mass = 0;        // integral of pdf over it
};

Albedo integrate(const MetallicRoughnessBsdf& b, const Vec3f& wo) {
  HalfVectorChart chart(wo, std::max(b.roughness * b.roughness, kMinGgxAlpha));
  auto g = [&](const Vec3f& wi) {
    float pdf;
    Spectrum f = b.eval_pdf(wo, wi, pdf);
    return test::Values<4>{double(f.x) * wi.z, double(f.y) * wi.z, double(f.z) * wi.z, double(pdf)};
  };
  test::Values<4> v = chart.integrate<4>(g, 0, 1, -kPiQ, kPiQ, 1e-9, 1e-6);
  Albedo a;
  for (int c = 0; c < 3; ++c) a.rgb[c] = v[c];
  a.pdf_mass = v[3];
  return a;
}

// The directional albedo of GGX single scattering with Fresnel 1 (and with Schlick's weight
// (1 - wo.h)^5) at mu for roughness r, by quadrature of ggx.h's D and G2: the quantity the tables hold.
std::pair<double, double> single_scattering(float roughness, float mu) {
  Ggx ggx{std::max(roughness * roughness, kMinGgxAlpha)};
  Vec3f wo{std::sqrt(std::max(0.0f, 1 - mu * mu)), 0.0f, mu};
  HalfVectorChart chart(wo, ggx.alpha);
  auto g = [&](const Vec3f& wi) {
    Vec3f h = normalize(wo + wi);
    double f_cos = double(ggx.d(h)) * ggx.g2(wo, wi) / (4.0 * wo.z);
    return test::Values<2>{f_cos, f_cos * schlick_weight(dot(wo, h))};
  };
  test::Values<2> v = chart.integrate<2>(g, 0, 1, -kPiQ, kPiQ, 1e-10, 1e-6);
  return {v[0], v[1]};
}

// The pdf's integral may exceed 1 by this much through float rounding: at roughness 0.01
// (alpha 1e-4) the float half vector's tilt carries ~6e-8 / alpha = 6e-4 relative error, so the
// quadrature of the float pdf does not converge below ~1e-5 (4e-5 over 1 was seen at 60 degrees).
constexpr double kPdfMassRounding = 1e-4;

const float kRoughness[] = {0.01f, 0.02f, 0.05f, 0.1f, 0.2f, 0.3f, 0.5f, 0.7f, 0.85f, 1.0f};
const double kAngles[] = {0.0, 30.0, 60.0, 75.0, 85.0, 89.0};

}  // namespace

TEST_CASE("metallic-roughness: white furnace: metal and dielectric of base colour 1 reflect 1 at every roughness and angle") {
  double worst_metal = 0, worst_dielectric = 0;
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      Vec3f wo = at_angle(deg);
      CAPTURE(r);
      CAPTURE(deg);
      Albedo metal = integrate(material(Spectrum(1.0f), 1.0f, r), wo);
      Albedo dielectric = integrate(material(Spectrum(1.0f), 0.0f, r), wo);
      for (int c = 0; c < 3; ++c) {
        CHECK(std::abs(metal.rgb[c] - 1.0) < 0.01);
        CHECK(std::abs(dielectric.rgb[c] - 1.0) < 0.01);
      }
      worst_metal = std::max(worst_metal, std::abs(metal.rgb[0] - 1.0));
      worst_dielectric = std::max(worst_dielectric, std::abs(dielectric.rgb[0] - 1.0));
      CHECK(metal.pdf_mass <= 1.0 + kPdfMassRounding);
      CHECK(dielectric.pdf_mass <= 1.0 + kPdfMassRounding);
    }
  }
  MESSAGE("largest |albedo - 1|: metal " << worst_metal << ", dielectric " << worst_dielectric);
}

TEST_CASE("metallic-roughness: the dielectric reflects Es + b (1 - Es), Es its specular layer's albedo") {
  // A black dielectric is its specular layer alone: its albedo is Es, measured. The model computes
  // Es(mu) = F0 E + (1 - F0) E_schlick + (1 - E) Fms from its tables; the two agree to the tables'
  // interpolation error. With base colour b the diffuse base adds exactly b (1 - Es).
  double worst_layer = 0, worst_table = 0;
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      Vec3f wo = at_angle(deg);
      CAPTURE(r);
      CAPTURE(deg);
      double es = integrate(material(Spectrum(0.0f), 0.0f, r), wo).rgb[0];
      CHECK(es > 0.0);
      CHECK(es < 1.0);
      const Spectrum base(0.9f, 0.5f, 0.1f);
      Albedo coloured = integrate(material(base, 0.0f, r), wo);
      for (int c = 0; c < 3; ++c) {
        double stated = es + base[c] * (1 - es);
        CHECK(std::abs(coloured.rgb[c] - stated) < 0.01);
        worst_layer = std::max(worst_layer, std::abs(coloured.rgb[c] - stated));
      }
      MetallicRoughnessBsdf black = material(Spectrum(0.0f), 0.0f, r);
      MetallicRoughnessBsdf::Terms t = black.terms();
      double table_es = MetallicRoughnessBsdf::e_dielectric(t, wo.z, MetallicRoughnessBsdf::e_single(t, wo.z));
      CHECK(std::abs(table_es - es) < 0.003);
      worst_table = std::max(worst_table, std::abs(table_es - es));
    }
  }
  MESSAGE("largest |albedo - (Es + b (1 - Es))| " << worst_layer << "; largest |Es from the tables - Es measured| " << worst_table);
}

TEST_CASE("metallic-roughness: no material reflects more than it receives, and the pdf integrates to at most 1") {
  Pcg32 rng(5, 6);
  for (int i = 0; i < 60; ++i) {
    Spectrum base(rng.next_float(), rng.next_float(), rng.next_float());
    if (i % 4 == 0) base = Spectrum(1.0f, rng.next_float(), 0.0f);
    float metallic = i % 3 == 0 ? rng.next_float() : float(i % 3 - 1);
    float r = kRoughness[i % 10];
    double deg = kAngles[i % 6];
    CAPTURE(i);
    Albedo a = integrate(material(base, metallic, r), at_angle(deg));
    for (int c = 0; c < 3; ++c) CHECK(a.rgb[c] <= 1.0 + 1e-3);
    CHECK(a.pdf_mass <= 1.0 + kPdfMassRounding);
  }
}

TEST_CASE("GGX albedo tables: the entries against a quadrature of ggx.h's lobe, and against mpmath") {
  // At the nodes: only the generator's quadrature and the float storage separate them, wherever
  // the float BSDF can be integrated to that precision: where its reflected lobe is at least
  // 2 mu alpha = 1e-4 rad across (~1700 float ulps of wi). Narrower, float rounding of the half
  // vector shows (at roughness 0.016 and mu 0.016 the quadrature through ggx.h is off by 1.7e-4,
  // at mu 0.001 by 1e-3, in float or double lobe arithmetic alike, as wi is a float); there the
  // 20-digit mpmath values below check the table.
  int compared = 0;
  for (int ri : {8, 12, 20, 30, 44, 63}) {
    for (int mi : {4, 8, 12, 16, 30, 45, 63}) {
      float r = static_cast<float>(ggx_albedo_node(ri)), mu = static_cast<float>(ggx_albedo_node(mi));
      if (2 * mu * std::max(r * r, kMinGgxAlpha) < 1e-4f) continue;
      ++compared;
      CAPTURE(r);
      CAPTURE(mu);
      auto [e, e5] = single_scattering(r, mu);
      CHECK(std::abs(e - kGgxAlbedo[ri][mi]) < 2e-5);
      CHECK(std::abs(e5 - kGgxAlbedoSchlick[ri][mi]) < 2e-5);
    }
  }
  CHECK(compared >= 30);
  // 20-digit mpmath quadratures (over the half vector in (theta_h, phi), the horizon a limit of the
  // phi integral, dps 20) of single-scattering E at table nodes (roughness node, mu node, E).
  struct Reference {
    int ri, mi;
    double e;
  };
  const Reference kMpmath[] = {{63, 63, 0.30685415}, {63, 8, 0.933188}, {63, 1, 0.99791218}, {20, 8, 0.89988592},
                               {20, 1, 0.9947947},   {10, 2, 0.89998091}, {6, 2, 0.99427696}, {6, 1, 0.93101535}};
  for (const Reference& ref : kMpmath) {
    CAPTURE(ref.ri);
    CAPTURE(ref.mi);
    CHECK(std::abs(kGgxAlbedo[ref.ri][ref.mi] - ref.e) < 2e-6);
  }
}

TEST_CASE("GGX albedo tables: interpolated between the nodes, within 0.002 of a quadrature up to 89 degrees") {
  // The compensation's white furnace is off by exactly the interpolation error of E at wo, so this
  // bounds how far from 1 it can be. Largest seen by the generator's quadrature at random points:
  // 0.0007 (E) and 0.0012 (E_schlick) for roughness 0.01-1 and 0-89 degrees.
  Pcg32 rng(11, 12);
  double worst = 0, worst5 = 0;
  for (int i = 0; i < 120; ++i) {
    float r = i % 2 ? 0.01f + 0.99f * rng.next_float() : std::exp(std::log(0.01f) * rng.next_float());
    double deg = i % 3 ? 89.0 * rng.next_float() : 89.0 - 6.0 * rng.next_float();
    float mu = static_cast<float>(std::cos(deg * kPiQ / 180));
    CAPTURE(r);
    CAPTURE(deg);
    auto [e, e5] = single_scattering(r, mu);
    TableCoord c(r);
    double te = table_lookup(kGgxAlbedo, c, mu), te5 = table_lookup(kGgxAlbedoSchlick, c, mu);
    CHECK(std::abs(te - e) < 0.002);
    CHECK(std::abs(te5 - e5) < 0.002);
    worst = std::max(worst, std::abs(te - e));
    worst5 = std::max(worst5, std::abs(te5 - e5));
  }
  MESSAGE("largest interpolation error: E " << worst << ", E_schlick " << worst5);
}

TEST_CASE("GGX albedo tables: the averages are 2 integral E(mu) mu dmu of the interpolated rows") {
  // The compensation lobe (1 - E(mu_o)) (1 - E(mu_i)) / (pi (1 - E_avg)) reflects exactly
  // 1 - E(mu_o) only if E_avg is the cosine-weighted average of the very function looked up.
  for (int ri = 0; ri < kGgxAlbedoSize; ri += 7) {
    TableCoord c(static_cast<float>(ggx_albedo_node(ri)));
    double sum = 0, sum5 = 0;
    const int n = 20000;  // midpoints in x = sqrt(mu), mu = x^2, dmu = 2x dx
    for (int k = 0; k < n; ++k) {
      double x = (k + 0.5) / n, mu = x * x;
      sum += 2 * table_lookup(kGgxAlbedo, c, static_cast<float>(mu)) * mu * 2 * x / n;
      sum5 += 2 * table_lookup(kGgxAlbedoSchlick, c, static_cast<float>(mu)) * mu * 2 * x / n;
    }
    CAPTURE(ri);
    CHECK(std::abs(sum - kGgxAlbedoAvg[ri]) < 1e-5);
    CHECK(std::abs(sum5 - kGgxAlbedoSchlickAvg[ri]) < 1e-5);
  }
}
