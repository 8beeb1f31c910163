// Piecewise-constant distributions for choosing lights by power and sampling environment maps
// (PBRT 3rd ed., 13.3.1 and 14.2.4).
#pragma once
#include <algorithm>
#include <cmath>
#include <vector>

#include "core/math/vec.h"

namespace pt {

class Distribution1D {
 public:
  Distribution1D() = default;
  explicit Distribution1D(const std::vector<float>& weights) : func_(weights), cdf_(weights.size() + 1) {
    for (float& f : func_) f = std::max(0.0f, f);  // negative weights count as zero, in the pdf too
    double sum = 0;
    cdf_[0] = 0;
    std::vector<double> acc(weights.size() + 1, 0.0);
    for (size_t i = 0; i < weights.size(); ++i) {
      sum += std::max(0.0f, weights[i]);
      acc[i + 1] = sum;
    }
    integral_ = static_cast<float>(sum / std::max<size_t>(1, weights.size()));
    for (size_t i = 1; i < acc.size(); ++i) {
      cdf_[i] = sum > 0 ? static_cast<float>(acc[i] / sum) : static_cast<float>(i) / weights.size();
    }
    if (sum <= 0) std::fill(func_.begin(), func_.end(), 1.0f), integral_ = 1.0f;
    cdf_.back() = 1.0f;
  }
  size_t size() const { return func_.size(); }
  bool empty() const { return func_.empty(); }
  // Discrete: index with probability weight/sum, and u remapped to [0,1) inside the chosen cell.
  size_t sample_discrete(float u, float* pdf = nullptr, float* u_remapped = nullptr) const {
    size_t i = find(u);
    float width = cdf_[i + 1] - cdf_[i];
    if (pdf) *pdf = width;
    if (u_remapped) *u_remapped = width > 0 ? std::min((u - cdf_[i]) / width, 0x1.fffffep-1f) : 0.0f;
    return i;
  }
  float discrete_pdf(size_t i) const { return cdf_[i + 1] - cdf_[i]; }
  // Continuous on [0,1): returns x and its density.
  float sample_continuous(float u, float* pdf, size_t* index = nullptr) const {
    size_t i = find(u);
    float width = cdf_[i + 1] - cdf_[i];
    float du = width > 0 ? (u - cdf_[i]) / width : 0.5f;
    if (pdf) *pdf = integral_ > 0 ? func_[i] / integral_ : 0.0f;
    if (index) *index = i;
    // The point must lie in cell i, where pdf() will look for it: (i + du) / n can round onto the
    // next cell's edge, and i / n back into the previous cell.
    float n = static_cast<float>(func_.size());
    float x = std::min((static_cast<float>(i) + std::min(du, 0x1.fffffep-1f)) / n, 0x1.fffffep-1f);
    while (x > 0.0f && static_cast<size_t>(x * n) > i) x = std::nextafter(x, 0.0f);
    while (x < 1.0f && static_cast<size_t>(x * n) < i) x = std::nextafter(x, 1.0f);
    return x;
  }
  float continuous_pdf(size_t i) const { return integral_ > 0 ? func_[i] / integral_ : 0.0f; }
  float integral() const { return integral_; }

 private:
  size_t find(float u) const {
    // Largest i with cdf[i] <= u, skipping zero-width cells.
    auto it = std::upper_bound(cdf_.begin(), cdf_.end(), u);
    size_t i = static_cast<size_t>(std::max<std::ptrdiff_t>(0, (it - cdf_.begin()) - 1));
    i = std::min(i, func_.size() - 1);
    while (i + 1 < func_.size() && cdf_[i + 1] - cdf_[i] <= 0) ++i;
    while (i > 0 && cdf_[i + 1] - cdf_[i] <= 0) --i;
    return i;
  }
  std::vector<float> func_;
  std::vector<float> cdf_;
  float integral_ = 0;
};

// Density on [0,1)^2 proportional to a w x h grid of weights (row-major, row 0 at v = 0).
class Distribution2D {
 public:
  Distribution2D() = default;
  Distribution2D(const std::vector<float>& weights, int w, int h) {
    rows_.reserve(h);
    std::vector<float> marginal(h);
    for (int y = 0; y < h; ++y) {
      std::vector<float> row(weights.begin() + static_cast<size_t>(y) * w,
                             weights.begin() + static_cast<size_t>(y + 1) * w);
      rows_.emplace_back(row);
      // The row's own weight, not rows_.back().integral(): a row of zeros falls back to a uniform
      // conditional with integral 1, which must not give it a share of the marginal.
      double sum = 0;
      for (float v : row) sum += std::max(0.0f, v);
      marginal[y] = static_cast<float>(sum / std::max(1, w));
    }
    marginal_ = Distribution1D(marginal);
  }
  Vec2f sample(Vec2f u, float* pdf) const {
    float pdf_v, pdf_u;
    size_t row;
    float v = marginal_.sample_continuous(u.y, &pdf_v, &row);
    float uu = rows_[row].sample_continuous(u.x, &pdf_u);
    *pdf = pdf_u * pdf_v;
    return {uu, v};
  }
  float pdf(Vec2f uv) const {
    size_t h = rows_.size(), w = rows_[0].size();
    size_t y = std::min(static_cast<size_t>(std::max(0.0f, uv.y) * h), h - 1);
    size_t x = std::min(static_cast<size_t>(std::max(0.0f, uv.x) * w), w - 1);
    return rows_[y].continuous_pdf(x) * marginal_.continuous_pdf(y);
  }

 private:
  std::vector<Distribution1D> rows_;
  Distribution1D marginal_;
};

}  // namespace pt
