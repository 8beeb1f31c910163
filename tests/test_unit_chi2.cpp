// Chi-square goodness-of-fit tests of every sampling routine against its own pdf (after nori's
// chi2test and pbrt-v4's bsdfs_test): samples are binned on a grid over the unit square (directions
// through an equal-area (cos theta, phi) map, or (theta, phi) for lat-long maps), the pdf is
// integrated numerically over each cell, sparse cells are pooled, and the statistic's p-value is
// compared with a Šidák-corrected significance. Samples a routine refuses (returns false) are a
// cell of their own, expected to hold the pdf's missing mass.
#include <doctest/doctest.h>

#include <cstdio>
#include <cstdlib>
#include <functional>

#include "core/accel/accel.h"
#include "core/math/distribution.h"
#include "core/math/frame.h"
#include "core/math/rng.h"
#include "core/math/sampling.h"
#include "core/scene/environment.h"
#include "core/material/material.h"
#include "core/scene/scene.h"
#include "scene_helpers.h"
#include "stats.h"

using namespace pt;

namespace {

// Upper bound on the chi-square tests in this file that are expected to pass; each gets a share of
// the overall significance 0.01.
constexpr int kChi2Tests = 60;
const double kSignificance = stats::sidak(0.01, kChi2Tests);
int g_tests_run = 0;

constexpr double kTwoPi = 6.283185307179586;
constexpr double kPiD = 3.141592653589793;

// A sampler writes a point of [0,1)^2 and returns false when it refuses to sample; `density` is the
// claimed density on [0,1)^2.
using SampleFn = std::function<bool(Pcg32&, double&, double&)>;
using DensityFn = std::function<double(double, double)>;

// 3 x 3 Gauss-Legendre rule on the rectangle [x0, x0 + w] x [y0, y0 + h].
double gauss3(const DensityFn& f, double x0, double y0, double w, double h) {
  static const double kNode[3] = {-0.7745966692414834, 0.0, 0.7745966692414834};
  static const double kWeight[3] = {5.0 / 9.0, 8.0 / 9.0, 5.0 / 9.0};
  double sum = 0;
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 3; ++i) {
      sum += kWeight[i] * kWeight[j] * f(x0 + 0.5 * w * (1 + kNode[i]), y0 + 0.5 * h * (1 + kNode[j]));
    }
  }
  return 0.25 * w * h * sum;
}

// Adaptive quadtree integration: a rectangle is split while its four children disagree with it, so
// the work concentrates along the pdf's edges (a light's silhouette, a cone's rim) and peaks.
double integrate_rect(const DensityFn& f, double x0, double y0, double w, double h, double whole, double tol,
                      int depth) {
  double hw = 0.5 * w, hh = 0.5 * h;
  double c[4] = {gauss3(f, x0, y0, hw, hh), gauss3(f, x0 + hw, y0, hw, hh), gauss3(f, x0, y0 + hh, hw, hh),
                 gauss3(f, x0 + hw, y0 + hh, hw, hh)};
  double sum = c[0] + c[1] + c[2] + c[3];
  if (depth == 0 || std::abs(sum - whole) <= tol) return sum;
  return integrate_rect(f, x0, y0, hw, hh, c[0], 0.25 * tol, depth - 1) +
         integrate_rect(f, x0 + hw, y0, hw, hh, c[1], 0.25 * tol, depth - 1) +
         integrate_rect(f, x0, y0 + hh, hw, hh, c[2], 0.25 * tol, depth - 1) +
         integrate_rect(f, x0 + hw, y0 + hh, hw, hh, c[3], 0.25 * tol, depth - 1);
}

