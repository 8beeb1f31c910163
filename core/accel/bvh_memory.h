// Memory for the BVH's node and triangle arrays. Incoherent rays touch a new page at nearly every
// node and leaf; with 4 KiB pages a scene of a million triangles spans ~20 000 pages, far more than
// the TLB holds, so most fetches also walk the page table. Arrays of 2 MiB or more are therefore
// aligned to 2 MiB and marked MADV_HUGEPAGE, so that the kernel can back them with transparent huge
// pages (when THP is "madvise" or "always"; elsewhere the hint is ignored and nothing changes).
#pragma once
#include <cstddef>
#include <cstdlib>
#include <new>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace pt::bvh {

constexpr size_t kHugePage = size_t(2) << 20;

template <class T>
struct HugePageAllocator {
  using value_type = T;
  HugePageAllocator() = default;
  template <class U>
  HugePageAllocator(const HugePageAllocator<U>&) {}

  T* allocate(size_t n) {
    size_t bytes = n * sizeof(T);
    size_t align = bytes >= kHugePage ? kHugePage : 64;
    void* p = nullptr;
    if (posix_memalign(&p, align, bytes) != 0) throw std::bad_alloc();
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    // Only whole huge pages can be backed; the tail of the array keeps small pages.
    if (align == kHugePage) madvise(p, bytes / kHugePage * kHugePage, MADV_HUGEPAGE);
#endif
    return static_cast<T*>(p);
  }
  void deallocate(T* p, size_t) { std::free(p); }
  template <class U>
  bool operator==(const HugePageAllocator<U>&) const { return true; }
};

}  // namespace pt::bvh
