// BSDF consistency: reciprocity, energy (directional albedo by quadrature), sampling weights and
// probabilities against numerical integrals, the mirror, and the dielectric against the Fresnel
// equations computed independently in double. Statistical bounds are Šidák-corrected z-tests at a
// family significance level (tests/stats.h); deterministic checks use float-rounding bounds.
#include <doctest/doctest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/math/rng.h"
#include "core/material/material.h"
#include "stats.h"

using namespace pt;

namespace {
// Probability that one check fails although the BSDF is right.
constexpr double kFamilyAlpha = 1e-3;
}  // namespace

namespace {

constexpr double kPiD = 3.141592653589793;

Vec3f direction_at(double theta, double phi, bool below = false) {
  return Vec3f(static_cast<float>(std::sin(theta) * std::cos(phi)), static_cast<float>(std::sin(theta) * std::sin(phi)),
               static_cast<float>((below ? -1 : 1) * std::cos(theta)));
}

struct Moments {
  double albedo[3] = {0, 0, 0};  // integral of f cos over the hemisphere, per channel
  double pdf_mass = 0;           // integral of pdf over the hemisphere
};

// Over the upper hemisphere in (theta, phi): composite 4-point Gauss-Legendre in theta (panels
// with the pole and the horizon on their edges, so the integrands, smooth inside, have no kink or
// jump inside a panel; a midpoint rule would carry an O(h^2) error from the pole, where the
// integrand sin(theta) g grows linearly) and the midpoint rule in phi, which is spectrally
// accurate for a periodic integrand. In double except for the BSDF itself. The narrowest lobe
// tested (n = 1000, angular width ~ 1/sqrt(n) = 0.03 rad) spans ~ 5 panels at 256 panels.
Moments integrate_hemisphere(const Bsdf& b, const Vec3f& wo, int panels) {
  static const double kNode[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563, 0.8611363115940526};
  static const double kWeight[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461, 0.3478548451374538};
  const int n_phi = 4 * panels;
  const double h = 0.5 * kPiD / panels, dp = 2 * kPiD / n_phi;
  Moments m;
  for (int i = 0; i < panels; ++i) {
    for (int g = 0; g < 4; ++g) {
      double theta = (i + 0.5 + 0.5 * kNode[g]) * h;
      double w = std::sin(theta) * 0.5 * h * kWeight[g] * dp;
      double row[3] = {0, 0, 0}, row_pdf = 0;
      for (int j = 0; j < n_phi; ++j) {
        Vec3f wi = direction_at(theta, (j + 0.5) * dp);
        Spectrum f = b.eval(wo, wi);
        for (int c = 0; c < 3; ++c) row[c] += double(f[c]) * wi.z;
        row_pdf += b.pdf(wo, wi);
      }
      for (int c = 0; c < 3; ++c) m.albedo[c] += row[c] * w;
      m.pdf_mass += row_pdf * w;
    }
  }
  return m;
}

// Numerical-integration error allowed: the quadrature must reproduce the closed forms at normal
// incidence (albedo kd + ks, pdf mass 1) to this, and doubling the resolution must change nothing
// beyond it elsewhere. At 256 panels the observed error is ~1e-6 at worst (n = 1000, 80 degrees),
// ~1e-7 elsewhere (the BSDF is evaluated in float); an energy leak of 1e-5 would still be caught.
constexpr double kQuadTol = 1e-5;
constexpr int kQuadPanels = 256;
// A float "unit" vector is unit only to an ulp or so, and the lobe raises the mirror cosine to the
// n-th power: away from normal incidence (where wo = +z exactly) the lobe's integral, as the BSDF
// computes it in float, is off by up to ~n ulps (observed 1.7e-5 at n = 1000). A wrong
// normalisation ((n+1) for (n+2): 1e-3 at n = 1000) is still far outside.
double float_lobe_tol(float n) { return 4.0 * (n + 1) * 0x1p-24; }

// Unpolarised Fresnel reflectance in double, from the Fresnel equations for s and p polarisation
// (Born & Wolf 1.5.2; Hecht, Optics, 4.6.2): light from a medium of index n1 toward n2.
double fresnel_reference(double cos_i, double n1, double n2) {
  double sin_i = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
  double sin_t = n1 / n2 * sin_i;  // Snell
  if (sin_t >= 1.0) return 1.0;    // total internal reflection
  double cos_t = std::sqrt(1.0 - sin_t * sin_t);
  double rs = (n1 * cos_i - n2 * cos_t) / (n1 * cos_i + n2 * cos_t);
  double rp = (n2 * cos_i - n1 * cos_t) / (n2 * cos_i + n1 * cos_t);
  return 0.5 * (rs * rs + rp * rp);
}

// The model's name and, for the Phong lobe, its exponent (1 for the others: the tolerances' scale).
std::string model_of(const Bsdf& b) { return MaterialModels::kNames[b.model().index()]; }
float exponent_of(const Bsdf& b) {
  const auto* g = std::get_if<GlossyBsdf>(&b.model());
  return g ? g->exponent : 1.0f;
}

const double kAnglesDeg[] = {0.0, 30.0, 60.0, 80.0, 88.0};

}  // namespace