// Bins `samples` draws on an nx x ny grid and compares them with the integrated density. When
// `can_fail` the refused samples form one more cell, expected to hold the density's missing mass;
// otherwise a single refusal fails the test.
stats::Chi2Result run_chi2(int nx, int ny, int samples, const SampleFn& sample, const DensityFn& density,
                           bool can_fail = false, uint64_t seed = 1) {
  std::vector<double> observed(static_cast<size_t>(nx) * ny + 1, 0.0), expected(observed.size(), 0.0);
  Pcg32 rng(seed, 0x51ed2701);
  for (int i = 0; i < samples; ++i) {
    double x, y;
    if (!sample(rng, x, y)) {
      observed.back() += 1;
      continue;
    }
    int cx = std::clamp(static_cast<int>(x * nx), 0, nx - 1), cy = std::clamp(static_cast<int>(y * ny), 0, ny - 1);
    observed[static_cast<size_t>(cy) * nx + cx] += 1;
  }
  double total = 0;
  const int base = 4;  // each cell starts as base x base rectangles, so small features are seen
  const double w = 1.0 / (static_cast<double>(nx) * base), h = 1.0 / (static_cast<double>(ny) * base);
  for (int cy = 0; cy < ny; ++cy) {
    for (int cx = 0; cx < nx; ++cx) {
      double integral = 0;
      for (int j = 0; j < base; ++j) {
        for (int i = 0; i < base; ++i) {
          double x0 = (cx * base + i) * w, y0 = (cy * base + j) * h;
          integral += integrate_rect(density, x0, y0, w, h, gauss3(density, x0, y0, w, h), 1e-5 * w * h, 4);
        }
      }
      expected[static_cast<size_t>(cy) * nx + cx] = integral * samples;
      total += integral;
    }
  }
  if (can_fail) {
    expected.back() = std::max(0.0, 1.0 - total) * samples;
  } else {
    INFO(observed.back() << " samples refused or outside the grid by a routine that must not refuse");
    CHECK(observed.back() == 0);
    INFO("the density integrates to " << total);
    CHECK(total == doctest::Approx(1.0).epsilon(1e-3));
    observed.pop_back();
    expected.pop_back();
  }
  if (std::getenv("PT_CHI2_DEBUG")) {
    for (size_t i = 0; i < observed.size(); ++i) {
      double e = expected[i], o = observed[i];
      if ((o - e) * (o - e) / std::max(e, 1e-9) > 9) {
        std::printf("cell %zu (%d,%d): observed %g expected %g\n", i, static_cast<int>(i % nx), static_cast<int>(i / nx), o, e);
      }
    }
  }
  return stats::chi2_test(observed, expected);
}

void expect_accepted(const stats::Chi2Result& r, const std::string& what) {
  ++g_tests_run;
  REQUIRE(g_tests_run <= kChi2Tests);
  INFO(what << ": " << r.message << ", significance " << kSignificance);
  CHECK(r.p_value > kSignificance);
}

// Directions around the axis of `frame`, within the cap cos(theta) >= cos_cap, mapped to [0,1)^2 by
// (phi / 2pi, (1 - cos theta) / (1 - cos_cap)): equal area, so the density on the square is
// 2 pi (1 - cos_cap) times the solid-angle pdf. cos_cap = -1 is the whole sphere; a smaller cap
// around a light gives the test the resolution to see the light's shape.
struct DirGrid {
  Frame frame{Vec3f(0, 0, 1)};
  double cos_cap = -1.0;
  int nx = 40, ny = 40;
  double area() const { return kTwoPi * (1.0 - cos_cap); }
  Vec3f dir(double x, double y) const {
    double z = 1.0 - y * (1.0 - cos_cap), r = std::sqrt(std::max(0.0, 1.0 - z * z)), phi = kTwoPi * x;
    return frame.to_world(Vec3f(static_cast<float>(r * std::cos(phi)), static_cast<float>(r * std::sin(phi)),
                                static_cast<float>(z)));
  }
  // False when d is outside the cap.
  bool xy(const Vec3f& d, double& x, double& y) const {
    Vec3f l = frame.to_local(d);
    double phi = std::atan2(static_cast<double>(l.y), static_cast<double>(l.x));
    x = phi < 0 ? phi / kTwoPi + 1.0 : phi / kTwoPi;
    y = (1.0 - std::clamp(static_cast<double>(l.z) / length(l), -1.0, 1.0)) / (1.0 - cos_cap);
    return y < 1.0;
  }
};

