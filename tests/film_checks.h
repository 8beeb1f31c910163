// Rendering a test scene and the statistical agreement of two films (the transport tests' z-tests),
// shared by test_transport_paths.cpp and test_transport_sampling.cpp.
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "renderer/render/film.h"
#include "renderer/render/job.h"
#include "renderer/render/render.h"
#include "scene_helpers.h"
#include "stats.h"

namespace pt::test {

using ScenePtr = std::shared_ptr<const Scene>;

inline RenderResult render_with(const ScenePtr& scene, const std::string& integrator, const IntegratorOptions& io, int spp,
                         uint64_t seed, SamplerKind sampler = SamplerKind::kIndependent) {
  JobOptions o;
  o.integrator = kIntegratorNames.parse(integrator);
  o.spp = spp;
  o.seed = seed;
  o.sampler = sampler;
  RenderControl control;
  control.threads = 2;
  RenderResult r = render(test::make_job(scene, o, io), control);
  REQUIRE(r.nonfinite == 0);
  REQUIRE(r.film.min_count() == static_cast<uint32_t>(spp));
  return r;
}

// Probability that one check (all pixels and channels of one comparison) fails although the
// renderer is right.
constexpr double kFamilyAlpha = 1e-3;
// Bound on an image-wide mean: two-sided p = 6e-5 for a true hypothesis.
constexpr double kMeanSigmas = 4.0;
// Relative rounding allowed where a pixel's samples are (nearly) all equal and the film variance
// is zero: float radiance summed in double, so far below this.
constexpr double kRoundoff = 1e-5;

// Two independent renders of the same scene estimate the same image. The image is cut into
// block x block squares; each square's mean (the average of its pixel means, variance the sum of the
// pixels' variances of the mean / block^4: pixels are independent) is z-tested for equality, at a
// Šidák bound over all squares and channels, and so is the image-wide mean, at kMeanSigmas.
// block = 1 tests every pixel; larger blocks are for estimators whose per-pixel samples hold too few
// of their rare large values for the normal approximation (BSDF sampling of a small light).
inline void check_films_agree(const Film& a, const Film& b, int block, const std::string& what) {
  REQUIRE(a.width() == b.width());
  REQUIRE(a.height() == b.height());
  REQUIRE(a.width() % block == 0);
  REQUIRE(a.height() % block == 0);
  const int bw = a.width() / block, bh = a.height() / block;
  const double z_cell = stats::z_bound(stats::sidak(kFamilyAlpha, 3 * bw * bh));
  const double n_block = double(block) * block, n_image = double(a.width()) * a.height();
  for (int c = 0; c < 3; ++c) {
    int failures = 0;
    double worst = 0, sum_a = 0, sum_b = 0, var_a = 0, var_b = 0;
    for (int by = 0; by < bh; ++by) {
      for (int bx = 0; bx < bw; ++bx) {
        double ma = 0, mb = 0, sa = 0, sb = 0;
        for (int y = by * block; y < (by + 1) * block; ++y) {
          for (int x = bx * block; x < (bx + 1) * block; ++x) {
            ma += a.mean(x, y)[c], mb += b.mean(x, y)[c];
            sa += a.variance_of_mean(x, y)[c], sb += b.variance_of_mean(x, y)[c];
          }
        }
        sum_a += ma, sum_b += mb, var_a += sa, var_b += sb;
        double excess = std::abs(ma - mb) / n_block - kRoundoff * std::max(std::abs(ma), std::abs(mb)) / n_block;
        double z = excess > 0 ? excess / std::sqrt(std::max((sa + sb) / (n_block * n_block), 1e-300)) : 0.0;
        worst = std::max(worst, z);
        failures += z > z_cell;
      }
    }
    double z_mean = stats::z_difference(sum_a / n_image, var_a / (n_image * n_image), sum_b / n_image,
                                        var_b / (n_image * n_image));
    INFO(what << ", channel " << c << ": image means " << sum_a / n_image << " +- " << std::sqrt(var_a) / n_image
              << " vs " << sum_b / n_image << " +- " << std::sqrt(var_b) / n_image << " (z = " << z_mean << "), worst "
              << block << "x" << block << " block |z| " << worst << " (bound " << z_cell << ")");
    CHECK(failures == 0);
    CHECK(std::abs(z_mean) <= kMeanSigmas);
  }
}

}  // namespace pt::test