TEST_CASE("BSDF reciprocity: f(wo, wi) = f(wi, wo) for the non-delta lobes; delta lobes evaluate to 0") {
  Pcg32 rng(17, 3);
  auto random_upper = [&]() {
    double z = rng.next_double(), phi = 2 * kPiD * rng.next_double();
    return direction_at(std::acos(z), phi);
  };
  std::vector<std::pair<std::string, Bsdf>> lobes = {
      {"diffuse", Bsdf(DiffuseBsdf{Spectrum(0.7f, 0.5f, 0.3f)})}};
  for (float n : {1.0f, 10.0f, 100.0f, 1000.0f}) {
    lobes.push_back({"glossy n " + std::to_string(int(n)),
                     Bsdf(GlossyBsdf{Spectrum(0.3f, 0.2f, 0.1f), Spectrum(0.6f, 0.7f, 0.8f), n})});
  }
  for (const auto& [name, b] : lobes) {
    CAPTURE(name);
    int mismatches = 0, nonzero = 0;
    double worst = 0;
    for (int i = 0; i < 20000; ++i) {
      Vec3f wo = random_upper(), wi = random_upper();
      // Half of the pairs near the mirror configuration, where the glossy lobe is large.
      if (i % 2) {
        Vec3f r = reflect(wo, {0, 0, 1});
        wi = normalize(r + (random_upper() - Vec3f(0, 0, 0.5f)) * 0.05f);
        if (wi.z <= 0) continue;
      }
      Spectrum a = b.eval(wo, wi), c = b.eval(wi, wo);
      for (int k = 0; k < 3; ++k) {
        // The mirror cosine is computed from wo in one order and wi in the other, a few float ulps
        // apart; cos^n multiplies that relative error by n.
        double tol = 8 * 6e-8 * (exponent_of(b) + 1) * std::max(a[k], c[k]) + 1e-30;
        double err = std::abs(double(a[k]) - c[k]);
        worst = std::max(worst, err / std::max(1e-30, double(std::max(a[k], c[k]))));
        mismatches += err > tol;
        nonzero += a[k] > 0;
      }
    }
    INFO("worst relative difference " << worst);
    CHECK(mismatches == 0);
    CHECK(nonzero > 30000);
  }
  for (const Bsdf& b : {Bsdf(MirrorBsdf{Spectrum(1.0f)}), Bsdf(DielectricBsdf{1.5f})}) {
    std::string name = model_of(b);
    CAPTURE(name);
    int nonzero = 0;
    for (int i = 0; i < 1000; ++i) {
      Vec3f wo = random_upper(), wi = random_upper();
      nonzero += !is_black(b.eval(wo, wi)) || b.pdf(wo, wi) != 0 || !is_black(b.eval(wo, reflect(wo, {0, 0, 1})));
    }
    CHECK(nonzero == 0);
  }
}