using DirSampleFn = std::function<bool(Pcg32&, Vec3f&)>;
using DirPdfFn = std::function<double(const Vec3f&)>;

stats::Chi2Result chi2_directions(const DirSampleFn& sample, const DirPdfFn& pdf, int samples = 400000,
                                  const DirGrid& grid = DirGrid(), bool can_fail = false) {
  return run_chi2(
      grid.nx, grid.ny, samples,
      [&](Pcg32& rng, double& x, double& y) {
        Vec3f d;
        return sample(rng, d) && grid.xy(d, x, y);
      },
      [&](double x, double y) { return grid.area() * pdf(grid.dir(x, y)); }, can_fail);
}

Vec2f next2(Pcg32& rng) {
  float a = rng.next_float();
  return {a, rng.next_float()};
}

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

namespace {

// A lat-long map in the Environment's orientation (theta from +y, phi from -z toward +x), mapped to
// [0,1)^2 by (phi / 2pi + 1/2, theta / pi): the density on the square is 2 pi^2 sin(theta) times
// the solid-angle pdf. Written here from the documented convention, not taken from the class.
Vec3f latlong_dir(double x, double y, double& jacobian) {
  double theta = kPiD * y, phi = kTwoPi * (x - 0.5);
  jacobian = 2.0 * kPiD * kPiD * std::sin(theta);
  return {static_cast<float>(std::sin(theta) * std::sin(phi)), static_cast<float>(std::cos(theta)),
          static_cast<float>(-std::sin(theta) * std::cos(phi))};
}
void latlong_xy(const Vec3f& d, double& x, double& y) {
  x = 0.5 + std::atan2(static_cast<double>(d.x), -static_cast<double>(d.z)) / kTwoPi;
  if (x >= 1.0) x -= 1.0;
  y = std::acos(std::clamp(static_cast<double>(d.y), -1.0, 1.0)) / kPiD;
}

// A sky with a gradient, a hot "sun" near the horizon, a coloured patch and a black band.
std::shared_ptr<Texture> synthetic_sky(int w, int h) {
  auto t = std::make_shared<Texture>();
  t->width = w;
  t->height = h;
  t->texels.resize(static_cast<size_t>(w) * h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      float v = (y + 0.5f) / h, u = (x + 0.5f) / w;
      Spectrum c(0.2f + 0.8f * (1 - v));
      float du = u - 0.7f, dv = v - 0.35f;
      if (du * du + dv * dv < 0.004f) c = Spectrum(60.0f, 50.0f, 40.0f);
      if (x >= 10 && x < 16 && y >= 20 && y < 26) c = Spectrum(0.0f, 3.0f, 0.5f);
      if (y == 28 || y == 29) c = Spectrum(0.0f);
      t->texels[static_cast<size_t>(y) * w + x] = c;
    }
  }
  return t;
}

}  // namespace

