// Chi-square tests of the warps, the discrete and piecewise-constant distributions and the BSDFs'
// sampling against their own pdfs (the harness is chi2_test.h); the environment map's are in
// test_unit_chi2_environment.cpp, the lights' in test_unit_chi2_lights.cpp.
#include <doctest/doctest.h>

#include "chi2_test.h"
#include "core/material/material.h"
#include "core/math/distribution.h"
#include "core/math/sampling.h"

using namespace pt;
using namespace pt::test;

namespace {

Chi2Family g_family(31);
void expect_accepted(const stats::Chi2Result& r, const std::string& what) { g_family.expect_accepted(r, what); }

}  // namespace

TEST_CASE("incomplete gamma matches closed forms") {
  // Chi-square with 2 dof: survival exp(-x/2); with 1 dof: erfc(sqrt(x/2)); with 4 dof:
  // exp(-x/2)(1 + x/2).
  for (double x : {0.01, 0.5, 1.0, 2.0, 3.5, 10.0, 40.0}) {
    CHECK(stats::chi2_survival(x, 2) == doctest::Approx(std::exp(-x / 2)).epsilon(1e-10));
    CHECK(stats::chi2_survival(x, 1) == doctest::Approx(std::erfc(std::sqrt(x / 2))).epsilon(1e-9));
    CHECK(stats::chi2_survival(x, 4) == doctest::Approx(std::exp(-x / 2) * (1 + x / 2)).epsilon(1e-10));
  }
  // Large dof: the statistic's mean is dof, its median just below.
  CHECK(stats::chi2_survival(1000, 1000) == doctest::Approx(0.4941).epsilon(1e-3));
}

TEST_CASE("chi-square rejects a wrong pdf") {
  // Cosine-weighted samples against the uniform hemisphere pdf, and the Phong lobe against the pdf
  // of a lobe one exponent sharper: both must be rejected, or the tests above prove nothing.
  auto cosine = [](Pcg32& rng, Vec3f& d) {
    d = square_to_cosine_hemisphere(next2(rng));
    return true;
  };
  auto r = chi2_directions(cosine, [](const Vec3f& d) { return d.z > 0 ? uniform_hemisphere_pdf() : 0.0; });
  INFO(r.message);
  CHECK(r.p_value < 1e-12);
  auto lobe = [](Pcg32& rng, Vec3f& d) {
    d = square_to_phong_lobe(next2(rng), 20.0f);
    return true;
  };
  r = chi2_directions(lobe, [](const Vec3f& d) { return phong_lobe_pdf(d.z, 21.0f); });
  INFO(r.message);
  CHECK(r.p_value < 1e-12);
}

TEST_CASE("warps match their pdfs") {
  expect_accepted(chi2_directions(
                      [](Pcg32& rng, Vec3f& d) {
                        d = square_to_cosine_hemisphere(next2(rng));
                        return true;
                      },
                      [](const Vec3f& d) { return cosine_hemisphere_pdf(d.z); }),
                  "cosine hemisphere");
  expect_accepted(chi2_directions(
                      [](Pcg32& rng, Vec3f& d) {
                        d = square_to_uniform_sphere(next2(rng));
                        return true;
                      },
                      [](const Vec3f&) { return uniform_sphere_pdf(); }),
                  "uniform sphere");
  expect_accepted(chi2_directions(
                      [](Pcg32& rng, Vec3f& d) {
                        d = square_to_uniform_hemisphere(next2(rng));
                        return true;
                      },
                      [](const Vec3f& d) { return d.z > 0 ? uniform_hemisphere_pdf() : 0.0f; }),
                  "uniform hemisphere");
  for (float cos_max : {-0.3f, 0.4f, 0.85f}) {
    expect_accepted(chi2_directions(
                        [&](Pcg32& rng, Vec3f& d) {
                          d = square_to_uniform_cone(next2(rng), 1.0f - cos_max);
                          return true;
                        },
                        [&](const Vec3f& d) { return d.z >= cos_max ? uniform_cone_pdf(1.0f - cos_max) : 0.0f; }),
                    "uniform cone, cos_max " + std::to_string(cos_max));
  }
  for (float n : {0.0f, 3.0f, 40.0f}) {
    expect_accepted(chi2_directions(
                        [&](Pcg32& rng, Vec3f& d) {
                          d = square_to_phong_lobe(next2(rng), n);
                          return true;
                        },
                        [&](const Vec3f& d) { return phong_lobe_pdf(d.z, n); }),
                    "Phong lobe, n " + std::to_string(n));
  }
  // Uniform points on a triangle: barycentrics placed on a triangle whose edges follow no grid line.
  const Vec2f a{0.05f, 0.1f}, b{0.93f, 0.2f}, c{0.3f, 0.97f};
  const double area = 0.5 * std::abs((b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y));
  auto inside = [&](double x, double y) {
    auto edge = [&](Vec2f p, Vec2f q) { return (q.x - p.x) * (y - p.y) - (q.y - p.y) * (x - p.x); };
    return edge(a, b) >= 0 && edge(b, c) >= 0 && edge(c, a) >= 0;
  };
  expect_accepted(run_chi2(
                      20, 20, 200000,
                      [&](Pcg32& rng, double& x, double& y) {
                        Vec2f w = square_to_triangle(next2(rng));
                        double w0 = 1.0 - w.x - w.y;
                        x = w0 * a.x + w.x * b.x + w.y * c.x;
                        y = w0 * a.y + w.x * b.y + w.y * c.y;
                        return true;
                      },
                      [&](double x, double y) { return inside(x, y) ? 1.0 / area : 0.0; }),
                  "uniform triangle");
}

