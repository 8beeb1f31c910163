#include "renderer/film.h"

#include <algorithm>
#include <cmath>

namespace pt {

void Film::merge(const Film& other) {
  for (size_t i = 0; i < pixels_.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      pixels_[i].sum[c] += other.pixels_[i].sum[c];
      pixels_[i].sum_sq[c] += other.pixels_[i].sum_sq[c];
    }
    pixels_[i].count += other.pixels_[i].count;
    pixels_[i].nonfinite += other.pixels_[i].nonfinite;
  }
  if (!half_.empty() && other.half_.size() == half_.size()) {
    for (size_t i = 0; i < half_.size(); ++i) {
      for (int c = 0; c < 3; ++c) half_[i].sum[c] += other.half_[i].sum[c];
      half_[i].count += other.half_[i].count;
    }
  }
}

Spectrum Film::mean(int x, int y) const {
  const Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
  if (p.count == 0) return Spectrum(0.0f);
  return {static_cast<float>(p.sum[0] / p.count), static_cast<float>(p.sum[1] / p.count),
          static_cast<float>(p.sum[2] / p.count)};
}

Spectrum Film::variance_of_mean(int x, int y) const {
  const Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
  if (p.count < 2) return Spectrum(0.0f);
  Spectrum v;
  for (int c = 0; c < 3; ++c) {
    double m = p.sum[c] / p.count;
    double var = std::max(0.0, (p.sum_sq[c] - p.count * m * m) / (p.count - 1));
    v[c] = static_cast<float>(var / p.count);
  }
  return v;
}

double Film::relative_error2(int x, int y) const {
  size_t i = static_cast<size_t>(y) * width_ + x;
  const Pixel& p = pixels_[i];
  const Half& h = half_[i];
  if (p.count < 2 || h.count == 0) return 0.0;
  double e = 0;
  for (int c = 0; c < 3; ++c) {
    double m = p.sum[c] / p.count, d = m - h.sum[c] / h.count;
    e += d * d / (m * m + 1e-2);
  }
  return e / 3.0;
}

double Film::estimated_error() const {
  if (half_.empty() || pixels_.empty()) return 0.0;
  double sum = 0;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) sum += relative_error2(x, y);
  return std::sqrt(sum / pixels_.size());
}

uint32_t Film::min_count() const {
  uint32_t m = UINT32_MAX;
  for (const Pixel& p : pixels_) m = std::min(m, p.count);
  return pixels_.empty() ? 0 : m;
}

uint32_t Film::max_count() const {
  uint32_t m = 0;
  for (const Pixel& p : pixels_) m = std::max(m, p.count);
  return m;
}

Image Film::to_image(bool with_variance) const {
  std::vector<std::string> names = {"R", "G", "B"};
  if (with_variance) names.insert(names.end(), {"variance.R", "variance.G", "variance.B"});
  Image image(width_, height_, names);
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      Spectrum m = mean(x, y);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = m[c];
      if (with_variance) {
        Spectrum v = variance_of_mean(x, y);
        for (int c = 0; c < 3; ++c) image.at(x, y, 3 + c) = v[c];
      }
    }
  }
  return image;
}

}  // namespace pt