TEST_CASE("environment map importance sampling matches its pdf") {
  const int w = 64, h = 32;
  auto sky = synthetic_sky(w, h);
  // Rotations by whole texel pairs keep the texel edges on cell edges (the pdf is piecewise constant).
  for (float rotation : {0.0f, 45.0f, -90.0f}) {
    Environment env(sky, 1.0f, rotation);
    // sample() reports pdf(direction), so a direction whose round trip through float lands on the
    // zero side of a texel edge is refused: a set of measure zero, hit a handful of times. Those
    // are drawn again and counted; anything beyond 1 in 10^4 is a real mismatch.
    int edge_refusals = 0;
    expect_accepted(run_chi2(
                        w / 2, h / 2, 400000,
                        [&](Pcg32& rng, double& x, double& y) {
                          float pdf;
                          Vec3f d = env.sample(next2(rng), &pdf);
                          while (!(pdf > 0) && edge_refusals < 1000) {
                            ++edge_refusals;
                            d = env.sample(next2(rng), &pdf);
                          }
                          if (!(pdf > 0)) return false;
                          CHECK(pdf == doctest::Approx(env.pdf(d)).epsilon(2e-3));
                          latlong_xy(d, x, y);
                          return true;
                        },
                        [&](double x, double y) {
                          double jacobian;
                          Vec3f d = latlong_dir(x, y, jacobian);
                          return env.pdf(d) * jacobian;
                        }),
                    "environment map, rotation " + std::to_string(rotation));
    CAPTURE(rotation);
    CHECK(edge_refusals <= 40);
  }
  // A constant environment samples the sphere uniformly.
  Environment constant(Spectrum(1.0f));
  expect_accepted(chi2_directions(
                      [&](Pcg32& rng, Vec3f& d) {
                        float pdf;
                        d = constant.sample(next2(rng), &pdf);
                        return pdf > 0;
                      },
                      [&](const Vec3f& d) { return constant.pdf(d); }),
                  "constant environment");
}

TEST_CASE("environment map orientation follows the documented convention") {
  // One bright texel per axis direction; eval must find it where environment.h says it is.
  auto t = std::make_shared<Texture>();
  t->width = 8, t->height = 4;
  t->texels.assign(32, Spectrum(0.0f));
  t->texels[1 * 8 + 6] = Spectrum(1, 0, 0);
  Environment env(t, 1.0f, 0.0f);
  // Texel (6, 1) spans u in [0.75, 0.875), v in [0.25, 0.5): its centre looks above the horizon,
  // mostly toward +x (u = 0.75 is +x).
  double jac;
  Vec3f d = latlong_dir(6.5 / 8, 1.5 / 4, jac);
  CHECK(d.x > 0.5f);      // toward +x
  CHECK(d.y > 0.0f);      // above the horizon (row 1 of 4 is the upper half)
  CHECK(env.eval(d).x == doctest::Approx(1.0f).epsilon(1e-4));
  CHECK(env.eval(Vec3f(0, 0, -1)).x == doctest::Approx(0.0f));
  // rotation = +90 degrees turns the map right-handedly about +y, like an object's "rotate":
  // what was toward +x is now toward -z.
  Environment turned(t, 1.0f, 90.0f);
  Vec3f rotated{d.z, d.y, -d.x};  // R_y(90) (x, y, z) = (z, y, -x)
  CHECK(turned.eval(rotated).x == doctest::Approx(1.0f).epsilon(1e-4));
  CHECK(turned.eval(d).x == doctest::Approx(0.0f));
}

namespace {

// A scene of emitters only, with an accelerator, to test Scene::sample_light against
// Scene::light_pdf (the pair MIS relies on) from a shading point.
struct LightScene {
  SceneBuilder builder;
  std::unique_ptr<const Scene> scene_;
  std::unique_ptr<Accel> accel;
  Vec3f normal{0.0f};  // the shading point's normal the light sampler is given (zero: none)

