// The coarser MIP levels of a texture held in pt's own memory and filtered without OpenImageIO.
//
// A call into the TextureSystem costs about 100 ns whatever it reads: on textured scenes it made
// the time per sample 1.4-2x that of the whole-image bilinear lookups it replaced. So the levels of
// at most kHeldTexels texels (all of a texture up to 512x512, the 512x512 level and coarser of a
// larger one; only those of at most kSmallTexels when the scene's budget for them is spent) are
// made once while the texture is checked at load (the one pass that reads every texel anyway:
// LevelBuilder, box-filtered as OpenImageIO's automip makes its levels) and a lookup whose footprint
// selects one of them is filtered here. The filter: probes along the
// footprint's major axis, each as wide as its minor axis (Feline: McCormack et al. 1999; at most
// kMaxProbes, beyond which they widen), each bilinear on the level nearest that width (Williams
// 1983; trilinear blending gave the same error for twice the reads, docs/textures.md). Finer levels
// stay with the TextureSystem, whose cache bounds their memory.
#pragma once
#include <algorithm>
#include <bit>
#include <cstdint>
#include <cmath>
#include <cstring>
#include <vector>

#include "core/image/texture_cache.h"
#include "core/math/vec.h"

namespace pt {

class CoarseLevels {
 public:
  static constexpr size_t kHeldTexels = 512 * 512;
  static constexpr size_t kSmallTexels = 64 * 64;
  static constexpr int kMaxProbes = 8;

  struct Level {
    int width = 0, height = 0;
    // `stride` floats per texel, row 0 at t = 0: RGB and alpha, or RGB alone where every alpha of
    // the texture is 1, then with one float of 1 after the last texel (a texel is read with one
    // 16-byte load, which reads the next texel's red, or that float, as its fourth lane).
    std::vector<float> texels;
    int stride = 4;
    bool masks = false;  // both sizes powers of two: repeat wraps by masking (fetch)
  };

  // `first` is the index in the full pyramid of levels[0]; the levels follow it to the 1x1 level.
  CoarseLevels() = default;
  CoarseLevels(int first, int width0, int height0, std::vector<Level> levels)
      : first_(first), width0_(width0), height0_(height0), levels_(std::move(levels)) {
    for (Level& l : levels_) {
      l.masks = std::has_single_bit(static_cast<unsigned>(l.width)) &&
                std::has_single_bit(static_cast<unsigned>(l.height));
    }
    pack_opaque();
  }

  bool empty() const { return levels_.empty(); }
  int first() const { return first_; }
  const std::vector<Level>& levels() const { return levels_; }

