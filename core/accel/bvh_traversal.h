// Traversal of the 8-wide BVH built in bvh_build.cpp and bvh_collapse.cpp, compiled once per instruction set: included
// only by bvh_accel_sse42.cpp, bvh_accel_avx2.cpp and bvh_accel_avx512.cpp, after their
// #pragma GCC target and their PT_BVH_ISA, which puts this copy in its own namespace.
//
// Per node, one slab test (Kay & Kajiya, "Ray Tracing Complex Scenes", SIGGRAPH 1986) of all eight
// children's decoded boxes against the current closest hit. Closest-hit rays visit the hit children
// nearest entry first: the others are pushed with their entry distance (one 64-bit key, distance
// above reference, so the few pushed ones are sorted as integers) and a pop discards them once a
// closer hit is known. Triangles are tested four at a time, or eight (a pair of packs) with AVX2.
// occluded() is the same loop without the ordering (its entries carry no distance): at each node it
// tests the leaf children first, each stopping at the first hit, and pushes the inner ones.
// In trees larger than the caches, children that wait on the stack are prefetched when pushed, and
// in trees larger than the L3, every child's first lines before a node's box test.
#pragma once
#include <bit>
#include <chrono>
#include <memory>

#include "core/accel/accel.h"
#include "core/accel/bvh_build.h"
#include "core/accel/bvh_kernels.h"
#include "core/accel/bvh_stack_keys.h"
#include "core/geometry/geometry.h"