  void add_triangle(Vec3f a, Vec3f b, Vec3f c, Spectrum emission) {
    Material m;
    m.emission = emission;
    uint32_t id = test::add_material(builder, m);
    Mesh& mesh = builder.mesh;
    uint32_t base = static_cast<uint32_t>(mesh.positions.size());
    mesh.positions.insert(mesh.positions.end(), {a, b, c});
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    mesh.material.push_back(id);
  }
  void add_sphere(Vec3f c, float r, Spectrum emission) {
    Material m;
    m.emission = emission;
    test::add_sphere(builder, c, r, test::add_material(builder, m));
  }
  void finish() {
    scene_ = std::make_unique<const Scene>(std::move(builder));
    accel = make_accel(scene_->geometry(), AccelOptions{});
  }
  const Scene& scene() const { return *scene_; }
  // Solid-angle density of choosing direction d from p: the light the ray sees, through light_pdf.
  double pdf(const Vec3f& p, const Vec3f& d) const {
    Ray r{p, d, 0.0f, kInf};
    auto hit = accel->intersect(r);
    if (!hit) return 0.0;
    SurfaceInteraction si = scene().interaction(r, *hit);
    if (is_black(scene().emitted(si, -d))) return 0.0;
    return scene().light_pdf(p, normal, si);
  }
  // Also counts samples whose reported pdf differs from light_pdf along the same direction.
  stats::Chi2Result chi2(const Vec3f& p, const DirGrid& grid = DirGrid(), int samples = 400000) const {
    int mismatches = 0, accepted = 0;
    auto r = chi2_directions(
        [&](Pcg32& rng, Vec3f& d) {
          LightSample ls;
          float u_select = rng.next_float();
          if (!scene().sample_light(p, normal, u_select, next2(rng), ls)) return false;
          d = ls.wi;
          ++accepted;
          double expected = pdf(p, d);
          if (!(std::abs(ls.pdf - expected) <= 1e-3 * expected)) {
            if (mismatches++ < 3) MESSAGE("sampled pdf " << ls.pdf << " but light_pdf " << expected);
          }
          return true;
        },
        [&](const Vec3f& d) { return pdf(p, d); }, samples, grid);
    INFO(mismatches << " of " << accepted << " samples disagree with light_pdf");
    CHECK(mismatches <= accepted / 10000);
    return r;
  }
};

// A cap around `axis` that holds every direction within `half_angle` (radians) of it.
DirGrid cap(const Vec3f& axis, double half_angle) {
  DirGrid g;
  g.frame = Frame(normalize(axis));
  g.cos_cap = std::cos(std::min(kPiD, half_angle));
  return g;
}
// The cap around a triangle as seen from p, with a margin.
DirGrid triangle_cap(const Vec3f& p, const Vec3f& a, const Vec3f& b, const Vec3f& c) {
  Vec3f da = normalize(a - p), db = normalize(b - p), dc = normalize(c - p);
  Vec3f axis = normalize(da + db + dc);
  double angle = 0;
  for (Vec3f d : {da, db, dc}) angle = std::max(angle, std::acos(std::clamp<double>(dot(d, axis), -1, 1)));
  return cap(axis, 1.15 * angle);
}

}  // namespace

TEST_CASE("triangle lights: area sampling seen from a point matches light_pdf") {
  const Vec3f a{-1, 2, -1}, b{2, 2, -0.5f}, c{0, 1.5f, 2};
  LightScene one;
  one.add_triangle(a, b, c, Spectrum(1.0f));
  one.finish();
  // Points on the emitting side, none near the triangle's plane: seen edge-on the triangle is a
  // sliver thinner than the quadrature's sample spacing and its integral would be missed.
  for (Vec3f p : {Vec3f(0.1f, 0, 0.2f), Vec3f(-2, 0.5f, 3), Vec3f(3, 0.5f, -2)}) {
    expect_accepted(one.chi2(p, triangle_cap(p, a, b, c)),
                    "one triangle from " + std::to_string(p.x) + " " + std::to_string(p.y) + " " + std::to_string(p.z));
  }
  // The same on the whole sphere of directions.
  expect_accepted(one.chi2({0.1f, 0, 0.2f}), "one triangle, whole sphere");

  // Three lights of different power and shape, none in front of another: the choice by power is
  // part of the density.
  LightScene three;
  three.add_triangle({-1, 2, -1}, {2, 2, -0.5f}, {0, 1.5f, 2}, Spectrum(1.0f));
  three.add_triangle({2, -1, 0}, {2, 0, 1}, {2, 1, 0}, Spectrum(5.0f, 2.0f, 1.0f));  // faces -x, the origin
  three.add_triangle({-2, -1, -1}, {-2, 0.5f, -1.2f}, {-1.5f, -1, 1}, Spectrum(0.3f));
  three.finish();
  expect_accepted(three.chi2({0, 0, 0}), "three triangles");
}

