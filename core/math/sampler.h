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
#include "core/util/names.h"

namespace pt {

enum class SamplerKind : uint8_t { kIndependent, kSobol };
inline constexpr NameTable<SamplerKind, 2> kSamplerNames{
    "sampler", {{{SamplerKind::kSobol, "sobol"}, {SamplerKind::kIndependent, "independent"}}}};

namespace sobol_detail {

inline uint32_t reverse_bits(uint32_t x) {
  x = __builtin_bswap32(x);  // bytes in one instruction, then bits within the bytes
  x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
  x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
  return ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
}
// Two 32-bit reversals in one 64-bit one: the result holds reverse_bits(lo) high, reverse_bits(hi) low.
inline uint64_t reverse_bits_pair(uint32_t hi, uint32_t lo) {
  uint64_t x = __builtin_bswap64((uint64_t{hi} << 32) | lo);
  x = ((x >> 1) & 0x5555555555555555ull) | ((x & 0x5555555555555555ull) << 1);
  x = ((x >> 2) & 0x3333333333333333ull) | ((x & 0x3333333333333333ull) << 2);
  return ((x >> 4) & 0x0f0f0f0f0f0f0f0full) | ((x & 0x0f0f0f0f0f0f0f0full) << 4);
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
// The same on an index already bit-reversed (a sampler reverses its sample index once).
inline uint32_t owen_scramble_reversed(uint32_t reversed, uint32_t seed) {
  return reverse_bits(laine_karras(reversed, seed));
}
// The first two Sobol dimensions: van der Corput, and the dimension with generator x + 1 (its
// matrix is Pascal's triangle mod 2). The second is linear over GF(2), so it is the XOR of four
// byte-indexed tables: a shuffled index has all 32 bits set and a bit-serial loop would run 32 times.
inline uint32_t sobol_dim0(uint32_t i) { return reverse_bits(i); }
constexpr uint32_t sobol_dim1_serial(uint32_t i) {
  uint32_t r = 0;
  for (uint32_t v = 1u << 31; i; i >>= 1, v ^= v >> 1) {
    if (i & 1u) r ^= v;
  }
  return r;
}
// Stored bit-reversed: the scramble works on reversed bits, and reversal is linear too.
struct SobolDim1Table {
  uint32_t t[4][256];
  constexpr SobolDim1Table() : t{} {
    for (int b = 0; b < 4; ++b) {
      for (uint32_t x = 0; x < 256; ++x) {
        uint32_t v = sobol_dim1_serial(x << (8 * b)), r = 0;
        for (int k = 0; k < 32; ++k) r |= ((v >> k) & 1u) << (31 - k);
        t[b][x] = r;
      }
    }
  }
};
inline constexpr SobolDim1Table kSobolDim1Reversed{};
inline uint32_t sobol_dim1_reversed(uint32_t i) {
  return kSobolDim1Reversed.t[0][i & 255u] ^ kSobolDim1Reversed.t[1][(i >> 8) & 255u] ^
         kSobolDim1Reversed.t[2][(i >> 16) & 255u] ^ kSobolDim1Reversed.t[3][i >> 24];
}
inline uint32_t sobol_dim1(uint32_t i) { return reverse_bits(sobol_dim1_reversed(i)); }
inline float to_unit(uint32_t x) { return static_cast<float>(x >> 8) * 0x1p-24f; }

}  // namespace sobol_detail

class Sampler {
 public:
  Sampler(SamplerKind kind, uint64_t seed, uint64_t pixel, uint32_t sample)
      : kind_(kind),
        sample_reversed_(sobol_detail::reverse_bits(sample)),
        base_sample_(sample),
        pixel_seed_(hash_combine(seed, pixel)) {
    // Only the independent kind draws from the stream: seeding it is a tenth of the camera ray's cost.
    if (kind_ == SamplerKind::kIndependent) rng_.seed(hash_combine(pixel_seed_, sample), pixel_seed_);
  }

  // Splitting: continuation k of `count` that share this sample's first vertex. Each draws the
  // dimensions from `dimension` (dimension() at the split) on, at index sample * count + k of
  // sequences of their own (the dimension seeds are salted, so they never repeat the points an
  // unsplit sample draws there): the count continuations of one sample are an aligned block of
  // one Owen-scrambled Sobol sequence, stratified among themselves and with the pixel's other
  // samples (Burley 2020: the index shuffle maps aligned power-of-two blocks to aligned blocks).
  uint64_t dimension() const { return dimension_; }
  void split(uint64_t dimension, uint32_t k, uint32_t count) {
    dimension_ = dimension | kSplitSalt;
    sample_reversed_ = sobol_detail::reverse_bits(base_sample_ * count + k);
    if (kind_ == SamplerKind::kIndependent) {
      rng_.seed(hash_combine(hash_combine(pixel_seed_, base_sample_), kSplitSalt + k), pixel_seed_);
    }
  }

  float next1d() {
    if (kind_ == SamplerKind::kIndependent) return rng_.next_float();
    using namespace sobol_detail;
    uint64_t h = dimension_seed();
    uint32_t seed = static_cast<uint32_t>(h);
    uint32_t index = owen_scramble_reversed(sample_reversed_, seed);
    // owen_scramble(sobol_dim0(i)) with the two reversals that cancel left out.
    return to_unit(reverse_bits(laine_karras(index, seed ^ 0xa511e9b3u)));
  }
  Vec2f next2d() {
    if (kind_ == SamplerKind::kIndependent) {
      float a = rng_.next_float();
      return {a, rng_.next_float()};
    }
    using namespace sobol_detail;
    uint64_t h = dimension_seed();
    uint32_t seed = static_cast<uint32_t>(h);
    uint32_t index = owen_scramble_reversed(sample_reversed_, seed);
    // owen_scramble(sobol_dim0(index)) and owen_scramble(sobol_dim1(index)) without the reversals
    // that cancel: the scramble hashes reversed bits, and dim 0 is the reversed index itself.
    uint32_t s = static_cast<uint32_t>(h >> 32);
    const uint64_t both = reverse_bits_pair(laine_karras(index, s), laine_karras(sobol_dim1_reversed(index), s ^ 0x68bc21ebu));
    return {to_unit(static_cast<uint32_t>(both)), to_unit(static_cast<uint32_t>(both >> 32))};
  }

 private:
  // Seeds of the next dimension's scrambles: one multiply-xorshift round of (pixel seed, dimension)
  // instead of a full 64-bit finaliser. The pixel seed is already a full hash, and every use goes
  // through the Laine-Karras hash, so one round is enough to separate neighbouring dimensions.
  uint64_t dimension_seed() {
    uint64_t h = pixel_seed_ ^ (++dimension_ * 0x9e3779b97f4a7c15ULL);
    h *= 0xd6e8feb86659fd93ULL;
    return h ^ (h >> 32);
  }
  static constexpr uint64_t kSplitSalt = uint64_t{1} << 40;
  SamplerKind kind_;
  uint32_t sample_reversed_;  // the sample's index in its sequence, bit-reversed
  uint32_t base_sample_;
  uint64_t pixel_seed_;
  uint64_t dimension_ = 0;
  Pcg32 rng_;
};

}  // namespace pt