TEST_CASE("BSDF energy: directional albedo by numerical integration is <= 1, and exact at normal incidence") {
  struct Case {
    std::string name;
    Bsdf b;
    Spectrum normal_albedo;  // closed form at normal incidence: kd + ks
  };
  std::vector<Case> cases = {
      {"diffuse", Bsdf(DiffuseBsdf{Spectrum(1.0f, 0.6f, 0.2f)}), {1.0f, 0.6f, 0.2f}}};
  // kd + ks = 1 in some channel: the most the loaders allow, where a leak would show.
  for (float n : {1.0f, 10.0f, 100.0f, 1000.0f}) {
    cases.push_back({"glossy", Bsdf(GlossyBsdf{Spectrum(0.2f, 0.5f, 0.0f), Spectrum(0.8f, 0.3f, 1.0f), n}),
                     {1.0f, 0.8f, 1.0f}});
  }
  for (const Case& k : cases) {
    for (double deg : kAnglesDeg) {
      CAPTURE(k.name);
      CAPTURE(exponent_of(k.b));
      CAPTURE(deg);
      Vec3f wo = direction_at(deg * kPiD / 180.0, 0.4);
      Moments m = integrate_hemisphere(k.b, wo, kQuadPanels);
      for (int c = 0; c < 3; ++c) {
        CAPTURE(c);
        CAPTURE(m.albedo[c]);
        const double tol = kQuadTol + float_lobe_tol(exponent_of(k.b));
        CHECK(m.albedo[c] <= 1.0 + tol);
        CHECK(m.albedo[c] <= k.normal_albedo[c] + tol);  // largest at normal incidence
        CHECK(m.albedo[c] >= 0.0);
        if (deg == 0.0) CHECK(std::abs(m.albedo[c] - k.normal_albedo[c]) <= kQuadTol);
        if (model_of(k.b) == "diffuse") CHECK(std::abs(m.albedo[c] - k.normal_albedo[c]) <= kQuadTol);
      }
      CAPTURE(m.pdf_mass);
      CHECK(m.pdf_mass <= 1.0 + kQuadTol + float_lobe_tol(exponent_of(k.b)));
      if (deg == 0.0 || model_of(k.b) == "diffuse") CHECK(std::abs(m.pdf_mass - 1.0) <= kQuadTol);
      if (deg == 80.0) {
        // The quadrature error bound holds where there is no closed form: halving the cells
        // changes nothing beyond it.
        Moments fine = integrate_hemisphere(k.b, wo, 2 * kQuadPanels);
        for (int c = 0; c < 3; ++c) CHECK(std::abs(fine.albedo[c] - m.albedo[c]) <= kQuadTol);
        CHECK(std::abs(fine.pdf_mass - m.pdf_mass) <= kQuadTol);
      }
    }
  }
}

