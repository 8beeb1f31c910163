// The film: per-pixel sums of radiance and its square, and the sample count. Sums merge exactly,
// so renders with different seeds or crop windows combine into one image (mean and variance
// weighted by sample count).
#pragma once
#include <cstdint>
#include <vector>

#include "core/image/image.h"
#include "core/math/vec.h"

namespace pt {

class Film {
 public:
  Film() = default;
  Film(int width, int height) : width_(width), height_(height), pixels_(static_cast<size_t>(width) * height) {}

  int width() const { return width_; }
  int height() const { return height_; }

  // One writer per pixel at a time (the renderer's tiles are disjoint). Non-finite samples are
  // dropped and counted, never folded into the pixel.
  bool add(int x, int y, const Spectrum& L) {
    if (!is_finite(L)) return false;
    Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
    for (int c = 0; c < 3; ++c) {
      double v = L[c];
      p.sum[c] += v;
      p.sum_sq[c] += v * v;
    }
    ++p.count;
    return true;
  }
  void merge(const Film& other);

  Spectrum mean(int x, int y) const;
  Spectrum variance_of_mean(int x, int y) const;  // sample variance / n
  uint32_t count(int x, int y) const { return pixels_[static_cast<size_t>(y) * width_ + x].count; }
  uint32_t min_count() const;
  uint32_t max_count() const;

  // R, G, B (the mean) and, when asked, variance.R/G/B (the variance of the mean).
  Image to_image(bool with_variance) const;

 private:
  struct Pixel {
    double sum[3] = {0, 0, 0};
    double sum_sq[3] = {0, 0, 0};
    uint32_t count = 0;
  };
  int width_ = 0, height_ = 0;
  std::vector<Pixel> pixels_;
};

}  // namespace pt