  // Looks `q` up here if its footprint selects a held level; false to leave it to the TextureSystem.
  // `out` gets the four channels.
  bool lookup(const TextureQuery& q, bool filtered, float out[4]) const {
    if (levels_.empty()) return false;
    if (!filtered) {
      if (first_ > 0) return false;
      const Level& level = levels_[0];
      const Texel v = level.stride == 3 ? bilinear<3>(level, q.s, q.t, q) : bilinear<4>(level, q.s, q.t, q);
      for (int c = 0; c < 4; ++c) out[c] = v[c];
      if (level.stride == 3) out[3] = 1.0f;
      return true;
    }
    // The footprint's axes in level-0 texels (texture space is [0, 1]^2 over the level).
    const float ax = std::sqrt(sq(q.dsdx * width0_) + sq(q.dtdx * height0_));
    const float ay = std::sqrt(sq(q.dsdy * width0_) + sq(q.dtdy * height0_));
    float major = ax, minor = ay;
    float ds = q.dsdx, dt = q.dtdx;  // the major axis in texture space
    if (ay > ax) major = ay, minor = ax, ds = q.dsdy, dt = q.dtdy;
    if (!std::isfinite(major)) return false;
    // An elliptical footprint is covered by probes along its major axis, each as wide as the minor
    // axis (Feline: McCormack et al. 1999), at most kMaxProbes of them: beyond, the probes widen.
    int probes = 1;
    if (!q.isotropic && major > minor && major > 1.0f) {
      // No closer than half a texel of level 0: bilinear reconstruction is linear between texel
      // centres, so denser probes hardly change the mean (horizon 4 spp: RMSE 0.0071466, against
      // 0.0071463 with probes as close as the minor axis), and a thin magnified footprint took 8.
      probes = std::min(kMaxProbes, static_cast<int>(std::ceil(major / std::max(minor, 0.5f))));
      minor = std::max(minor, major / static_cast<float>(kMaxProbes));
    }
    const float width = probes > 1 ? minor : major;
    const int lod = nearest_level(width);
    if (lod < first_) return false;
    const Level& level = levels_[std::min(lod - first_, static_cast<int>(levels_.size()) - 1)];
    // Probes evenly spread over the major axis, from -1/2 to 1/2 of it, equally weighted; in the
    // level's texel coordinates, the first at (fx, fy) and each next one a step further.
    const float lw = static_cast<float>(level.width), lh = static_cast<float>(level.height);
    const float inv = 1.0f / static_cast<float>(probes);
    float step_x = ds * lw * inv, step_y = dt * lh * inv;
    float fx = (q.s + q.dsdc) * lw - 0.5f - step_x * (0.5f * static_cast<float>(probes - 1));
    float fy = (q.t + q.dtdc) * lh - 0.5f - step_y * (0.5f * static_cast<float>(probes - 1));
    if (!(std::abs(fx) < 1e6f && std::abs(fy) < 1e6f && std::abs(step_x) < 1e5f && std::abs(step_y) < 1e5f)) {
      fx = fy = step_x = step_y = 0.0f;  // also NaN: as bilinear() does
    }
    Texel sum = level.stride == 3 ? filter<3>(level, fx, fy, step_x, step_y, probes, q)
                                  : filter<4>(level, fx, fy, step_x, step_y, probes, q);
    if (probes > 1) sum *= inv;
    for (int c = 0; c < 4; ++c) out[c] = sum[c];
    if (level.stride == 3) out[3] = 1.0f;
    return true;
  }

