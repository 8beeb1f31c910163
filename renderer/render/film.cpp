#include "renderer/render/film.h"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include "core/util/error.h"

namespace pt {
namespace {
// Film sums are double; an image channel is float. A value beyond the float range (the variance of
// an emitter brighter than ~1e19 squares past 3.4e38) is clamped, not turned into infinity.
float to_float(double v, size_t& clamped) {
  if (v > FLT_MAX || v < -FLT_MAX) {
    ++clamped;
    return v > 0 ? FLT_MAX : -FLT_MAX;
  }
  return static_cast<float>(v);
}
}  // namespace

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
  if (has_first_hit() && other.has_first_hit()) {
    for (size_t i = 0; i < first_hits_.size(); ++i) {
      for (int c = 0; c < 3; ++c) {
        first_hits_[i].albedo[c] += other.first_hits_[i].albedo[c];
        first_hits_[i].normal[c] += other.first_hits_[i].normal[c];
      }
      first_hits_[i].depth += other.first_hits_[i].depth;
      first_hits_[i].hits += other.first_hits_[i].hits;
    }
  }
}

Spectrum Film::mean(int x, int y, size_t* clamped) const {
  const Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
  if (p.count == 0) return Spectrum(0.0f);
  size_t n = 0;
  Spectrum m{to_float(p.sum[0] / p.count, n), to_float(p.sum[1] / p.count, n), to_float(p.sum[2] / p.count, n)};
  if (clamped) *clamped += n;
  return m;
}

Spectrum Film::variance_of_mean(int x, int y, size_t* clamped) const {
  const Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
  if (p.count < 2) return Spectrum(0.0f);
  Spectrum v;
  size_t n = 0;
  for (int c = 0; c < 3; ++c) v[c] = to_float(sample_variance(p, c) / p.count, n);
  if (clamped) *clamped += n;
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

double Film::relative_variance(int x, int y) const {
  const Pixel& p = pixels_[static_cast<size_t>(y) * width_ + x];
  if (p.count < 2) return 0.0;
  double e = 0;
  for (int c = 0; c < 3; ++c) {
    const double m = p.sum[c] / p.count;
    e += sample_variance(p, c) / p.count / (m * m + 1e-2);
  }
  return e / 3.0;
}

double Film::estimated_error() const {
  if (pixels_.empty()) return 0.0;
  double sum = 0;
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x) sum += estimated_error2(x, y);
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

Image Film::to_image(bool with_variance, size_t* clamped) const {
  std::vector<std::string> names = {"R", "G", "B"};
  if (with_variance) names.insert(names.end(), {"variance.R", "variance.G", "variance.B"});
  Image image(width_, height_, names);
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      Spectrum m = mean(x, y, clamped);
      for (int c = 0; c < 3; ++c) image.at(x, y, c) = m[c];
      if (with_variance) {
        Spectrum v = variance_of_mean(x, y, clamped);
        for (int c = 0; c < 3; ++c) image.at(x, y, 3 + c) = v[c];
      }
    }
  }
  return image;
}

Image Film::to_image(const AovSet& aovs, size_t* clamped) const {
  if (aovs.first_hit() && !has_first_hit()) throw Error("the film holds no first-hit AOVs (albedo, normal, depth)");
  Image image(width_, height_, aovs.channels());
  for (int y = 0; y < height_; ++y) {
    for (int x = 0; x < width_; ++x) {
      const size_t i = static_cast<size_t>(y) * width_ + x;
      const Pixel& p = pixels_[i];
      int c = 0;
      auto put = [&](float v) { image.at(x, y, c++) = v; };
      Spectrum m = mean(x, y, clamped);
      for (int k = 0; k < 3; ++k) put(m[k]);
      if (aovs.variance) {
        Spectrum v = variance_of_mean(x, y, clamped);
        for (int k = 0; k < 3; ++k) put(v[k]);
      }
      // albedo and N average over every sample taken (a miss adds 0), as the albedo and normals
      // integrators' images do; depth over the samples that hit.
      const double taken = static_cast<double>(p.count) + p.nonfinite;
      const FirstHitSums* f = has_first_hit() ? &first_hits_[i] : nullptr;
      if (aovs.albedo) {
        for (int k = 0; k < 3; ++k) put(taken > 0 ? static_cast<float>(f->albedo[k] / taken) : 0.0f);
      }
      if (aovs.normal) {
        for (int k = 0; k < 3; ++k) put(taken > 0 ? static_cast<float>(f->normal[k] / taken) : 0.0f);
      }
      if (aovs.depth) put(f->hits > 0 ? static_cast<float>(f->depth / f->hits) : 0.0f);
      if (aovs.samples) put(static_cast<float>(p.count));
      if (aovs.nonfinite) put(static_cast<float>(p.nonfinite));
    }
  }
  return image;
}

}  // namespace pt