// Counting hooks for experiments (nodes, leaves, pairs and singles: pack tests), empty unless an
// includer defines PT_BVH_COUNT(what) before including this header.
#ifndef PT_BVH_COUNT
#define PT_BVH_COUNT(x)
#endif
namespace pt::bvh {
inline namespace PT_BVH_ISA {
namespace traversal {


using bvh::PT_BVH_ISA::NodeTest;
using bvh::PackHits;
using bvh::TriPack;
using bvh::WideNode;
using bvh::WideNodeF;

using bvh::key_distance;
using bvh::keep_nearest_two;
using bvh::order_keys;
using bvh::stack_key;

// Depth of the binary tree is at most 40 SAH levels plus 32 halvings (bvh_build.cpp), and each wide
// level pushes at most seven children.
constexpr int kStackSize = 7 * 72 + 8;

// The top level of an instanced scene (bvh_two_level.h) is this same tree over the instances' boxes,
// its leaves listing instances where a scene's leaves list spheres; trace_instances takes a ray into
// each listed instance's mesh and traverses that mesh's tree.
template <TriangleTest kTest>
struct InstanceLeaves;
template <TriangleTest kTest>
bool trace_instances(const InstanceLeaves<kTest>& leaves, uint32_t first, uint32_t count, const Ray& ray, Hit& hit,
                     bool any_hit);

template <TriangleTest kTest>
class BvhAccel final : public Accel {
 public:
  BvhAccel(const Geometry& scene, const bvh::BuildOptions& options) : scene_(scene) {
    auto start = std::chrono::steady_clock::now();
    bvh::Bvh2 tree = bvh::build_bvh2(bvh::make_prim_refs(scene), options, &scene.mesh());
    bvh_ = bvh::collapse_to_wide(tree, scene, bvh::kPackLayout<kTest>, options, kPairs);
    stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats_.nodes = bvh_.nodes;
    stats_.primitives = scene.mesh().triangle_count() + scene.spheres().size();
    stats_.bytes = bvh_.bytes();
    prefetch_ = bvh_.bytes() > kPrefetchMinBytes;
    prefetch_children_ = bvh_.bytes() > kPrefetchChildrenMinBytes;
  }

  // A top level: `refs` are instance boxes (PrimKind::kSphere, index = instance), whose leaves
  // `leaves` traces. `scene` holds no geometry of this tree's (it is only the tree's owner's).
  BvhAccel(const Geometry& scene, bvh::PrimRefs refs, const bvh::BuildOptions& options, const InstanceLeaves<kTest>* leaves)
      : scene_(scene), leaves_(leaves) {
    bvh::Bvh2 tree = bvh::build_bvh2(std::move(refs), options);
    bvh_ = bvh::collapse_to_wide(tree, scene, bvh::kPackLayout<kTest>, options, kPairs);
    stats_.nodes = bvh_.nodes;
    stats_.bytes = bvh_.bytes();
  }

  std::optional<Hit> intersect(const Ray& ray) const override {
    Hit hit;
    bool found = traverse<false>(ray, hit);
    if (!found) return std::nullopt;
    return hit;
  }

  bool occluded(const Ray& ray) const override {
    Hit hit;
    bool found = traverse<true>(ray, hit);
    return found;
  }

  AccelStats stats() const override { return stats_; }
  std::string name() const override { return kTest == TriangleTest::kWatertight ? "bvh" : "bvh (mt)"; }
  // The primitive (sphere or instance) of each slot that sphere leaves refer to, in slot order.
  const std::vector<uint32_t>& leaf_slots() const { return bvh_.spheres; }

  // Closest hit (children visited nearest first), or with kAnyHit the first hit found.
  template <bool kAnyHit>
  bool traverse(const Ray& ray, Hit& hit) const {
    if (bvh_.blocks.empty()) return false;
    NodeTest test(ray);
    bvh::PackTests<kTest> tris(ray);
    hit.t = ray.tmax;
    bool found = false;
    uint64_t stack[kStackSize];
    int sp = 0;
    uint32_t cur = bvh_.root;
    alignas(32) float dist[bvh::kWidth];
    for (;;) {
      if (!bvh::is_leaf(cur)) {
        PT_BVH_COUNT(nodes);
        const uint32_t* child;
        uint32_t mask;
        if (bvh::is_float_node(cur)) {
          const WideNodeF& node = bvh_.float_node(cur);
          child = node.child;
          prefetch_children(child);
          mask = test(node, ray.tmin, hit.t, dist);
        } else {
          const WideNode& node = bvh_.node(cur);
          child = node.child;
          prefetch_children(child);
          mask = test(node, ray.tmin, hit.t, dist);
        }
        if constexpr (kAnyHit) {
          // Leaf children first: their packs follow this node in memory, and a hit among them ends
          // the search before any subtree is opened. Inner children are pushed unordered: most
          // shadow rays find no hit, and they have to visit every child anyway. So every child hit
          // here is prefetched before the first leaf test: the pushed nodes arrive while the packs
          // are tested, and the packs of the second leaf while the first is. Leaves and inner
          // children are told apart by the references' leaf bits, not by a branch per child (on
          // scan-10k's ambient-occlusion rays 20.7 instead of 23.9 mispredictions a ray).
          uint32_t leaf_bits = leaf_mask(child);
          uint32_t leaves = mask & leaf_bits;
          for (uint32_t m = mask & ~leaf_bits; m; m &= m - 1) {
            uint32_t c = child[std::countr_zero(m)];
            stack[sp++] = c;
            prefetch_node(c);
          }
          if (prefetch_) {
            for (uint32_t m = leaves; m; m &= m - 1) prefetch_leaf(child[std::countr_zero(m)]);
          }
          for (; leaves; leaves &= leaves - 1) {
            if (occluded_leaf(child[std::countr_zero(leaves)], ray, tris)) return true;
          }
        } else if (mask != 0) {
          int a = std::countr_zero(mask);
          mask &= mask - 1;
          if (mask == 0) {
            cur = child[a];
            continue;
          }
          int b = std::countr_zero(mask);
          mask &= mask - 1;
          uint64_t ka = stack_key(dist[a], child[a]), kb = stack_key(dist[b], child[b]);
          order_keys(ka, kb);
          if (mask == 0) {
            // The farther child is the next one popped unless a hit culls it; fetching it now
            // overlaps its cache misses with the nearer child's subtree.
            prefetch_ref(static_cast<uint32_t>(kb));
            stack[sp++] = kb;
            cur = static_cast<uint32_t>(ka);
            continue;
          }
          // Three or more: the nearest becomes current, the second nearest tops the stack and the
          // rest go under it as they come, by order_keys (no branch). The full insertion sort it
          // replaced mispredicted its data-dependent loop; after the nearest two subtrees, a hit
          // has mostly culled the rest anyway (in one process, 54 rows of 10k-124k triangles:
          // 0.987 of the time on primary rays, 0.990 on diffuse, 1 thread; 328k-1.3M neutral;
          // as alternated binaries within the noise).
          uint64_t near = ka, second = kb;
          int base = sp;
          do {
            int c = std::countr_zero(mask);
            mask &= mask - 1;
            stack[sp++] = keep_nearest_two(near, second, stack_key(dist[c], child[c]));
          } while (mask);
          stack[sp++] = second;
          cur = static_cast<uint32_t>(near);
          if (prefetch_) {
            for (int j = base; j < sp; ++j) prefetch_ref(static_cast<uint32_t>(stack[j]));
          }
          continue;
        }
      } else if (cur != bvh::kEmptyChild) {
        // Only closest-hit traversal makes a leaf current (any-hit tests leaves from their node);
        // the root is always a node. So any-hit has no such call, which would only be dead code.
        if constexpr (!kAnyHit) found |= intersect_leaf(cur, ray, tris, hit);
      }
      // Pop the next subtree that may still hold a closer hit (any-hit entries carry no distance).
      for (;;) {
        if (sp == 0) return found;
        uint64_t k = stack[--sp];
        if (kAnyHit || key_distance(k) <= hit.t) {
          cur = static_cast<uint32_t>(k);
          break;
        }
      }
    }
  }

 private:
  // Traversal of incoherent rays waits mostly on cache misses for nodes and packs (perf on the scan
  // mesh: about half the samples sit on the first load of a node or a pack). Inline assembly on x86,
  // because GCC 12 deletes __builtin_prefetch in loops that do nothing else.
  // A tree of at most 2 MiB stays in the caches (a core's L2 is 1-2 MiB), where the prefetches cost
  // instructions and save no wait: without them scan-10k (0.5 MiB) took 0.93-0.97 of the time,
  // dense-20k and the dragon (0.9-1.2 MiB) 0.93-0.98, while the bunny (3.4 MiB) and dense-82k
  // (4 MiB) took up to 1.2x (docs/notes/bvh-history.md, 24). The top level of instances always
  // prefetches: its instances' trees are not in the caches.
  static constexpr size_t kPrefetchMinBytes = size_t(2) << 20;
  // The eight children's first lines before a node's box test (prefetch_children) pay where the
  // tree is larger than the L3 holds for it (32 MiB on the reference machine): on dense-1.3M
  // (57 MiB) and scan-1M (77 MiB) without them 1.05-1.2x the time. In a tree the L3 holds they
  // cost more than they save: sixteen prefetches a node, most for children the ray misses, that
  // take the L1's miss buffers and evict lines still in use (alternated, 1 thread: scan-100k, 7.8
  // MiB, under the ground 1.18 -> 1.02 of Embree's time on shadow rays, dense-82k without it 1.29
  // -> 1.08; dense-328k, 16 MiB, alike either way). docs/bvh.md, Traversal.
  static constexpr size_t kPrefetchChildrenMinBytes = size_t(16) << 20;
  bool prefetch_ = true;
  bool prefetch_children_ = true;
  static void prefetch(const char* p) {
#if defined(__x86_64__) || defined(__i386__)
    asm volatile("prefetcht0 %0" : : "m"(*p));
#else
    __builtin_prefetch(p);
#endif
  }
  // Every cache line of a node: a quantised one (96 bytes at a 32-byte boundary) spans exactly two,
  // a float one (224 bytes) four.
  void prefetch_node(uint32_t ref) const {
    if (!prefetch_) return;
    const char* p = reinterpret_cast<const char*>(bvh_.blocks.data() + bvh::node_block(ref));
    prefetch(p);
    prefetch(p + 64);
    if (bvh::is_float_node(ref)) {
      prefetch(p + 128);
      prefetch(p + 192);
    }
  }
  // Every cache line of a leaf's packs.
  void prefetch_leaf(uint32_t ref) const {
    if (!prefetch_) return;
    if (ref == bvh::kEmptyChild || (ref & bvh::kSphereBit)) return;
    const char* p = reinterpret_cast<const char*>(bvh_.blocks.data() + bvh::leaf_first(ref));
    const char* end = p + bvh::leaf_count(ref) * sizeof(TriPack);
    for (; p < end; p += 64) prefetch(p);
    prefetch(end - 1);
  }
  // The first two lines of every child, issued before the node's box test: the child the ray
  // descends into next is one of them, and its load no longer waits for the test to finish. A child
  // the ray misses costs two prefetches. (In-process A/B against no such prefetch: closest hit
  // 7-15% faster on 1M-triangle meshes; docs/notes/bvh-history.md, 16.)
  void prefetch_children(const uint32_t* child) const {
    if (!prefetch_children_) return;
    // Without a branch per child: on a cache-resident tree the branches (leaf or node, empty or
    // not) mispredicted more than the prefetches saved. Two lines for every child, an empty one's
    // reference (all ones) becoming block 0; a float node's third and fourth lines are left to the
    // hardware.
#if PT_BVH_AVX2
    __m256i c = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(child));
    __m256i empty = _mm256_cmpeq_epi32(c, _mm256_set1_epi32(-1));
    __m256i block = _mm256_andnot_si256(empty, _mm256_and_si256(c, _mm256_set1_epi32(static_cast<int>(bvh::kFirstMask))));
    __m256i offset = _mm256_slli_epi32(block, 5);  // sizeof(Block) == 32
    __m256i base = _mm256_set1_epi64x(reinterpret_cast<long long>(bvh_.blocks.data()));
    alignas(32) const char* address[bvh::kWidth];
    _mm256_store_si256(reinterpret_cast<__m256i*>(address),
                       _mm256_add_epi64(base, _mm256_cvtepu32_epi64(_mm256_castsi256_si128(offset))));
    _mm256_store_si256(reinterpret_cast<__m256i*>(address + 4),
                       _mm256_add_epi64(base, _mm256_cvtepu32_epi64(_mm256_extracti128_si256(offset, 1))));
    for (int i = 0; i < bvh::kWidth; ++i) {
      prefetch(address[i]);
      prefetch(address[i] + 64);
    }
#else
    const char* base = reinterpret_cast<const char*>(bvh_.blocks.data());
    for (int i = 0; i < bvh::kWidth; ++i) {
      uint32_t c = child[i] == bvh::kEmptyChild ? 0u : child[i];
      const char* p = base + size_t(c & bvh::kFirstMask) * sizeof(bvh::Block);
      prefetch(p);
      prefetch(p + 64);
    }
#endif
  }
  // Bit i: child i is a leaf (or empty: kEmptyChild has the leaf bit too).
  static uint32_t leaf_mask(const uint32_t* child) {
    static_assert(bvh::kLeafBit == 1u << 31);
#if PT_BVH_AVX2
    return static_cast<uint32_t>(_mm256_movemask_ps(_mm256_loadu_ps(reinterpret_cast<const float*>(child))));
#else
    uint32_t bits = 0;
    for (int i = 0; i < bvh::kWidth; ++i) bits |= (child[i] >> 31) << i;
    return bits;
#endif
  }
  // A pushed subtree's first four lines, whatever it is: all of a node (a float one has four), or
  // a leaf's first pack and a half (a sphere or instance leaf's index is not a block: four lines
  // prefetched for nothing, and no fault). Choosing by the reference's leaf bit was a branch on
  // data (in one process with the cmov ordering above, 0.99 of the time on closest-hit rays).
  void prefetch_ref(uint32_t ref) const {
    if (!prefetch_) return;
    const char* p = reinterpret_cast<const char*>(bvh_.blocks.data() + (ref & bvh::kFirstMask));
    prefetch(p);
    prefetch(p + 64);
    prefetch(p + 128);
    prefetch(p + 192);
  }

  // Where the triangle tests take packs in pairs (the eight-lane kernels), the leaves' packs are
  // stored paired (TriPair).
  static constexpr bool kPairs = bvh::PackTests<kTest>::kPairs;

  bool intersect_leaf(uint32_t ref, const Ray& ray, const bvh::PackTests<kTest>& tris, Hit& hit) const {
    uint32_t count = bvh::leaf_count(ref);
    PT_BVH_COUNT(leaves);
    if (ref & bvh::kSphereBit) return intersect_spheres(ref, ray, hit, false);
    bool found = false;
    uint32_t k = 0;
#if PT_BVH_AVX2
    // A pair of packs per eight-lane test while two remain (the lanes in the packs' order, so the
    // nearest hit and ties come out as one pack at a time gives them).
    for (; k + 1 < count; k += 2) {
      const bvh::TriPair& p = bvh_.pair(ref, k);
      PT_BVH_COUNT(pairs);
      bvh::LaneHits<8> h;
      uint32_t mask = tris.pair(p, hit.t, h);
      while (mask) {
        int lane = std::countr_zero(mask);
        mask &= mask - 1;
        if (h.t[lane] < hit.t) {
          hit = Hit{h.t[lane], kGeomTriangles, p.prim[lane], h.u[lane], h.v[lane]};
          found = true;
        }
      }
    }
#endif
    for (; k < count; ++k) {
      const TriPack& p = bvh_.pack(ref, k);
      PT_BVH_COUNT(singles);
      PackHits h;
      uint32_t mask = tris.one(p, hit.t, h);
      while (mask) {
        int lane = std::countr_zero(mask);
        mask &= mask - 1;
        if (h.t[lane] < hit.t) {
          hit = Hit{h.t[lane], kGeomTriangles, p.prim[lane], h.u[lane], h.v[lane]};
          found = true;
        }
      }
    }
    return found;
  }

  bool occluded_leaf(uint32_t ref, const Ray& ray, const bvh::PackTests<kTest>& tris) const {
    if (ref & bvh::kSphereBit) {
      Hit hit;
      hit.t = ray.tmax;
      return intersect_spheres(ref, ray, hit, true);
    }
    uint32_t count = bvh::leaf_count(ref);
    PT_BVH_COUNT(leaves);
    uint32_t k = 0;
#if PT_BVH_AVX2
    for (; k + 1 < count; k += 2) {
      PT_BVH_COUNT(pairs);
      bvh::LaneHits<8> h;
      if (tris.pair(bvh_.pair(ref, k), ray.tmax, h)) return true;
    }
#endif
    for (; k < count; ++k) {
      PT_BVH_COUNT(singles);
      PackHits h;
      if (tris.one(bvh_.pack(ref, k), ray.tmax, h)) return true;
    }
    return false;
  }

  [[gnu::noinline]] bool intersect_spheres(uint32_t ref, const Ray& ray, Hit& hit, bool any_hit) const {
    uint32_t first = bvh::leaf_first(ref), count = bvh::leaf_count(ref);
    if (leaves_) return trace_instances(*leaves_, first, count, ray, hit, any_hit);
    bool found = false;
    Ray r = ray;
    for (uint32_t i = 0; i < count; ++i) {
      uint32_t s = bvh_.spheres[first + i];
      const Sphere& sphere = scene_.spheres()[s];
      r.tmax = hit.t;
      float t;
      if (intersect_sphere(r, sphere.center, sphere.radius, t)) {
        hit = Hit{t, kGeomSpheres, s, 0.0f, 0.0f};
        found = true;
      }
    }
    return found;
  }

  const Geometry& scene_;
  const InstanceLeaves<kTest>* leaves_ = nullptr;  // a top level's instances, else none
  bvh::WideBvh bvh_;
  AccelStats stats_;
};

}  // namespace traversal

// The BVH with this instruction set's kernels.
inline std::unique_ptr<Accel> make_accel(const Geometry& scene, TriangleTest test, const BuildOptions& options) {
  if (test == TriangleTest::kWatertight) return std::make_unique<traversal::BvhAccel<TriangleTest::kWatertight>>(scene, options);
  return std::make_unique<traversal::BvhAccel<TriangleTest::kMollerTrumbore>>(scene, options);
}

}  // namespace PT_BVH_ISA
}  // namespace pt::bvh