TEST_CASE("BSDF sampling: weight = f cos / pdf, and E[weight] and P(sample) match the numerical integrals") {
  // Samples that sample() refuses (a glossy direction below the horizon) count as weight 0; the
  // refused fraction must be the pdf's mass below the horizon.
  const int kSamples = 400000;
  int checks = 0;
  std::vector<Bsdf> lobes = {Bsdf(DiffuseBsdf{Spectrum(0.9f, 0.5f, 0.1f)})};
  for (float n : {1.0f, 10.0f, 100.0f, 1000.0f}) {
    lobes.push_back(Bsdf(GlossyBsdf{Spectrum(0.3f, 0.1f, 0.0f), Spectrum(0.6f, 0.8f, 0.9f), n}));
  }
  const int kTests = static_cast<int>(lobes.size()) * 5 * 4;  // lobes x angles x (3 channels + P)
  const double z = stats::z_bound(stats::sidak(kFamilyAlpha, kTests));
  Pcg32 rng(23, 9);
  for (const Bsdf& b : lobes) {
    for (double deg : kAnglesDeg) {
      std::string type = model_of(b);
      CAPTURE(type);
      CAPTURE(exponent_of(b));
      CAPTURE(deg);
      Vec3f wo = direction_at(deg * kPiD / 180.0, 1.1);
      Moments m = integrate_hemisphere(b, wo, kQuadPanels);
      stats::MeanVar weight[3], accepted;
      int inconsistent = 0;
      for (int i = 0; i < kSamples; ++i) {
        Bsdf::Sample s;
        float u_lobe = rng.next_float();
        Vec2f u{rng.next_float(), rng.next_float()};
        bool ok = b.sample(wo, u_lobe, u, s);
        accepted.add(ok ? 1.0 : 0.0);
        for (int c = 0; c < 3; ++c) weight[c].add(ok ? double(s.weight[c]) : 0.0);
        if (!ok) continue;
        // The sample's own pdf and weight must be what pdf() and eval() say.
        float pdf = b.pdf(wo, s.wi);
        Spectrum expect = b.eval(wo, s.wi) * (s.wi.z / pdf);
        bool same = !s.specular && s.wi.z > 0 && std::abs(s.pdf - pdf) <= 1e-5f * pdf &&
                    std::abs(length(s.wi) - 1.0f) < 1e-5f;
        for (int c = 0; c < 3; ++c) same = same && std::abs(s.weight[c] - expect[c]) <= 1e-5f * expect[c] + 1e-12f;
        inconsistent += !same;
      }
      CHECK(inconsistent == 0);
      for (int c = 0; c < 3; ++c) {
        double se = std::sqrt(weight[c].variance_of_mean());
        INFO("channel " << c << ": E[weight] " << weight[c].mean() << " +- " << se << ", integral of f cos "
                        << m.albedo[c]);
        CHECK(std::abs(weight[c].mean() - m.albedo[c]) <= z * se + kQuadTol + float_lobe_tol(exponent_of(b)));
        ++checks;
      }
      double se = std::sqrt(accepted.variance_of_mean());
      INFO("accepted fraction " << accepted.mean() << " +- " << se << ", pdf mass " << m.pdf_mass);
      CHECK(std::abs(accepted.mean() - m.pdf_mass) <= z * se + kQuadTol + float_lobe_tol(exponent_of(b)));
      ++checks;
    }
  }
  CHECK(checks <= kTests);
}

TEST_CASE("mirror: exact reflected direction, weight ks, delta pdf; nothing from below") {
  const Spectrum ks{0.9f, 0.7f, 0.5f};
  Bsdf b = Bsdf(MirrorBsdf{ks});
  Pcg32 rng(5, 1);
  for (int i = 0; i < 1000; ++i) {
    Vec3f wo = normalize(direction_at(std::acos(rng.next_double()), 2 * kPiD * rng.next_double()));
    Bsdf::Sample s;
    REQUIRE(b.sample(wo, rng.next_float(), {rng.next_float(), rng.next_float()}, s));
    CHECK(s.wi.x == -wo.x);
    CHECK(s.wi.y == -wo.y);
    CHECK(s.wi.z == wo.z);
    for (int c = 0; c < 3; ++c) CHECK(s.weight[c] == ks[c]);
    CHECK(s.specular);
    CHECK(s.pdf == 0.0f);
    Bsdf::Sample below;
    CHECK_FALSE(b.sample(Vec3f(wo.x, wo.y, -wo.z), 0.5f, {0.5f, 0.5f}, below));
  }
}

