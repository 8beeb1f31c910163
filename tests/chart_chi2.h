// Chi-square of a BSDF sampler against its pdf in the half-vector chart of
// tests/microfacet_quadrature.h: rows of v at quantiles of a pilot run (a separate stream), 16
// columns of phi, one more cell for samples refused or below the horizon; a cell's probability
// is the pdf integrated over it by the chart's adaptive cubature. Shared by the metallic-roughness
// and clear-coat tests.
#pragma once
#include <doctest/doctest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "core/math/rng.h"
#include "microfacet_quadrature.h"
#include "stats.h"

namespace pt::test {

// sample(rng, wi) -> false when no direction was drawn; pdf(wi) -> solid-angle density.
template <class SampleFn, class PdfFn>
stats::Chi2Result chi2_in_chart(const HalfVectorChart& chart, const SampleFn& sample, const PdfFn& pdf, int n,
                                uint64_t seed, int rows = 16, int columns = 16) {
  auto cell_of = [&](Pcg32& rng, int& row, int& column, const std::vector<double>& edges) {
    Vec3f wi;
    if (!sample(rng, wi) || !(wi.z > 0)) return false;
    double v, phi;
    chart.coords(wi, v, phi);
    row = std::clamp(static_cast<int>(std::upper_bound(edges.begin(), edges.end(), v) - edges.begin()) - 1, 0, rows - 1);
    column = std::clamp(static_cast<int>((phi + kPiQ) / (2 * kPiQ) * columns), 0, columns - 1);
    return true;
  };
  // Rows at quantiles of v from a pilot run.
  std::vector<double> pilot;
  Pcg32 pilot_rng(seed, 1);
  for (int i = 0; i < 20000; ++i) {
    Vec3f wi;
    if (!sample(pilot_rng, wi) || !(wi.z > 0)) continue;
    double v, phi;
    chart.coords(wi, v, phi);
    pilot.push_back(v);
  }
  REQUIRE(pilot.size() > 1000);
  std::sort(pilot.begin(), pilot.end());
  std::vector<double> edges{0.0};
  for (int k = 1; k < rows; ++k) {
    size_t at = pilot.size() * k / rows;
    double e = 0.5 * (pilot[at - 1] + pilot[at]);
    edges.push_back(std::max(e, edges.back()));
  }
  edges.push_back(1.0);

  std::vector<double> observed(rows * columns + 1, 0.0), expected(rows * columns + 1, 0.0);
  Pcg32 rng(seed, 2);
  for (int i = 0; i < n; ++i) {
    int row, column;
    if (cell_of(rng, row, column, edges)) {
      observed[row * columns + column] += 1;
    } else {
      observed.back() += 1;
    }
  }
  double inside = 0;
  for (int row = 0; row < rows; ++row) {
    if (!(edges[row + 1] > edges[row])) continue;
    for (int column = 0; column < columns; ++column) {
      double phi0 = -kPiQ + 2 * kPiQ * column / columns, phi1 = -kPiQ + 2 * kPiQ * (column + 1) / columns;
      auto density = [&](const Vec3f& wi) { return test::Values<1>{double(pdf(wi))}; };
      double p = chart.integrate<1>(density, edges[row], edges[row + 1], phi0, phi1, 1e-10, 2e-3)[0];
      expected[row * columns + column] = p * n;
      inside += p;
    }
  }
  expected.back() = std::max(0.0, 1 - inside) * n;
  stats::Chi2Result result = stats::chi2_test(observed, expected);
  result.message += "; pdf mass in the cells " + std::to_string(inside) + ", unconverged cubature rectangles " +
                    std::to_string(chart.unconverged());
  return result;
}

}  // namespace pt::test