 private:
  // The texel index i (possibly outside [0, n)) under a wrap mode; -1 for none (black).
  static int wrap(int i, int n, TextureWrap mode) {
    if (i >= 0 && i < n) return i;
    switch (mode) {
      case TextureWrap::kRepeat: return ((i % n) + n) % n;
      case TextureWrap::kClamp: return i < 0 ? 0 : n - 1;
      case TextureWrap::kMirror: {
        int period = 2 * n, m = ((i % period) + period) % period;
        return m < n ? m : period - 1 - m;
      }
      case TextureWrap::kBlack: return -1;
    }
    return 0;
  }
  static float sq(float x) { return x * x; }
  // The level whose texels are nearest `width` level-0 texels wide: log2(width) rounded, read off
  // the float's exponent and mantissa (up a level from a mantissa of sqrt(2)).
  static int nearest_level(float width) {
    if (!(width > 1.0f)) return 0;
    const uint32_t bits = std::bit_cast<uint32_t>(width);
    return static_cast<int>(bits >> 23) - 127 + ((bits & 0x7fffffu) >= 0x3504f3u ? 1 : 0);
  }
  // Texel columns (or rows) i and i + 1 under a wrap mode, -1 for none (black).
  static void wrap_pair(int i, int n, TextureWrap mode, int& a, int& b) {
    if (static_cast<unsigned>(i) < static_cast<unsigned>(n - 1)) {
      a = i, b = i + 1;
    } else {
      a = wrap(i, n, mode), b = wrap(i + 1, n, mode);
    }
  }
  // Four channels in one vector register (GCC's vector extension): a texel is one load.
  typedef float Texel __attribute__((vector_size(16)));
  static Texel load(const float* p) {
    Texel v;
    std::memcpy(&v, p, sizeof v);
    return v;
  }
  // floor(x) for |x| < 2^31, without a call or SSE4.1's roundss.
  static int floor_int(float x) {
    const int i = static_cast<int>(x);
    return i - (x < static_cast<float>(i) ? 1 : 0);
  }
  // Every alpha 1 (three channels or fewer in the file, or an alpha channel that is all 1): the
  // levels keep RGB alone, 12 bytes a texel instead of 16. On textured-sphere the held texels' reads
  // waited on memory (the 512x256 planet's level 0 was 2 MiB, the L2 is 1 MiB).
  void pack_opaque() {
    for (const Level& l : levels_) {
      if (l.stride != 4) return;
      for (size_t i = 3; i < l.texels.size(); i += 4) {
        if (l.texels[i] != 1.0f) return;
      }
    }
    for (Level& l : levels_) {
      const size_t n = l.texels.size() / 4;
      std::vector<float> rgb(3 * n + 1, 1.0f);
      for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) rgb[3 * i + c] = l.texels[4 * i + c];
      }
      l.texels = std::move(rgb);
      l.stride = 3;
    }
  }
  // The probes' sum: four at a time where the level repeats over power-of-two sizes.
  template <int Stride>
  static Texel filter(const Level& level, float fx, float fy, float step_x, float step_y, int probes, const TextureQuery& q) {
    if (probes > 1 && level.masks && q.wrap_s == TextureWrap::kRepeat && q.wrap_t == TextureWrap::kRepeat) {
      return probe_series<Stride>(level, fx, fy, step_x, step_y, probes);
    }
    Texel sum = fetch<Stride>(level, fx, fy, q);
    for (int k = 1; k < probes; ++k) sum += fetch<Stride>(level, fx + step_x * k, fy + step_y * k, q);
    return sum;
  }
  // Bilinear between the four texel centres around (s, t), texel centres at (i + 0.5) / n.
  template <int Stride>
  static Texel bilinear(const Level& level, float s, float t, const TextureQuery& q) {
    float fx = s * level.width - 0.5f, fy = t * level.height - 0.5f;
    if (!(std::abs(fx) < 1e6f && std::abs(fy) < 1e6f)) fx = fy = 0.0f;  // also NaN
    return fetch<Stride>(level, fx, fy, q);
  }
  // The same at texel coordinates fx = s w - 1/2, fy = t h - 1/2 (each within +-1e6). A texture
  // repeated in both axes over power-of-two sizes (every held level of a power-of-two texture) has
  // its texel pairs wrapped by a mask: a floor seen to the horizon is read mostly far outside [0, n).
  // Stride: Level::stride; a texel's fourth lane is meaningless where it is 3.
  template <int Stride>
  static Texel fetch(const Level& level, float fx, float fy, const TextureQuery& q) {
    const int x0 = floor_int(fx), y0 = floor_int(fy);
    const float ax = fx - static_cast<float>(x0), ay = fy - static_cast<float>(y0);
    const float w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
    const float* texels = level.texels.data();
    const int w = level.width, h = level.height;
    int xa, xb, ya, yb;
    if (level.masks && q.wrap_s == TextureWrap::kRepeat && q.wrap_t == TextureWrap::kRepeat) {
      xa = x0 & (w - 1), xb = (x0 + 1) & (w - 1), ya = y0 & (h - 1), yb = (y0 + 1) & (h - 1);
    } else {
      wrap_pair(x0, w, q.wrap_s, xa, xb);
      wrap_pair(y0, h, q.wrap_t, ya, yb);
      if ((xa | xb | ya | yb) < 0) {
        auto texel = [&](int x, int y) {
          return x < 0 || y < 0 ? Texel{0, 0, 0, 0} : load(texels + Stride * (static_cast<size_t>(y) * w + x));
        };
        return w00 * texel(xa, ya) + w10 * texel(xb, ya) + w01 * texel(xa, yb) + w11 * texel(xb, yb);
      }
    }
    const float* row_a = texels + Stride * static_cast<size_t>(ya) * w;
    const float* row_b = texels + Stride * static_cast<size_t>(yb) * w;
    return w00 * load(row_a + Stride * xa) + w10 * load(row_a + Stride * xb) + w01 * load(row_b + Stride * xa) +
           w11 * load(row_b + Stride * xb);
  }

  // The sum of fetch() at (fx + k step_x, fy + k step_y), k < probes, on a level repeated over
  // power-of-two sizes: coordinates, weights and texel offsets of four probes at a time in vector
  // registers, so that each probe costs little more than its four texel loads.
  template <int Stride>
  static Texel probe_series(const Level& level, float fx, float fy, float step_x, float step_y, int probes) {
    typedef int Lanes __attribute__((vector_size(16)));
    const float* texels = level.texels.data();
    const int wm = level.width - 1, hm = level.height - 1;
    Texel sum{0, 0, 0, 0};
    for (int k0 = 0; k0 < probes; k0 += 4) {
      const Texel k = Texel{0, 1, 2, 3} + static_cast<float>(k0);
      const Texel x = fx + step_x * k, y = fy + step_y * k;
      Lanes xi = __builtin_convertvector(x, Lanes), yi = __builtin_convertvector(y, Lanes);
      xi += x < __builtin_convertvector(xi, Texel);  // floor: a true compare is -1
      yi += y < __builtin_convertvector(yi, Texel);
      const Texel ax = x - __builtin_convertvector(xi, Texel), ay = y - __builtin_convertvector(yi, Texel);
      const Texel w00 = (1 - ax) * (1 - ay), w10 = ax * (1 - ay), w01 = (1 - ax) * ay, w11 = ax * ay;
      const Lanes xa = Stride * (xi & wm), xb = Stride * ((xi + 1) & wm);
      const Lanes ra = Stride * (level.width * (yi & hm)), rb = Stride * (level.width * ((yi + 1) & hm));
      const int n = std::min(4, probes - k0);
      for (int j = 0; j < n; ++j) {
        sum += w00[j] * load(texels + ra[j] + xa[j]) + w10[j] * load(texels + ra[j] + xb[j]) +
               w01[j] * load(texels + rb[j] + xa[j]) + w11[j] * load(texels + rb[j] + xb[j]);
      }
    }
    return sum;
  }

  int first_ = 0;
  int width0_ = 0, height0_ = 0;
  std::vector<Level> levels_;
};