TEST_CASE("Distribution1D and Distribution2D sample what they claim") {
  const std::vector<float> w = {1.0f, 0.0f, 3.0f, 0.5f, 2.0f, 0.0f, 0.0f, 4.0f, 0.25f, 1.0f};
  double sum = 0;
  for (float v : w) sum += v;
  Distribution1D d1(w);
  // The pdf follows from the weights, not from the class: weight / mean weight.
  for (size_t i = 0; i < w.size(); ++i) {
    CHECK(d1.discrete_pdf(i) == doctest::Approx(w[i] / sum).epsilon(1e-6));
    CHECK(d1.continuous_pdf(i) == doctest::Approx(w[i] * w.size() / sum).epsilon(1e-6));
  }
  expect_accepted(run_chi2(
                      static_cast<int>(w.size()) * 4, 1, 200000,
                      [&](Pcg32& rng, double& x, double& y) {
                        float pdf;
                        x = d1.sample_continuous(rng.next_float(), &pdf);
                        y = 0.5;
                        return pdf > 0;
                      },
                      [&](double x, double) { return w[static_cast<size_t>(x * w.size())] * w.size() / sum; }),
                  "Distribution1D continuous");
  expect_accepted(run_chi2(
                      static_cast<int>(w.size()), 1, 200000,
                      [&](Pcg32& rng, double& x, double& y) {
                        x = (d1.sample_discrete(rng.next_float()) + 0.5) / w.size();
                        y = 0.5;
                        return true;
                      },
                      [&](double x, double) { return w[static_cast<size_t>(x * w.size())] * w.size() / sum; }),
                  "Distribution1D discrete");

  // 2D: 12 x 8 weights with an all-zero row and scattered zeros.
  const int W = 12, H = 8;
  std::vector<float> w2(W * H);
  Pcg32 fill(7, 3);
  double sum2 = 0;
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      float v = (y == 5 || (x + y) % 5 == 0) ? 0.0f : fill.next_float() * (1 + y);
      w2[y * W + x] = v;
      sum2 += v;
    }
  }
  Distribution2D d2(w2, W, H);
  auto truth = [&](double x, double y) {
    return w2[static_cast<size_t>(y * H) * W + static_cast<size_t>(x * W)] * (W * H) / sum2;
  };
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      Vec2f c{(x + 0.5f) / W, (y + 0.5f) / H};
      CHECK(d2.pdf(c) == doctest::Approx(truth(c.x, c.y)).epsilon(1e-5));
    }
  }
  expect_accepted(run_chi2(
                      W * 2, H * 2, 300000,
                      [&](Pcg32& rng, double& x, double& y) {
                        float pdf;
                        Vec2f p = d2.sample(next2(rng), &pdf);
                        CHECK(pdf == doctest::Approx(truth(p.x, p.y)).epsilon(1e-4));
                        x = p.x, y = p.y;
                        return pdf > 0;
                      },
                      truth),
                  "Distribution2D");
}


TEST_CASE("BSDF sampling matches Bsdf::pdf") {
  const float kAngles[] = {0.0f, 50.0f, 80.0f};
  auto wo_at = [](float degrees) {
    float t = degrees * kPi / 180.0f;
    return Vec3f(std::sin(t) * 0.8f, std::sin(t) * 0.6f, std::cos(t));
  };
  auto test = [&](const Bsdf& b, const std::string& name) {
    for (float angle : kAngles) {
      Vec3f wo = wo_at(angle);
      expect_accepted(chi2_directions(
                          [&](Pcg32& rng, Vec3f& d) {
                            Bsdf::Sample s;
                            float u_lobe = rng.next_float();
                            if (!b.sample(wo, u_lobe, next2(rng), s)) return false;
                            d = s.wi;
                            return true;
                          },
                          [&](const Vec3f& wi) { return b.pdf(wo, wi); }, 300000, DirGrid(),
                          b.has(kBsdfGlossy)),
                      name + ", wo at " + std::to_string(angle) + " degrees");
    }
  };
  test(Bsdf(DiffuseBsdf{Spectrum(0.5f, 0.6f, 0.7f)}), "diffuse");
  struct Mix {
    float kd, ks, n;
  };
  for (Mix m : {Mix{0.5f, 0.5f, 1.0f}, Mix{0.3f, 0.6f, 12.0f}, Mix{0.1f, 0.9f, 80.0f}, Mix{0.8f, 0.1f, 300.0f},
                Mix{0.0f, 1.0f, 30.0f}}) {
    Bsdf g = GlossyBsdf{Spectrum(m.kd), Spectrum(m.ks), m.n};
    test(g, "glossy kd " + std::to_string(m.kd) + " ks " + std::to_string(m.ks) + " n " + std::to_string(m.n));
  }
}
