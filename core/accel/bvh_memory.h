// Memory for the BVH's node and triangle arrays. Incoherent rays touch a new page at nearly every
// node and leaf; with 4 KiB pages a scene of a million triangles spans ~20 000 pages, far more than
// the TLB holds, so most fetches also walk the page table. Arrays of 2 MiB or more are therefore
// aligned to 2 MiB and marked MADV_HUGEPAGE, so that the kernel can back them with transparent huge
// pages (when THP is "madvise" or "always"; elsewhere the hint is ignored and nothing changes).
#pragma once
#include <algorithm>
#include <cstddef>
#include <cstdlib>
#include <new>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace pt::bvh {

constexpr size_t kHugePage = size_t(2) << 20;

// `bytes` of memory (free it with std::free), aligned and marked for huge pages when that large.
// Besides the TLB, huge pages save page faults: the builder's arrays (references, nodes, the block
// array) span tens of megabytes each, and on this VM one 4 KiB page fault costs as much as binning a
// few hundred references (perf on a 1.3 M triangle build: ~20% of its time in page faults).
inline void* allocate_huge(size_t bytes) {
  size_t align = bytes >= kHugePage ? kHugePage : 64;
  void* p = nullptr;
  if (posix_memalign(&p, align, std::max<size_t>(bytes, 1)) != 0) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  // Only whole huge pages can be backed; the tail of the array keeps small pages.
  if (align == kHugePage) madvise(p, bytes / kHugePage * kHugePage, MADV_HUGEPAGE);
#endif
  return p;
}

// Also leaves elements uninitialised when a vector is resized (construct() without arguments does
// nothing), for trivially copyable types: a vector that is resized and then filled (in parallel)
// is not written twice. Every user writes each element before reading it.
template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) {}

  T* allocate(size_t n) { return static_cast<T*>(allocate_huge(n * sizeof(T))); }
  void deallocate(T* p, size_t) { std::free(p); }
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0 && std::is_trivially_copyable_v<U>) {
      return;  // default-initialised: left as it is
    } else {
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
    }
  }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const { return true; }
};

template <class T>
using HugeVector = std::vector<T, HugePageAllocator<T>>;

}  // namespace pt::bvh