TEST_CASE("triangle lights: area, solid-angle and auto sampling each match light_pdf") {
  const Vec3f a{-1, 2, -1}, b{2, 2, -0.5f}, c{0, 1.5f, 2};
  // Near (a large solid angle, where auto takes it), at a grazing angle, and far (auto: the area).
  const Vec3f points[] = {Vec3f(0.1f, 1.2f, 0.2f), Vec3f(-2, 0.5f, 3), Vec3f(6, -9, 5)};
  for (const char* mode : {"area", "solid-angle", "auto"}) {
    LightScene one;
    one.builder.settings.choices.light_sampling = kLightSamplingNames.parse(mode);
    one.add_triangle(a, b, c, Spectrum(1.0f));
    one.finish();
    for (Vec3f p : points) {
      expect_accepted(one.chi2(p, triangle_cap(p, a, b, c), 200000),
                      std::string(mode) + ", one triangle from " + std::to_string(p.x) + " " + std::to_string(p.y) +
                          " " + std::to_string(p.z));
    }
  }
  // A quad light (two coplanar triangles that share an edge) is one group: near it a member is
  // chosen by its solid angle, far from it by power; seen from beside it, from above its middle
  // and from afar.
  for (const char* mode : {"solid-angle", "auto"}) {
    LightScene quad;
    quad.builder.settings.choices.light_sampling = kLightSamplingNames.parse(mode);
    const Vec3f q0{-1, 1, -1}, q1{1, 1, -1}, q2{1, 1, 1}, q3{-1, 1, 1};  // faces -y
    quad.add_triangle(q0, q1, q2, Spectrum(1.0f));
    quad.add_triangle(q0, q2, q3, Spectrum(1.0f));
    quad.finish();
    REQUIRE(quad.scene().light_set().triangle_groups().size() == 1);
    CHECK(quad.scene().light_set().triangle_groups()[0].count == 2);
    for (Vec3f p : {Vec3f(1.6f, 0.5f, 0.3f), Vec3f(0.1f, 0.4f, -0.2f), Vec3f(3, -6, 2)}) {
      expect_accepted(quad.chi2(p, DirGrid(), 200000), std::string(mode) + ", a quad from " + std::to_string(p.x) + " " +
                                                           std::to_string(p.y) + " " + std::to_string(p.z));
    }
  }
  // Light chosen by power with a near and a far triangle: each decides from the same point.
  LightScene two;
  two.builder.settings.choices.light_sampling = LightSampling::kAuto;
  two.add_triangle({-0.5f, 0.3f, -0.5f}, {0.6f, 0.3f, -0.4f}, {0, 0.3f, 0.7f}, Spectrum(1.0f));  // faces -y, near
  two.add_triangle({4, -1, 0}, {4, 0, 1}, {4, 1, 0}, Spectrum(5.0f, 2.0f, 1.0f));                 // faces -x, far
  two.finish();
  CHECK(two.scene().light_set().triangle_groups().size() == 2);  // not coplanar, not touching
  expect_accepted(two.chi2({0, 0, 0}), "auto, a near and a far triangle");
}

TEST_CASE("sphere lights: cone sampling matches light_pdf") {
  for (float distance : {1.3f, 3.0f, 12.0f}) {
    LightScene s;
    s.add_sphere({distance * 0.6f, distance * 0.8f, 0}, 1.0f, Spectrum(2.0f));
    s.finish();
    // The cap is the sphere's silhouette with a margin.
    Vec3f centre{distance * 0.6f, distance * 0.8f, 0};
    expect_accepted(s.chi2({0, 0, 0}, cap(centre, 1.3 * std::asin(1.0 / distance))),
                    "sphere light at distance " + std::to_string(distance));
  }
  // A sphere and a triangle together.
  LightScene mixed;
  mixed.add_sphere({0, 0, 3}, 0.8f, Spectrum(4.0f));
  mixed.add_triangle({-1, 2, -1}, {2, 2, -0.5f}, {0, 1.5f, 2}, Spectrum(1.0f));
  mixed.finish();
  expect_accepted(mixed.chi2({0, 0, 0}), "sphere and triangle");
}

