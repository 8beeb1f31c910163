// The film: per-pixel sums of radiance and its square, the sample count and the count of dropped
// (non-finite) samples. Sums merge exactly, so renders with different seeds or crop windows
// combine into one image (mean and variance weighted by sample count); a split render's parts
// carry these sums bit for bit (renderer/farm/part_file.h).
#pragma once
#include <algorithm>
#include <cstdint>
#include <vector>

#include "core/image/image.h"
#include "core/math/vec.h"
#include "renderer/render/aov.h"

namespace pt {

class Film {
 public:
  Film() = default;
  Film(int width, int height) : width_(width), height_(height), pixels_(static_cast<size_t>(width) * height) {}

  int width() const { return width_; }
  int height() const { return height_; }

  // One writer per pixel at a time (the renderer's tiles are disjoint). Non-finite samples are
  // dropped and counted, never folded into the pixel.
  // `sample` is the sample's index in its pixel; with error estimation on, even indices also go
  // into the half buffer.
  bool add(int x, int y, const Spectrum& L, uint32_t sample = 0) {
    size_t i = static_cast<size_t>(y) * width_ + x;
    Pixel& p = pixels_[i];
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
    if (!half_.empty() && (sample & 1u) == 0) {
      Half& h = half_[i];
      for (int c = 0; c < 3; ++c) h.sum[c] += L[c];
      ++h.count;
    }
    return true;
  }

  // Error estimation (Film::error below): keeps a second sum over the even-indexed samples only.
  void enable_error_estimate() { half_.assign(pixels_.size(), Half{}); }
  bool has_error_estimate() const { return !half_.empty(); }
  // The estimated relative squared error of pixel (x, y)'s mean, averaged over R, G, B:
  // (m - h)^2 / (m^2 + 0.01) with m the mean of all samples and h that of the even-indexed half.
  // With independent samples E[(m - h)^2] is exactly the variance of m (m - h is half the
  // difference of two independent half means), so no assumption about the sample distribution is
  // needed; the 0.01 keeps dark pixels from dominating (the relative MSE of Rousselle et al. 2011,
  // which `pt bench converge` reports against a reference as rel_mse).
  double relative_error2(int x, int y) const;
  // The same from the sample variance: var / n / (m^2 + 0.01), averaged over R, G, B. It needs no
  // half buffer, but overstates the error of stratified (Sobol) samples, whose mean converges
  // faster than the variance of one sample says.
  double relative_variance(int x, int y) const;
  // The pixel's estimated relative squared error: relative_error2 where the film keeps the half
  // buffers, else relative_variance.
  double estimated_error2(int x, int y) const {
    return has_error_estimate() ? relative_error2(x, y) : relative_variance(x, y);
  }
  // The image's estimated relative error: sqrt of the mean of estimated_error2 over every pixel.
  double estimated_error() const;
  void merge(const Film& other);

  // Values beyond the float range are clamped to +-FLT_MAX and counted in *clamped when given.
  Spectrum mean(int x, int y, size_t* clamped = nullptr) const;
  Spectrum variance_of_mean(int x, int y, size_t* clamped = nullptr) const;  // sample variance / n
  uint32_t count(int x, int y) const { return pixels_[static_cast<size_t>(y) * width_ + x].count; }
  // Samples taken, kept or dropped: the pixel holds sample indices [first, first + taken) of its
  // sequence, so a resumed render continues at index first + taken.
  uint32_t taken(int x, int y) const {
    const Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
    return p.count + p.nonfinite;
  }
  uint32_t min_count() const;
  uint32_t max_count() const;

  // R, G, B (the mean) and, when asked, variance.R/G/B (the variance of the mean); every value
  // finite (clamped to the float range, counted in *clamped).
  Image to_image(bool with_variance, size_t* clamped = nullptr) const;
  // R, G, B and the AOV channels of `aovs` (aov.h); albedo, N and depth need enable_first_hit().
  Image to_image(const AovSet& aovs, size_t* clamped = nullptr) const;

  // The first-hit AOVs' sums (aov.h), kept only once enable_first_hit() has been called, so a
  // render that does not ask for them carries no memory for them. Every sample taken adds one,
  // kept or dropped, so they average over `taken` samples.
  struct FirstHitSums {
    double albedo[3] = {0, 0, 0};
    double normal[3] = {0, 0, 0};
    double depth = 0;
    uint32_t hits = 0;  // samples whose ray hit a surface (depth averages over these)
  };
  void enable_first_hit() { first_hits_.assign(pixels_.size(), FirstHitSums{}); }
  bool has_first_hit() const { return !first_hits_.empty(); }
  void add_first_hit(int x, int y, const FirstHit& f) {
    FirstHitSums& s = first_hits_[static_cast<size_t>(y) * width_ + x];
    if (!f.hit) return;
    for (int c = 0; c < 3; ++c) {
      s.albedo[c] += f.albedo[c];
      s.normal[c] += f.normal[c];
    }
    s.depth += f.depth;
    ++s.hits;
  }

  struct Pixel {
    double sum[3] = {0, 0, 0};
    double sum_sq[3] = {0, 0, 0};
    uint32_t count = 0;      // finite samples, in the sums
    uint32_t nonfinite = 0;  // NaN or infinite samples, dropped
  };
  // The variance of one sample of channel c (unbiased, n - 1), 0 below two samples.
  static double sample_variance(const Pixel& p, int c) {
    if (p.count < 2) return 0.0;
    const double m = p.sum[c] / p.count;
    return std::max(0.0, (p.sum_sq[c] - p.count * m * m) / (p.count - 1));
  }
  // The raw state, for the part files that carry it exactly (renderer/farm/part_file.cpp).
  const Pixel& pixel(int x, int y) const { return pixels_[static_cast<size_t>(y) * width_ + x]; }
  Pixel& pixel(int x, int y) { return pixels_[static_cast<size_t>(y) * width_ + x]; }

 private:
  struct Half {
    double sum[3] = {0, 0, 0};
    uint32_t count = 0;
  };
  int width_ = 0, height_ = 0;
  std::vector<Pixel> pixels_;
  std::vector<Half> half_;
  std::vector<FirstHitSums> first_hits_;  // empty unless enable_first_hit()
};

}  // namespace pt