// Builds the held levels from the rows of level 0 as they are read, a strip at a time, so that a
// large texture is never whole in memory: the first held level is the finest of at most
// `max_texels` texels (level k is max(1, w >> k) by max(1, h >> k)), each of its texels the mean of
// the level-0 texels it covers; the coarser ones follow by 2x2 means down to 1x1.
class LevelBuilder {
 public:
  LevelBuilder(int width, int height, int channels, size_t max_texels)
      : width_(width), height_(height), channels_(channels) {
    first_ = first_level(width, height, max_texels);
    w_ = dim(width_, first_), h_ = dim(height_, first_);
    // Level 0 itself, and a first level finer than the first pass holds (a texture held whole or
    // nearly, finish_loading in texture_system.cpp: 4-16 texels a mean), are summed in floats in
    // place, so that building them takes no more memory than holding them (sums in double and
    // counts took 2.25 times as much); coarser ones sum in double, with counts.
    if (first_ == 0 || static_cast<size_t>(w_) * h_ > CoarseLevels::kHeldTexels) {
      whole_.assign(4 * static_cast<size_t>(w_) * h_, 0.0f);
    } else {
      sums_.assign(4 * static_cast<size_t>(w_) * h_, 0.0);
      counts_.assign(static_cast<size_t>(w_) * h_, 0);
    }
  }
  // The index of the finest level of at most `max_texels` texels of a width x height texture.
  static int first_level(int width, int height, size_t max_texels) {
    int first = 0;
    while (static_cast<size_t>(dim(width, first)) * dim(height, first) > max_texels) ++first;
    return first;
  }
  // The bytes of the levels held from `first` down to 1x1.
  static size_t held_bytes(int width, int height, int first) {
    size_t texels = 0;
    for (int w = dim(width, first), h = dim(height, first);; w = std::max(1, w / 2), h = std::max(1, h / 2)) {
      texels += static_cast<size_t>(w) * h;
      if (w == 1 && h == 1) break;
    }
    return 4 * sizeof(float) * texels;
  }
  // Rows [y, y + rows) of level 0, `channels` floats per texel.
  void add_rows(int y, int rows, const float* data) {
    if (!whole_.empty()) {
      add_rows_to(whole_.data(), y, rows, data);
      return;
    }
    add_rows_to(sums_.data(), y, rows, data);
    for (int j = 0; j < rows; ++j) {
      const int ty = std::min((y + j) >> first_, h_ - 1);
      for (int x = 0; x < width_; ++x) ++counts_[static_cast<size_t>(ty) * w_ + std::min(x >> first_, w_ - 1)];
    }
  }
  CoarseLevels finish() {
    std::vector<CoarseLevels::Level> levels(1);
    CoarseLevels::Level& top = levels[0];
    top.width = w_, top.height = h_;
    if (!whole_.empty()) {
      // The level-0 texels a texel covers: 2^first in each axis, the last column and row also
      // taking what is left over (level 0 itself: one, so its texels stay as read).
      const int span = 1 << first_;
      for (int ty = 0; ty < h_; ++ty) {
        const int ny = ty + 1 < h_ ? span : height_ - ty * span;
        for (int tx = 0; tx < w_; ++tx) {
          const int nx = tx + 1 < w_ ? span : width_ - tx * span;
          const float inv = 1.0f / static_cast<float>(std::max(1, nx * ny));
          for (int c = 0; c < 4; ++c) whole_[4 * (static_cast<size_t>(ty) * w_ + tx) + c] *= inv;
        }
      }
      top.texels = std::move(whole_);
    } else {
      top.texels.resize(sums_.size());
      for (size_t i = 0; i < counts_.size(); ++i) {
        const double n = std::max<uint32_t>(1, counts_[i]);
        for (int c = 0; c < 4; ++c) top.texels[4 * i + c] = static_cast<float>(sums_[4 * i + c] / n);
      }
    }
    return finish_coarser(std::move(levels));
  }
  size_t held_bytes() const { return held_bytes(width_, height_, first_); }

