// The chi-square goodness-of-fit harness shared by the sampling tests (test_unit_chi2*.cpp), after
// nori's chi2test and pbrt-v4's bsdfs_test: samples are binned on a grid over the unit square
// (directions through an equal-area (cos theta, phi) map, or (theta, phi) for lat-long maps), the pdf
// is integrated numerically over each cell, sparse cells are pooled, and the statistic's p-value is
// compared with a Šidák-corrected significance. Samples a routine refuses (returns false) are a
// cell of their own, expected to hold the pdf's missing mass.
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <string>
#include <vector>

#include "core/math/frame.h"
#include "core/math/rng.h"
#include "core/math/vec.h"
#include "stats.h"

namespace pt::test {

inline constexpr double kTwoPi = 6.283185307179586;
inline constexpr double kPiD = 3.141592653589793;

// The chi-square tests of one test program that are expected to pass: each gets a share of the
// overall significance 0.01, for at most `tests` of them.
class Chi2Family {
 public:
  explicit Chi2Family(int tests) : tests_(tests), significance_(stats::sidak(0.01, tests)) {}
  double significance() const { return significance_; }
  void expect_accepted(const stats::Chi2Result& r, const std::string& what) {
    ++run_;
    REQUIRE(run_ <= tests_);
    INFO(what << ": " << r.message << ", significance " << significance_);
    CHECK(r.p_value > significance_);
  }

 private:
  int tests_, run_ = 0;
  double significance_;
};

// A sampler writes a point of [0,1)^2 and returns false when it refuses to sample; `density` is the
// claimed density on [0,1)^2.
using SampleFn = std::function<bool(Pcg32&, double&, double&)>;
using DensityFn = std::function<double(double, double)>;

// 3 x 3 Gauss-Legendre rule on the rectangle [x0, x0 + w] x [y0, y0 + h].
inline double gauss3(const DensityFn& f, double x0, double y0, double w, double h) {
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
inline double integrate_rect(const DensityFn& f, double x0, double y0, double w, double h, double whole, double tol,
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
inline stats::Chi2Result run_chi2(int nx, int ny, int samples, const SampleFn& sample, const DensityFn& density,
                           bool can_fail = false, uint64_t seed = 1, int base = 4) {
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
  // Each cell starts as base x base rectangles, so small features are seen (a light's corner that
  // falls between the first quadrature nodes of a cell would count as nothing).
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


// Directions around the axis of `frame`, within the cap cos(theta) >= cos_cap, mapped to [0,1)^2 by
// (phi / 2pi, (1 - cos theta) / (1 - cos_cap)): equal area, so the density on the square is
// 2 pi (1 - cos_cap) times the solid-angle pdf. cos_cap = -1 is the whole sphere; a smaller cap
// around a light gives the test the resolution to see the light's shape.
struct DirGrid {
  Frame frame{Vec3f(0, 0, 1)};
  double cos_cap = -1.0;
  int nx = 40, ny = 40;
  int quadrature = 4;  // each cell's first quadrature rectangles per side (run_chi2's base)
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

inline stats::Chi2Result chi2_directions(const DirSampleFn& sample, const DirPdfFn& pdf, int samples = 400000,
                                  const DirGrid& grid = DirGrid(), bool can_fail = false) {
  return run_chi2(
      grid.nx, grid.ny, samples,
      [&](Pcg32& rng, double& x, double& y) {
        Vec3f d;
        return sample(rng, d) && grid.xy(d, x, y);
      },
      [&](double x, double y) { return grid.area() * pdf(grid.dir(x, y)); }, can_fail, 1, grid.quadrature);
}

inline Vec2f next2(Pcg32& rng) {
  float a = rng.next_float();
  return {a, rng.next_float()};
}

}  // namespace pt::test