TEST_CASE("light tree selection: sampled lights match light_pdf, with and without a normal") {
  // Seven triangles (two of them a quad: one group) and two spheres around the origin, of
  // different powers and facing different ways, chosen by the light tree.
  LightScene s;
  s.builder.settings.choices.light_selection = LightSelection::kTree;
  s.add_triangle({-1, 2, -1}, {2, 2, -0.5f}, {0, 1.5f, 2}, Spectrum(1.0f));
  s.add_triangle({2, -1, 0}, {2, 0, 1}, {2, 1, 0}, Spectrum(5.0f, 2.0f, 1.0f));
  s.add_triangle({-2, -1, -1}, {-2, 0.5f, -1.2f}, {-1.5f, -1, 1}, Spectrum(0.3f));
  s.add_triangle({-1, -2, 3}, {1, -2, 3}, {1, 0, 3}, Spectrum(2.0f));
  s.add_triangle({-1, -2, 3}, {1, 0, 3}, {-1, 0, 3}, Spectrum(2.0f));
  s.add_triangle({0.5f, -3, -2}, {1.5f, -3, -2}, {1, -3, -1}, Spectrum(8.0f));
  s.add_triangle({-3, 3, 3}, {-3, 4, 3}, {-3, 3, 4}, Spectrum(20.0f));
  s.add_sphere({0, 0, -4}, 0.7f, Spectrum(3.0f));
  s.add_sphere({4, 3, 1}, 0.4f, Spectrum(10.0f));
  s.finish();
  REQUIRE(s.scene().light_set().selection() == LightSelection::kTree);
  expect_accepted(s.chi2({0, 0, 0}, DirGrid(), 300000), "light tree, no normal");
  s.normal = normalize(Vec3f(0.3f, 1, -0.2f));
  expect_accepted(s.chi2({0, 0, 0}, DirGrid(), 300000), "light tree, with a normal");
  s.normal = Vec3f(0.0f);
  expect_accepted(s.chi2({0.5f, -1.5f, 2.5f}, DirGrid(), 300000), "light tree, beside the quad");
}

TEST_CASE("sphere light pdf is the subtended solid angle, even for small distant spheres") {
  // Every cone sample must hit the sphere and the pdf must be 1 / (2 pi (1 - cos theta_max)),
  // evaluated here in double. Catastrophic cancellation in 1 - cos theta_max in float would sample a
  // cone of the wrong size (or none at all).
  for (double distance : {5.0, 50.0, 300.0, 2000.0}) {
    LightScene s;
    const double radius = 0.5;
    Vec3f centre{0, static_cast<float>(distance), 0};
    s.add_sphere(centre, static_cast<float>(radius), Spectrum(1.0f));
    s.finish();
    double sin2 = radius * radius / (distance * distance);
    double one_minus_cos = sin2 / (1.0 + std::sqrt(1.0 - sin2));
    double expected_pdf = 1.0 / (kTwoPi * one_minus_cos);
    Pcg32 rng(11, 5);
    int hits = 0, n = 2000;
    double max_rel = 0;
    for (int i = 0; i < n; ++i) {
      LightSample ls;
      if (!s.scene().sample_light({0, 0, 0}, Vec3f(0.0f), rng.next_float(), next2(rng), ls)) continue;
      max_rel = std::max(max_rel, std::abs(ls.pdf / expected_pdf - 1.0));
      // Distance from the centre to the sampled ray, in double.
      double dx = ls.wi.x, dy = ls.wi.y, dz = ls.wi.z, len = std::sqrt(dx * dx + dy * dy + dz * dz);
      double t = distance * dy / len;
      double miss2 = distance * distance - t * t;
      if (miss2 <= radius * radius * (1 + 1e-3)) ++hits;
    }
    INFO("distance " << distance << ": " << hits << " of " << n << " hit, max pdf error " << max_rel);
    CHECK(hits == n);
    CHECK(max_rel < 1e-3);
  }
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