 private:
  template <class T>
  void add_rows_to(T* sums, int y, int rows, const float* data) {
    for (int j = 0; j < rows; ++j) {
      const int ty = std::min((y + j) >> first_, h_ - 1);
      for (int x = 0; x < width_; ++x) {
        const int tx = std::min(x >> first_, w_ - 1);
        const float* p = data + (static_cast<size_t>(j) * width_ + x) * channels_;
        T* t = &sums[4 * (static_cast<size_t>(ty) * w_ + tx)];
        if (channels_ >= 3) {
          t[0] += p[0], t[1] += p[1], t[2] += p[2], t[3] += channels_ >= 4 ? p[3] : 1.0f;
        } else {
          t[0] += p[0], t[1] += p[0], t[2] += p[0], t[3] += channels_ == 2 ? p[1] : 1.0f;
        }
      }
    }
  }
  CoarseLevels finish_coarser(std::vector<CoarseLevels::Level> levels) const {
    while (levels.back().width > 1 || levels.back().height > 1) {
      const CoarseLevels::Level& fine = levels.back();
      CoarseLevels::Level coarse;
      coarse.width = std::max(1, fine.width / 2), coarse.height = std::max(1, fine.height / 2);
      coarse.texels.assign(4 * static_cast<size_t>(coarse.width) * coarse.height, 0.0f);
      std::vector<int> n(static_cast<size_t>(coarse.width) * coarse.height, 0);
      for (int y = 0; y < fine.height; ++y) {
        const int cy = std::min(y / 2, coarse.height - 1);
        for (int x = 0; x < fine.width; ++x) {
          const int cx = std::min(x / 2, coarse.width - 1);
          const size_t ci = static_cast<size_t>(cy) * coarse.width + cx;
          for (int c = 0; c < 4; ++c) coarse.texels[4 * ci + c] += fine.texels[4 * (static_cast<size_t>(y) * fine.width + x) + c];
          ++n[ci];
        }
      }
      for (size_t i = 0; i < n.size(); ++i) {
        for (int c = 0; c < 4; ++c) coarse.texels[4 * i + c] /= static_cast<float>(n[i]);
      }
      levels.push_back(std::move(coarse));
    }
    return CoarseLevels(first_, width_, height_, std::move(levels));
  }
  static int dim(int n, int level) { return std::max(1, n >> level); }
  int width_, height_, channels_;
  int first_ = 0, w_ = 0, h_ = 0;
  std::vector<float> whole_;  // the first held level's sums, where it is level 0 or large
  std::vector<double> sums_;
  std::vector<uint32_t> counts_;
};

}  // namespace pt
