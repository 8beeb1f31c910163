// PCG32 random numbers (O'Neill, "PCG: A Family of Simple Fast Space-Efficient Statistically Good
// Algorithms for Random Number Generation", 2014) and the hashing that seeds one stream per sample.
#pragma once
#include <cstdint>

namespace pt {

// A 64-bit mixer (the MurmurHash3 finaliser) so that nearby (seed, pixel, sample) give unrelated streams.
constexpr uint64_t mix64(uint64_t x) {
  x ^= x >> 33;
  x *= 0xff51afd7ed558ccdULL;
  x ^= x >> 33;
  x *= 0xc4ceb9fe1a85ec53ULL;
  x ^= x >> 33;
  return x;
}

constexpr uint64_t hash_combine(uint64_t a, uint64_t b) { return mix64(a ^ (mix64(b) + 0x9e3779b97f4a7c15ULL)); }

class Pcg32 {
 public:
  Pcg32() { seed(0x853c49e6748fea9bULL, 0xda3e39cb94b95bdbULL); }
  Pcg32(uint64_t state, uint64_t stream) { seed(state, stream); }
  void seed(uint64_t init_state, uint64_t stream) {
    state_ = 0;
    inc_ = (stream << 1u) | 1u;
    next_u32();
    state_ += init_state;
    next_u32();
  }
  uint32_t next_u32() {
    uint64_t old = state_;
    state_ = old * 6364136223846793005ULL + inc_;
    uint32_t xorshifted = static_cast<uint32_t>(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = static_cast<uint32_t>(old >> 59u);
    return (xorshifted >> rot) | (xorshifted << ((~rot + 1u) & 31));
  }
  // Uniform in [0, 1): 24 random bits, so the result is never rounded up to 1.
  float next_float() { return static_cast<float>(next_u32() >> 8) * 0x1p-24f; }
  double next_double() { return static_cast<double>(next_u32()) * 0x1p-32; }

 private:
  uint64_t state_ = 0, inc_ = 0;
};

}  // namespace pt
