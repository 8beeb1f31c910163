// Statistics shared by the tests: the regularized incomplete gamma function, Pearson's chi-square
// goodness-of-fit test with pooling of sparse cells, and z-tests on means with their variances.
// Thresholds come from a significance level, never from the data.
#pragma once
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>
#include <string>
#include <vector>

namespace pt::stats {

// Regularized lower incomplete gamma P(a, x) by its power series, valid for x < a + 1
// (Abramowitz & Stegun 6.5.29; Press et al., "Numerical Recipes", 3rd ed., 6.2).
inline double gamma_p_series(double a, double x) {
  double term = 1.0 / a, sum = term;
  for (int n = 1; n < 10000; ++n) {
    term *= x / (a + n);
    sum += term;
    if (std::abs(term) < std::abs(sum) * 1e-16) break;
  }
  return sum * std::exp(-x + a * std::log(x) - std::lgamma(a));
}

// Regularized upper incomplete gamma Q(a, x) by its continued fraction, valid for x >= a + 1,
// evaluated with the modified Lentz method (A&S 6.5.31; Numerical Recipes 6.2, 5.2).
inline double gamma_q_fraction(double a, double x) {
  constexpr double kTiny = 1e-300;
  double b = x + 1.0 - a, c = 1.0 / kTiny, d = 1.0 / b, h = d;
  for (int i = 1; i < 10000; ++i) {
    double an = -i * (i - a);
    b += 2.0;
    d = an * d + b;
    if (std::abs(d) < kTiny) d = kTiny;
    c = b + an / c;
    if (std::abs(c) < kTiny) c = kTiny;
    d = 1.0 / d;
    double delta = d * c;
    h *= delta;
    if (std::abs(delta - 1.0) < 1e-16) break;
  }
  return std::exp(-x + a * std::log(x) - std::lgamma(a)) * h;
}

// Q(a, x) = 1 - P(a, x): the probability that a chi-square variable with 2a degrees of freedom
// exceeds 2x.
inline double gamma_q(double a, double x) {
  if (x <= 0) return 1.0;
  return x < a + 1.0 ? 1.0 - gamma_p_series(a, x) : gamma_q_fraction(a, x);
}

inline double chi2_survival(double statistic, int dof) { return gamma_q(0.5 * dof, 0.5 * statistic); }

// Per-test significance so that `tests` independent tests together reject a true hypothesis with
// probability `alpha` (Šidák correction).
inline double sidak(double alpha, int tests) { return 1.0 - std::pow(1.0 - alpha, 1.0 / tests); }

struct Chi2Result {
  double statistic = 0;
  int dof = 0;
  double p_value = 1;
  std::string message;
};

// Pearson's chi-square on observed vs expected counts. Cells expecting fewer than `min_expected`
// samples are pooled into one cell (the chi-square approximation needs a handful per cell); if the
// pool is still too small it joins the smallest regular cell. Same approach as nori's chi2test.
inline Chi2Result chi2_test(const std::vector<double>& observed, const std::vector<double>& expected,
                            double min_expected = 5.0) {
  std::vector<size_t> order(observed.size());
  std::iota(order.begin(), order.end(), 0);
  std::sort(order.begin(), order.end(), [&](size_t a, size_t b) { return expected[a] < expected[b]; });
  double pool_obs = 0, pool_exp = 0;
  std::vector<std::pair<double, double>> cells;  // (observed, expected), ascending expected
  for (size_t i : order) {
    if (expected[i] < min_expected) {
      pool_obs += observed[i];
      pool_exp += expected[i];
    } else {
      cells.emplace_back(observed[i], expected[i]);
    }
  }
  if (pool_exp >= min_expected || cells.empty()) {
    cells.emplace_back(pool_obs, pool_exp);
  } else {
    cells.front().first += pool_obs;
    cells.front().second += pool_exp;
  }
  Chi2Result r;
  for (const auto& [o, e] : cells) {
    if (e <= 0) {
      if (o > 0) r.statistic = INFINITY;
      continue;
    }
    r.statistic += (o - e) * (o - e) / e;
  }
  r.dof = static_cast<int>(cells.size()) - 1;
  r.p_value = r.dof > 0 ? chi2_survival(r.statistic, r.dof) : 1.0;
  if (!std::isfinite(r.statistic)) r.p_value = 0;
  std::ostringstream s;
  s << "chi2 = " << r.statistic << ", dof = " << r.dof << ", p = " << r.p_value << " (" << cells.size()
    << " cells, pooled " << pool_exp << " expected / " << pool_obs << " observed)";
  r.message = s.str();
  return r;
}

// Two-sided normal tail probability of |z|.
inline double normal_two_sided_p(double z) { return std::erfc(std::abs(z) / std::sqrt(2.0)); }

// The |z| exceeded with two-sided probability alpha under the normal law (bisection on erfc).
inline double z_bound(double alpha) {
  double lo = 0, hi = 40;
  for (int i = 0; i < 200; ++i) {
    double mid = 0.5 * (lo + hi);
    (normal_two_sided_p(mid) > alpha ? lo : hi) = mid;
  }
  return hi;
}

// z-score of the difference of two independent estimates with variances var_a, var_b.
inline double z_difference(double a, double var_a, double b, double var_b) {
  return (a - b) / std::sqrt(std::max(1e-300, var_a + var_b));
}

// Mean and variance of the mean of a set of samples.
struct MeanVar {
  double n = 0, sum = 0, sum_sq = 0;
  void add(double x) {
    n += 1;
    sum += x;
    sum_sq += x * x;
  }
  double mean() const { return sum / n; }
  double variance_of_mean() const {
    double m = mean();
    return std::max(0.0, (sum_sq / n - m * m)) / (n - 1);
  }
};

}  // namespace pt::stats
