// The metallic-roughness material (core/material/metallic_roughness.h): chi-square of sampling
// against pdf for the GGX lobe alone and the whole material over roughness 0.01-1 and grazing
// angles; reciprocity; energy <= 1; the white furnace (a metal with base colour 1, and a
// dielectric with base colour 1, reflect 1 at every angle and roughness, within 1%); the
// dielectric's stated albedo Es + b (1 - Es); and the shipped albedo table against a fresh
// quadrature of the BSDF's own single-scattering lobe.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/material/material.h"
#include "core/math/frame.h"
#include "core/math/rng.h"
#include "stats.h"

using namespace pt;

namespace {

constexpr double kPiD = 3.141592653589793;
constexpr double kSignificance = 1e-4;  // per chi-square test; ~60 tests

Vec3f at_angle(double theta_deg) {
  double t = theta_deg * kPiD / 180.0;
  return Vec3f(static_cast<float>(std::sin(t) * 0.6), static_cast<float>(std::sin(t) * 0.8), static_cast<float>(std::cos(t)));
}

// Directional albedo and pdf mass over the upper hemisphere by quadrature: Gauss-Legendre in
// u = cos(theta) split at the specular peak's cosine (so a narrow lobe is resolved), midpoint in phi.
struct Integral {
  double albedo[3] = {0, 0, 0};
  double pdf_mass = 0;
};
template <class B>
Integral integrate(const B& b, const Vec3f& wo, int n_theta = 400, int n_phi = 800) {
  static const double kNode[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double kWeight[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  Integral out;
  // Integrate in the frame of the mirror direction (the lobe is centred there) over the full sphere
  // of directions; eval and pdf are 0 below the horizon.
  Vec3f r{-wo.x, -wo.y, wo.z};
  Frame frame(r);
  const double dp = 2 * kPiD / n_phi;
  // theta from the mirror direction: panels denser near 0, by t = s^2 with s uniform.
  for (int i = 0; i < n_theta; ++i) {
    for (int g = 0; g < 4; ++g) {
      double s = (i + 0.5 + 0.5 * kNode[g]) / n_theta;  // in [0, 1]
      double theta = kPiD * s * s, dtheta = kPiD * 2 * s / n_theta * 0.5 * kWeight[g];
      double w = std::sin(theta) * dtheta * dp;
      for (int j = 0; j < n_phi; ++j) {
        double phi = (j + 0.5) * dp;
        Vec3f l(static_cast<float>(std::sin(theta) * std::cos(phi)), static_cast<float>(std::sin(theta) * std::sin(phi)),
                static_cast<float>(std::cos(theta)));
        Vec3f wi = frame.to_world(l);
        if (wi.z <= 0) continue;
        float pdf;
        Spectrum f = b.eval_pdf(wo, wi, pdf);
        for (int c = 0; c < 3; ++c) out.albedo[c] += f[c] * wi.z * w;
        out.pdf_mass += pdf * w;
      }
    }
  }
  return out;
}

// Chi-square of directions drawn by `sample` against `pdf`, on an equal-area grid over a cap of
// half-angle cap_rad around `axis` (sized to the lobe, so a narrow lobe spans many cells), plus one
// cell for everything else (outside the cap, or refused). Cell probabilities by an 8x8 midpoint
// rule of the pdf over each cell.
template <class SampleFn, class PdfFn>
stats::Chi2Result chi2_cap(const SampleFn& sample, const PdfFn& pdf, const Vec3f& axis, double cap_rad, int n = 200000,
                           int cells = 24) {
  Frame frame(axis);
  const double one_minus_cap = 1 - std::cos(cap_rad);
  auto to_cell = [&](const Vec3f& d, int& cx, int& cy) {
    Vec3f l = frame.to_local(d);
    double x = l.x, y = l.y, z = l.z;
    if (z <= 0) return false;
    double omc = (x * x + y * y) / (1 + z);  // 1 - cos, without cancellation
    double v = omc / one_minus_cap;
    if (v >= 1) return false;
    double phi = std::atan2(y, x);
    double u = phi < 0 ? phi / (2 * kPiD) + 1 : phi / (2 * kPiD);
    cx = std::min(cells - 1, static_cast<int>(u * cells));
    cy = std::min(cells - 1, static_cast<int>(v * cells));
    return true;
  };
  std::vector<double> observed(cells * cells + 1, 0.0), expected(cells * cells + 1, 0.0);
  Pcg32 rng(7, 11);
  for (int i = 0; i < n; ++i) {
    Vec3f d;
    int cx, cy;
    if (sample(rng, d) && to_cell(d, cx, cy)) {
      observed[cy * cells + cx] += 1;
    } else {
      observed.back() += 1;
    }
  }
  double inside = 0;
  const int sub = 8;
  const double cell_area = 2 * kPiD * one_minus_cap / (cells * cells);
  for (int cy = 0; cy < cells; ++cy) {
    for (int cx = 0; cx < cells; ++cx) {
      double sum = 0;
      for (int a = 0; a < sub; ++a) {
        for (int b = 0; b < sub; ++b) {
          double u = (cx + (a + 0.5) / sub) / cells, v = (cy + (b + 0.5) / sub) / cells;
          double omc = v * one_minus_cap, z = 1 - omc, rad = std::sqrt(std::max(0.0, omc * (2 - omc)));
          double phi = 2 * kPiD * u;
          Vec3f l(static_cast<float>(rad * std::cos(phi)), static_cast<float>(rad * std::sin(phi)), static_cast<float>(z));
          sum += pdf(frame.to_world(l));
        }
      }
      double p = sum / (sub * sub) * cell_area;
      expected[cy * cells + cx] = p * n;
      inside += p;
    }
  }
  expected.back() = std::max(0.0, 1 - inside) * n;
  return stats::chi2_test(observed, expected);
}

MetallicRoughnessBsdf material(Spectrum base, float metallic, float roughness) {
  return MetallicRoughnessBsdf{base, metallic, roughness, 1.5f};
}

const float kRoughness[] = {0.01f, 0.05f, 0.2f, 0.5f, 1.0f};
const double kAngles[] = {0.0, 45.0, 75.0, 88.0};

// The cap a lobe of this roughness needs: a few alpha around the mirror direction, the
// hemisphere for rough ones.
double cap_for(float roughness) { return std::min(kPiD / 2, 8.0 * std::max(roughness * roughness, 1e-4f) + 1e-3); }

}  // namespace

TEST_CASE("metallic-roughness: visible-normal sampling of the GGX lobe matches its pdf") {
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      Ggx ggx{std::max(r * r, kMinGgxAlpha)};
      Vec3f wo = normalize(at_angle(deg));
      auto sample = [&](Pcg32& rng, Vec3f& d) {
        Vec3f h = ggx.sample_visible_normal(wo, {rng.next_float(), rng.next_float()});
        d = h * (2.0f * dot(wo, h)) - wo;
        return true;  // below the horizon too: the visible-normal density covers the sphere
      };
      auto pdf = [&](const Vec3f& wi) {
        Vec3f h = normalize(wo + wi);
        return double(ggx.reflection_pdf(wo, h));
      };
      Vec3f axis{-wo.x, -wo.y, wo.z};
      auto res = chi2_cap(sample, pdf, axis, cap_for(r));
      INFO("roughness " << r << ", wo at " << deg << " degrees: " << res.message);
      CHECK(res.p_value > kSignificance);
    }
  }
}

