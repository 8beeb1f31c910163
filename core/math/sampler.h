// Per-sample random numbers. A Sampler is made for one (seed, pixel, sample index), so a pixel's
// samples never depend on which thread draws them or in what order.
//
// independent  PCG32 seeded from a hash of (seed, pixel, sample).
// sobol        Owen-scrambled, index-shuffled 2D Sobol points (Burley, "Practical Hash-based Owen
//              Scrambling", JCGT 2020): each pair of dimensions is a scrambled (0,2)-sequence over
//              the pixel's sample index, decorrelated from the other pairs by its own shuffle seed.
#pragma once
#include <cstdint>

#include "core/math/rng.h"
#include "core/math/vec.h"

namespace pt {

enum class SamplerKind : uint8_t { kIndependent, kSobol };

namespace sobol_detail {

inline uint32_t reverse_bits(uint32_t x) {
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
  x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
  return (x >> 16) | (x << 16);
}
// Laine-Karras style hash acting as a nested uniform scramble on bit-reversed input (Burley 2020).
inline uint32_t laine_karras(uint32_t x, uint32_t seed) {
  x += seed;
  x ^= x * 0x6c50b47cu;
  x ^= x * 0xb82f1e52u;
  x ^= x * 0xc7afe638u;
  x ^= x * 0x8d22f6e6u;
  return x;
}
inline uint32_t owen_scramble(uint32_t x, uint32_t seed) {
  return reverse_bits(laine_karras(reverse_bits(x), seed));
}
// The first two Sobol dimensions: van der Corput, and the dimension with generator x + 1.
inline uint32_t sobol_dim0(uint32_t i) { return reverse_bits(i); }
inline uint32_t sobol_dim1(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1) {
    if (i & 1u) r ^= v;
  }
  return r;
}
inline float to_unit(uint32_t x) { return static_cast<float>(x >> 8) * 0x1p-24f; }

}  // namespace sobol_detail

class Sampler {
 public:
  Sampler(SamplerKind kind, uint64_t seed, uint64_t pixel, uint32_t sample)
      : kind_(kind), sample_(sample), pixel_seed_(hash_combine(seed, pixel)),
        rng_(hash_combine(pixel_seed_, sample), pixel_seed_) {}

  float next1d() {
    if (kind_ == SamplerKind::kIndependent) return rng_.next_float();
    using namespace sobol_detail;
    uint32_t seed = static_cast<uint32_t>(hash_combine(pixel_seed_, dimension_++));
    uint32_t index = owen_scramble(sample_, seed);
    return to_unit(owen_scramble(sobol_dim0(index), seed ^ 0xa511e9b3u));
  }
  Vec2f next2d() {
    if (kind_ == SamplerKind::kIndependent) {
      float a = rng_.next_float();
      return {a, rng_.next_float()};
    }
    using namespace sobol_detail;
    uint64_t h = hash_combine(pixel_seed_, dimension_++);
    uint32_t seed = static_cast<uint32_t>(h);
    uint32_t index = owen_scramble(sample_, seed);
    return {to_unit(owen_scramble(sobol_dim0(index), static_cast<uint32_t>(h >> 32))),
            to_unit(owen_scramble(sobol_dim1(index), static_cast<uint32_t>(h >> 32) ^ 0x68bc21ebu))};
  }

 private:
  SamplerKind kind_;
  uint32_t sample_;
  uint64_t pixel_seed_;
  uint64_t dimension_ = 0;
  Pcg32 rng_;
};

}  // namespace pt