TEST_CASE("dielectric: reflection probability and weights follow the Fresnel equations computed in double") {
  // The sampler reflects when u_lobe < F. Over a midpoint grid of K values of u_lobe the reflected
  // fraction is F to within 1/K, so the check reads off F exactly as the sampler uses it. The
  // reflected energy (fraction x weight) must be F, the transmitted energy with the radiance scale
  // removed 1 - F.
  const int K = 1 << 16;
  auto run = [&](float ior, double theta_deg, bool inside) {
    Bsdf b = Bsdf(DielectricBsdf{ior});
    double theta = theta_deg * kPiD / 180.0;
    Vec3f wo = direction_at(theta, 0.7, inside);
    double cos_i = std::abs(double(wo.z));
    double n1 = inside ? ior : 1.0, n2 = inside ? 1.0 : ior;
    double F = fresnel_reference(cos_i, n1, n2);
    double eta = n2 / n1;
    CAPTURE(ior);
    CAPTURE(theta_deg);
    CAPTURE(inside);
    CAPTURE(F);
    // The library's own Fresnel function (eta = eta_t / eta_i) against the double reference. Float
    // rounding near the critical angle is amplified by 1/cos_t: bound it at ~1e-5.
    CHECK(std::abs(fresnel_dielectric(float(cos_i), float(eta)) - F) <= 1e-5);
    int reflected = 0, bad_direction = 0, bad_weight = 0, not_delta = 0;
    double energy_r = 0, energy_t = 0;
    double sin_i = std::sqrt(std::max(0.0, 1.0 - cos_i * cos_i));
    for (int k = 0; k < K; ++k) {
      Bsdf::Sample s;
      float u_lobe = (k + 0.5f) / K;
      REQUIRE(b.sample(wo, u_lobe, {0.3f, 0.6f}, s));
      not_delta += !s.specular || s.pdf != 0.0f;
      bool refl = s.wi.z * wo.z > 0;
      if (refl) {
        ++reflected;
        energy_r += s.weight.x;
        bad_direction += !(s.wi.x == -wo.x && s.wi.y == -wo.y && s.wi.z == wo.z);
        bad_weight += !(s.weight.x == 1.0f && s.weight.y == 1.0f && s.weight.z == 1.0f);
      } else {
        energy_t += s.weight.x * eta * eta;
        // Snell's law, opposite side, in the plane of incidence on the far side of the normal.
        double sin_t = std::sqrt(double(s.wi.x) * s.wi.x + double(s.wi.y) * s.wi.y);
        bool ok = std::abs(length(s.wi) - 1.0f) < 1e-5f && std::abs(eta * sin_t - sin_i) < 1e-5 &&
                  std::abs(double(s.wi.x) * wo.y - double(s.wi.y) * wo.x) < 1e-5 &&
                  double(s.wi.x) * wo.x + double(s.wi.y) * wo.y <= 0;
        bad_direction += !ok;
        double w = 1.0 / (eta * eta);  // radiance compressed by (eta_i / eta_t)^2 (PBRT 3rd ed. 8.2.3)
        bad_weight += !(std::abs(s.weight.x - w) <= 1e-6 * w && s.weight.x == s.weight.y && s.weight.y == s.weight.z);
      }
    }
    CHECK(not_delta == 0);
    CHECK(bad_direction == 0);
    CHECK(bad_weight == 0);
    CHECK(std::abs(double(reflected) / K - F) <= 1.0 / K + 1e-5);
    CHECK(std::abs(energy_r / K - F) <= 1.0 / K + 1e-5);
    CHECK(std::abs(energy_t / K - (1 - F)) <= 1.0 / K + 1e-5);
    return F;
  };
  for (float ior : {1.5f, 1.33f, 2.4f}) {
    double n = ior;
    double normal = (n - 1) * (n - 1) / ((n + 1) * (n + 1));
    CAPTURE(ior);
    // Normal incidence, from either side: ((n - 1) / (n + 1))^2.
    CHECK(std::abs(run(ior, 0.0, false) - normal) < 1e-12);
    CHECK(std::abs(run(ior, 0.0, true) - normal) < 1e-12);
    for (double deg : {15.0, 30.0, 45.0, 60.0, 75.0, 85.0, 89.0}) run(ior, deg, false);
    double critical = std::asin(1.0 / n) * 180.0 / kPiD;
    for (double frac : {0.3, 0.6, 0.9}) run(ior, frac * critical, true);
    // Beyond the critical angle from inside: total internal reflection, every sample reflects.
    for (double deg : {critical + 1.0, 0.5 * (critical + 90.0), 89.0}) CHECK(run(ior, deg, true) == 1.0);
  }
  // Brewster's angle: the p-polarised part vanishes, so F = rs^2 / 2 (an independent check of the
  // reference itself).
  double n = 1.5, tb = std::atan(n);
  double cos_t = std::cos(kPiD / 2 - tb), rs = (std::cos(tb) - n * cos_t) / (std::cos(tb) + n * cos_t);
  CHECK(fresnel_reference(std::cos(tb), 1.0, n) == doctest::Approx(0.5 * rs * rs).epsilon(1e-12));
}

// ================================================================================================
// 3. MIS: three direct-lighting strategies, one mean
// ================================================================================================