TEST_CASE("metallic-roughness: sampling the whole material matches its pdf") {
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      for (float metallic : {0.0f, 0.5f, 1.0f}) {
        MetallicRoughnessBsdf b = material(Spectrum(0.9f, 0.6f, 0.3f), metallic, r);
        Vec3f wo = normalize(at_angle(deg));
        auto sample = [&](Pcg32& rng, Vec3f& d) {
          BsdfSample s;
          float u_lobe = rng.next_float();
          if (!b.sample(wo, u_lobe, {rng.next_float(), rng.next_float()}, s)) return false;
          d = s.wi;
          return true;
        };
        auto pdf = [&](const Vec3f& wi) { return double(b.pdf(wo, wi)); };
        // Around the mirror direction for the GGX lobe; the whole hemisphere for the cosine lobe.
        Vec3f axis{-wo.x, -wo.y, wo.z};
        auto near = chi2_cap(sample, pdf, axis, cap_for(r), 100000);
        auto all = chi2_cap(sample, pdf, Vec3f(0, 0, 1), kPiD / 2, 100000, 16);
        INFO("roughness " << r << ", metallic " << metallic << ", wo at " << deg << " degrees: " << near.message
                          << " / " << all.message);
        CHECK(near.p_value > kSignificance);
        CHECK(all.p_value > kSignificance);
      }
    }
  }
}

TEST_CASE("metallic-roughness: the sample's weight and pdf are what eval and pdf say") {
  Pcg32 rng(3, 4);
  int bad = 0, total = 0;
  for (float r : kRoughness) {
    for (double deg : kAngles) {
      MetallicRoughnessBsdf b = material(Spectrum(0.7f, 0.5f, 0.2f), 0.3f, r);
      Vec3f wo = normalize(at_angle(deg));
      for (int i = 0; i < 2000; ++i) {
        BsdfSample s;
        if (!b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s)) continue;
        ++total;
        float pdf = b.pdf(wo, s.wi);
        Spectrum expect = b.eval(wo, s.wi) * (s.wi.z / pdf);
        bool ok = !s.specular && std::abs(s.pdf - pdf) <= 1e-5f * pdf;
        for (int c = 0; c < 3; ++c) ok = ok && std::abs(s.weight[c] - expect[c]) <= 1e-4f * expect[c] + 1e-12f;
        bad += !ok;
      }
    }
  }
  CHECK(total > 30000);
  CHECK(bad == 0);
}

