// The film: per-pixel sums of radiance and its square, the sample count and the count of dropped
// (non-finite) samples. Sums merge exactly, so renders with different seeds or crop windows
// combine into one image (mean and variance weighted by sample count); a split render's parts
// carry these sums bit for bit (renderer/part_file.h).
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
    Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
    if (!is_finite(L)) {
      ++p.nonfinite;
      return false;
    }
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
  // Samples taken, kept or dropped: the pixel holds sample indices [first, first + taken) of its
  // sequence, so a resumed render continues at index first + taken.
  uint32_t taken(int x, int y) const {
    const Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
    return p.count + p.nonfinite;
  }
  uint32_t min_count() const;
  uint32_t max_count() const;

  // R, G, B (the mean) and, when asked, variance.R/G/B (the variance of the mean).
  Image to_image(bool with_variance) const;

  struct Pixel {
    double sum[3] = {0, 0, 0};
    double sum_sq[3] = {0, 0, 0};
    uint32_t count = 0;      // finite samples, in the sums
    uint32_t nonfinite = 0;  // NaN or infinite samples, dropped
  };
  // The raw state, for the part files that carry it exactly (renderer/part_file.cpp).
  const Pixel& pixel(int x, int y) const { return pixels_[static_cast<size_t>(y) * width_ + x]; }
  Pixel& pixel(int x, int y) { return pixels_[static_cast<size_t>(y) * width_ + x]; }

 private:
  int width_ = 0, height_ = 0;
  std::vector<Pixel> pixels_;
};

}  // namespace pt
