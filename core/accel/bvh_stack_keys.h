// The keys closest-hit traversal (bvh_traversal.h) pushes for the subtrees it visits later, and how
// it orders them without branches on data.
#pragma once
#include <algorithm>
#include <bit>
#include <cstdint>

namespace pt::bvh {

// A pushed subtree: its entry distance in the high half (entry distances are >= tmin >= 0, whose
// float bits order like the values), its reference in the low half.
inline uint64_t stack_key(float t, uint32_t ref) { return (uint64_t(std::bit_cast<uint32_t>(t)) << 32) | ref; }
inline float key_distance(uint64_t key) { return std::bit_cast<float>(static_cast<uint32_t>(key >> 32)); }

// a, b = min(a, b), max(a, b) by conditional moves. Written as std::min and std::max, GCC 12 made
// each a branch, and which key is nearer is data: on dense-20k's diffuse rays a third of the
// two-child orderings swapped. With cmov, in one process over 54 rows of 10k-124k triangles, 0.97
// of the time on diffuse rays and 0.99 on primary (docs/bvh.md, Traversal).
inline void order_keys(uint64_t& a, uint64_t& b) {
#if defined(__x86_64__)
  // t is an in-out operand so that it gets a register of its own: as an input holding a's value,
  // GCC may give it a's register, which the first cmova overwrites.
  uint64_t t = a;
  asm("cmp %[b], %[a]\n\tcmova %[b], %[a]\n\tcmova %[t], %[b]" : [a] "+r"(a), [b] "+r"(b), [t] "+r"(t) : : "cc");
#else
  uint64_t low = std::min(a, b);
  b = std::max(a, b);
  a = low;
#endif
}

// With near <= second the two nearest keys so far, takes in k: near and second become the two
// nearest of the three, and the third is returned (to go under them on the stack).
inline uint64_t keep_nearest_two(uint64_t& near, uint64_t& second, uint64_t k) {
  order_keys(near, k);
  order_keys(second, k);
  return k;
}

}  // namespace pt::bvh