TEST_CASE("metallic-roughness: reciprocity f(wo, wi) = f(wi, wo)") {
  Pcg32 rng(9, 2);
  int mismatches = 0;
  for (float r : kRoughness) {
    MetallicRoughnessBsdf b = material(Spectrum(0.8f, 0.4f, 0.1f), 0.4f, r);
    for (int i = 0; i < 5000; ++i) {
      float z1 = rng.next_float(), z2 = rng.next_float(), p1 = 2 * kPi * rng.next_float(), p2 = 2 * kPi * rng.next_float();
      float s1 = std::sqrt(1 - z1 * z1), s2 = std::sqrt(1 - z2 * z2);
      Vec3f a{s1 * std::cos(p1), s1 * std::sin(p1), z1}, c{s2 * std::cos(p2), s2 * std::sin(p2), z2};
      if (a.z <= 1e-3f || c.z <= 1e-3f) continue;
      Spectrum f = b.eval(a, c), g = b.eval(c, a);
      for (int k = 0; k < 3; ++k) mismatches += std::abs(f[k] - g[k]) > 1e-4f * std::max(f[k], g[k]) + 1e-7f;
    }
  }
  CHECK(mismatches == 0);
}

TEST_CASE("metallic-roughness: white furnace, energy <= 1, and the dielectric's stated albedo") {
  // A metal with base colour 1 and a dielectric with base colour 1 reflect 1 at every angle and
  // roughness (within 1%: the albedo tables' interpolation); no material reflects more than 1;
  // a dielectric with base colour b reflects Es(mu) + b (1 - Es(mu)), Es the specular's albedo.
  for (float r : {0.01f, 0.05f, 0.1f, 0.25f, 0.4f, 0.6f, 0.8f, 1.0f}) {
    for (double deg : {0.0, 30.0, 60.0, 75.0, 85.0, 89.0}) {
      Vec3f wo = normalize(at_angle(deg));
      CAPTURE(r);
      CAPTURE(deg);
      Integral metal = integrate(material(Spectrum(1.0f), 1.0f, r), wo);
      Integral diel = integrate(material(Spectrum(1.0f), 0.0f, r), wo);
      Integral black = integrate(material(Spectrum(0.0f), 0.0f, r), wo);  // the specular alone: Es
      Integral coloured = integrate(material(Spectrum(0.9f, 0.5f, 0.1f), 0.5f, r), wo);
      CHECK(std::abs(metal.albedo[0] - 1.0) < 0.01);
      CHECK(std::abs(diel.albedo[0] - 1.0) < 0.01);
      double es = black.albedo[0];
      CHECK(es > 0.02);
      CHECK(es < 1.0);
      Integral grey = integrate(material(Spectrum(0.5f), 0.0f, r), wo);
      CHECK(std::abs(grey.albedo[0] - (es + 0.5 * (1 - es))) < 0.01);
      for (int c = 0; c < 3; ++c) CHECK(coloured.albedo[c] <= 1.0 + 1e-3);
      // The pdf integrates to 1 over the hemisphere, less what the GGX lobe sends below it.
      CHECK(metal.pdf_mass <= 1.0 + 1e-2);
    }
  }
}

TEST_CASE("metallic-roughness: the shipped albedo table matches a quadrature of the single-scattering lobe") {
  // E(mu, r) integrates D G2 / (4 mu_o mu_i) cos_i, the BSDF's own specular lobe with Fresnel 1:
  // the table (made by sampling visible normals) against direct quadrature of D and G2.
  for (int ri : {6, 20, 40, 63}) {
    float r = static_cast<float>(ggx_albedo_node(ri));
    Ggx ggx{std::max(r * r, kMinGgxAlpha)};
    for (int mi : {4, 8, 16, 40, 63}) {
      float mu = static_cast<float>(ggx_albedo_node(mi));
      Vec3f wo{std::sqrt(1 - mu * mu), 0.0f, mu};
      struct Lobe {
        const Ggx& g;
        Spectrum eval_pdf(const Vec3f& o, const Vec3f& i, float& pdf) const {
          pdf = 0;
          Vec3f h = normalize(o + i);
          return Spectrum(g.d(h) * g.g2(o, i) / (4 * o.z * i.z));
        }
      } lobe{ggx};
      double e = integrate(lobe, wo).albedo[0];
      CAPTURE(r);
      CAPTURE(mu);
      CHECK(std::abs(e - kGgxAlbedo[ri][mi]) < 2e-3);
    }
  }
}
