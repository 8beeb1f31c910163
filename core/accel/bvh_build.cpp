// Binned-SAH construction of the binary BVH and its collapse into 8-wide nodes (see bvh_build.h).
#include "core/accel/bvh_build.h"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_group.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstring>

#include "core/geometry/geometry.h"
#include "core/util/error.h"

namespace pt::bvh {
namespace {

constexpr int kBins = 32;
// Ranges at least this large bin in parallel; subtrees at least this large build as separate tasks.
constexpr size_t kParallelBinning = 1 << 16;
constexpr size_t kParallelSubtree = 1 << 12;
// Below this depth SAH decides; deeper, ranges are halved by count, so the tree depth (and with it
// the traversal stack) stays bounded even on adversarial input.
constexpr int kSahDepthLimit = 40;

// SAH cost counts triangles in packs of four, the unit the leaf test works in (as Embree's
// builders do with their block size).
inline float blocks(uint32_t n) { return static_cast<float>((n + 3) / 4); }

struct Bin {
  BBox box, centroids;
  uint32_t count = 0;
  void add(const PrimRef& r) {
    box.expand(r.lo);
    box.expand(r.hi);
    centroids.expand(r.centroid());
    ++count;
  }
  void merge(const Bin& b) {
    box.expand(b.box);
    centroids.expand(b.centroids);
    count += b.count;
  }
};

struct Binning {
  std::array<std::array<Bin, kBins>, 3> bins;
};

struct BinMapping {
  Vec3f origin, scale;
  int bin(const Vec3f& c, int axis) const {
    int b = static_cast<int>((c[axis] - origin[axis]) * scale[axis]);
    return std::clamp(b, 0, kBins - 1);
  }
};

struct Bounds {
  BBox box, centroids;
  void add(const PrimRef& r) {
    box.expand(r.lo);
    box.expand(r.hi);
    centroids.expand(r.centroid());
  }
  void merge(const Bounds& b) {
    box.expand(b.box);
    centroids.expand(b.centroids);
  }
};

struct TmpNode {
  BBox box;
  uint32_t left = 0;   // inner: index of the left child (the right one is left + 1)
  uint32_t begin = 0, count = 0;  // leaf: range of refs
};

class Builder {
 public:
  Builder(std::vector<PrimRef>& refs, const BuildOptions& options)
      : refs_(refs), options_(options), nodes_(std::max<size_t>(1, 2 * refs.size())) {}

  void run() {
    Bounds root = bounds_of(0, static_cast<uint32_t>(refs_.size()));
    next_.store(1);
    build(0, 0, static_cast<uint32_t>(refs_.size()), root, 0);
  }

  // Rewrites the nodes, allocated in whatever order the tasks ran, in depth-first order.
  std::vector<Node2> flatten() const {
    std::vector<Node2> out;
    out.reserve(next_.load());
    flatten(0, out);
    return out;
  }

 private:
  Bounds bounds_of(uint32_t begin, uint32_t end) const {
    if (end - begin < kParallelBinning) {
      Bounds b;
      for (uint32_t i = begin; i < end; ++i) b.add(refs_[i]);
      return b;
    }
    return tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(begin, end, 4096), Bounds{},
        [&](const tbb::blocked_range<uint32_t>& r, Bounds b) {
          for (uint32_t i = r.begin(); i != r.end(); ++i) b.add(refs_[i]);
          return b;
        },
        [](Bounds a, const Bounds& b) {
          a.merge(b);
          return a;
        });
  }

  void bin_range(uint32_t begin, uint32_t end, const BinMapping& map, Binning& out) const {
    for (uint32_t i = begin; i < end; ++i) {
      Vec3f c = refs_[i].centroid();
      for (int axis = 0; axis < 3; ++axis) out.bins[axis][map.bin(c, axis)].add(refs_[i]);
    }
  }

  Binning bin(uint32_t begin, uint32_t end, const BinMapping& map) const {
    if (end - begin < kParallelBinning) {
      Binning b;
      bin_range(begin, end, map, b);
      return b;
    }
    return tbb::parallel_reduce(
        tbb::blocked_range<uint32_t>(begin, end, 8192), Binning{},
        [&](const tbb::blocked_range<uint32_t>& r, Binning b) {
          bin_range(r.begin(), r.end(), map, b);
          return b;
        },
        [](Binning a, const Binning& b) {
          for (int axis = 0; axis < 3; ++axis)
            for (int i = 0; i < kBins; ++i) a.bins[axis][i].merge(b.bins[axis][i]);
          return a;
        });
  }

  void make_leaf(uint32_t index, uint32_t begin, uint32_t end, const BBox& box) {
    TmpNode& n = nodes_[index];
    n.box = box;
    n.begin = begin;
    n.count = end - begin;
  }

  void split(uint32_t index, uint32_t begin, uint32_t mid, uint32_t end, const BBox& box, int depth) {
    uint32_t left = next_.fetch_add(2);
    TmpNode& n = nodes_[index];
    n.box = box;
    n.left = left;
    n.count = 0;
    Bounds lb = bounds_of(begin, mid), rb = bounds_of(mid, end);
    recurse(left, begin, mid, lb, left + 1, mid, end, rb, depth + 1);
  }

  void recurse(uint32_t li, uint32_t lbegin, uint32_t lend, const Bounds& lb, uint32_t ri, uint32_t rbegin,
               uint32_t rend, const Bounds& rb, int depth) {
    if (lend - lbegin + rend - rbegin >= kParallelSubtree) {
      tbb::parallel_invoke([&] { build(li, lbegin, lend, lb, depth); }, [&] { build(ri, rbegin, rend, rb, depth); });
    } else {
      build(li, lbegin, lend, lb, depth);
      build(ri, rbegin, rend, rb, depth);
    }
  }

  void build(uint32_t index, uint32_t begin, uint32_t end, const Bounds& bounds, int depth) {
    uint32_t n = end - begin;
    bool mixed = false;
    for (uint32_t i = begin + 1; i < end && !mixed; ++i) mixed = refs_[i].kind != refs_[begin].kind;
    if (n == 1 || (!mixed && n <= 2 && refs_[begin].kind == PrimKind::kTriangle)) {
      make_leaf(index, begin, end, bounds.box);
      return;
    }
    if (mixed && n <= static_cast<uint32_t>(options_.max_leaf)) {
      // A leaf holds one kind only, so a small mixed range splits by kind.
      auto mid = std::partition(refs_.begin() + begin, refs_.begin() + end,
                                [](const PrimRef& r) { return r.kind == PrimKind::kTriangle; });
      split(index, begin, static_cast<uint32_t>(mid - refs_.begin()), end, bounds.box, depth);
      return;
    }
    Vec3f extent = bounds.centroids.extent();
    if (depth >= kSahDepthLimit || max_component(extent) <= 0.0f) {
      // No spatial order left to exploit (or the depth guard): a leaf if it fits, else halve by count.
      if (!mixed && n <= static_cast<uint32_t>(options_.max_leaf)) {
        make_leaf(index, begin, end, bounds.box);
      } else {
        split(index, begin, begin + n / 2, end, bounds.box, depth);
      }
      return;
    }

    BinMapping map;
    map.origin = bounds.centroids.lo;
    for (int axis = 0; axis < 3; ++axis) {
      map.scale[axis] = extent[axis] > 0.0f ? kBins * (1.0f - 1e-6f) / extent[axis] : 0.0f;
    }
    Binning binning = bin(begin, end, map);

    // Sweep each axis from the right, then from the left, evaluating SAH at each of the kBins - 1
    // planes (Wald 2007, section 3).
    float best_cost = kInf;
    int best_axis = -1, best_plane = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (extent[axis] <= 0.0f) continue;
      const auto& bins = binning.bins[axis];
      std::array<float, kBins> right_cost{};
      BBox acc;
      uint32_t count = 0;
      for (int i = kBins - 1; i > 0; --i) {
        acc.expand(bins[i].box);
        count += bins[i].count;
        right_cost[i] = count ? acc.surface_area() * blocks(count) : kInf;
      }
      acc = BBox();
      count = 0;
      for (int i = 0; i < kBins - 1; ++i) {
        acc.expand(bins[i].box);
        count += bins[i].count;
        if (count == 0 || count == n) continue;
        float cost = acc.surface_area() * blocks(count) + right_cost[i + 1];
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_plane = i + 1;
        }
      }
    }
    float area = bounds.box.surface_area();
    float leaf_cost = blocks(n);
    float split_cost = options_.traversal_cost + (area > 0.0f ? best_cost / area : 0.0f);
    if (!mixed && n <= static_cast<uint32_t>(options_.max_leaf) && (best_axis < 0 || leaf_cost <= split_cost)) {
      make_leaf(index, begin, end, bounds.box);
      return;
    }
    if (best_axis < 0) {
      split(index, begin, begin + n / 2, end, bounds.box, depth);
      return;
    }
    auto mid = std::partition(refs_.begin() + begin, refs_.begin() + end, [&](const PrimRef& r) {
      return map.bin(r.centroid(), best_axis) < best_plane;
    });
    uint32_t m = static_cast<uint32_t>(mid - refs_.begin());
    // The child bounds come from the bins, which saw exactly the primitives on each side.
    Bounds lb, rb;
    const auto& bins = binning.bins[best_axis];
    for (int i = 0; i < kBins; ++i) {
      Bounds& side = i < best_plane ? lb : rb;
      side.box.expand(bins[i].box);
      side.centroids.expand(bins[i].centroids);
    }
    uint32_t left = next_.fetch_add(2);
    TmpNode& node = nodes_[index];
    node.box = bounds.box;
    node.left = left;
    node.count = 0;
    recurse(left, begin, m, lb, left + 1, m, end, rb, depth + 1);
  }

  void flatten(uint32_t index, std::vector<Node2>& out) const {
    const TmpNode& n = nodes_[index];
    size_t me = out.size();
    out.push_back(Node2{n.box, n.begin, n.count});
    if (n.count > 0) return;
    flatten(n.left, out);
    out[me].offset = static_cast<uint32_t>(out.size());
    flatten(n.left + 1, out);
  }

  std::vector<PrimRef>& refs_;
  const BuildOptions& options_;
  std::vector<TmpNode> nodes_;
  std::atomic<uint32_t> next_{0};
};

}  // namespace

std::vector<PrimRef> make_prim_refs(const Geometry& scene) {
  const Mesh& mesh = scene.mesh();
  const auto& spheres = scene.spheres();
  size_t tris = mesh.triangle_count();
  std::vector<PrimRef> refs(tris + spheres.size());
  tbb::parallel_for(tbb::blocked_range<size_t>(0, tris, 16384), [&](const tbb::blocked_range<size_t>& r) {
    for (size_t i = r.begin(); i != r.end(); ++i) {
      Vec3f a = mesh.vertex(i, 0), b = mesh.vertex(i, 1), c = mesh.vertex(i, 2);
      refs[i].lo = vmin(a, vmin(b, c));
      refs[i].hi = vmax(a, vmax(b, c));
      refs[i].index = static_cast<uint32_t>(i);
      refs[i].kind = PrimKind::kTriangle;
    }
  });
  for (size_t i = 0; i < spheres.size(); ++i) {
    BBox b = spheres[i].bounds();
    refs[tris + i] = PrimRef{b.lo, static_cast<uint32_t>(i), b.hi, PrimKind::kSphere};
  }
  return refs;
}

Bvh2 build_bvh2(std::vector<PrimRef> refs, const BuildOptions& options) {
  Bvh2 out;
  if (refs.empty()) return out;
  if (refs.size() >= (size_t(1) << 31)) throw Error("bvh: too many primitives");
  Builder builder(refs, options);
  builder.run();
  out.nodes = builder.flatten();
  out.prims = std::move(refs);
  return out;
}

namespace {

// The collapse runs in two passes over the binary tree: the first chooses each wide node's children
// and sums the blocks (and sphere slots) of every subtree, so that the second can write all
// subtrees in parallel, each at its final place in one array allocated once.
class Collapser {
 public:
  Collapser(const Bvh2& tree, const Geometry& scene, WideBvh& out)
      : tree_(tree), scene_(scene), out_(out), sizes_(tree.nodes.size()) {}

  void run() {
    Size total = measure(0, 0);
    if (total.blocks > kFirstMask) throw Error("bvh: scene too large for the node encoding");
    out_.blocks.resize(total.blocks);
    out_.spheres.resize(total.spheres);
    out_.depth = total.depth;
    emit(0, 0, 0, 0);
    out_.nodes = nodes_.load();
    out_.packs = packs_.load();
  }

 private:
  struct Size {
    uint32_t blocks = 0, spheres = 0;
    int depth = 0;
  };
  struct Children {
    uint32_t index[kWidth];
    int n = 0;
  };

  // Opens the binary subtree under `index` greedily, always expanding the child with the largest
  // surface area, until eight children are gathered or only leaves remain.
  Children gather(uint32_t index) const {
    Children c;
    const Node2& root = tree_.nodes[index];
    if (root.leaf()) {
      c.index[c.n++] = index;  // a root that is itself a leaf still gets a wide node above it
      return c;
    }
    c.index[c.n++] = index + 1;
    c.index[c.n++] = root.offset;
    while (c.n < kWidth) {
      int best = -1;
      float best_area = -1.0f;
      for (int i = 0; i < c.n; ++i) {
        const Node2& child = tree_.nodes[c.index[i]];
        if (!child.leaf() && child.box.surface_area() > best_area) {
          best_area = child.box.surface_area();
          best = i;
        }
      }
      if (best < 0) break;
      uint32_t opened = c.index[best];
      c.index[best] = opened + 1;
      c.index[c.n++] = tree_.nodes[opened].offset;
    }
    return c;
  }

  bool sphere_leaf(const Node2& n) const { return tree_.prims[n.offset].kind == PrimKind::kSphere; }

  template <class F>
  static void for_inner(const Children& c, bool parallel, const Bvh2& tree, F&& f) {
    if (!parallel) {
      for (int i = 0; i < c.n; ++i)
        if (!tree.nodes[c.index[i]].leaf()) f(i);
      return;
    }
    tbb::task_group group;
    for (int i = 0; i < c.n; ++i)
      if (!tree.nodes[c.index[i]].leaf()) group.run([&f, i] { f(i); });
    group.wait();
  }

  Size measure(uint32_t index, int depth) {
    Children c = gather(index);
    Size s;
    s.blocks = kNodeBlocks;
    Size sub[kWidth];
    for_inner(c, depth < kParallelLevels, tree_, [&](int i) { sub[i] = measure(c.index[i], depth + 1); });
    for (int i = 0; i < c.n; ++i) {
      const Node2& n = tree_.nodes[c.index[i]];
      if (n.leaf()) {
        if (sphere_leaf(n)) {
          s.spheres += n.count;
        } else {
          s.blocks += (n.count + 3) / 4 * kPackBlocks;
        }
      } else {
        s.blocks += sub[i].blocks;
        s.spheres += sub[i].spheres;
        s.depth = std::max(s.depth, sub[i].depth);
      }
      // Sums are checked against the encoding once, at the root; keep them from wrapping before that.
      s.blocks = std::min(s.blocks, kFirstMask + 1);
    }
    s.depth += 1;
    sizes_[index] = s;
    return s;
  }

  // Writes the wide node for `index` at block `at`, the packs of its leaf children after it, then the
  // subtrees of its inner children; sphere leaves take slots from `sphere_at` on.
  void emit(uint32_t index, uint32_t at, uint32_t sphere_at, int depth) {
    Children c = gather(index);
    nodes_.fetch_add(1, std::memory_order_relaxed);
    WideNode node;
    for (int i = 0; i < kWidth; ++i) {
      for (int axis = 0; axis < 3; ++axis) {
        node.bounds[2 * axis][i] = kInf;
        node.bounds[2 * axis + 1][i] = -kInf;
      }
      node.child[i] = kEmptyChild;
    }
    uint32_t next = at + kNodeBlocks;
    for (int i = 0; i < c.n; ++i) {
      const Node2& n = tree_.nodes[c.index[i]];
      for (int axis = 0; axis < 3; ++axis) {
        node.bounds[2 * axis][i] = n.box.lo[axis];
        node.bounds[2 * axis + 1][i] = n.box.hi[axis];
      }
      if (!n.leaf()) continue;
      if (sphere_leaf(n)) {
        node.child[i] = leaf_ref(true, n.count, sphere_at);
        for (uint32_t k = 0; k < n.count; ++k) out_.spheres[sphere_at + k] = tree_.prims[n.offset + k].index;
        sphere_at += n.count;
      } else {
        uint32_t packs = (n.count + 3) / 4;
        node.child[i] = leaf_ref(false, packs, next);
        write_packs(n, next);
        next += packs * kPackBlocks;
        packs_.fetch_add(packs, std::memory_order_relaxed);
      }
    }
    uint32_t child_at[kWidth], child_sphere_at[kWidth];
    for (int i = 0; i < c.n; ++i) {
      if (tree_.nodes[c.index[i]].leaf()) continue;
      const Size& sub = sizes_[c.index[i]];
      node.child[i] = child_at[i] = next;
      child_sphere_at[i] = sphere_at;
      next += sub.blocks;
      sphere_at += sub.spheres;
    }
    std::memcpy(out_.blocks.data() + at, &node, sizeof(node));
    for_inner(c, depth < kParallelLevels, tree_,
              [&](int i) { emit(c.index[i], child_at[i], child_sphere_at[i], depth + 1); });
  }

  static uint32_t leaf_ref(bool sphere, uint32_t count, uint32_t first) {
    if (first > kFirstMask || count > 15) throw Error("bvh: scene too large for the leaf encoding");
    return kLeafBit | (sphere ? kSphereBit : 0u) | (count << kCountShift) | first;
  }

  void write_packs(const Node2& n, uint32_t at) {
    const Mesh& mesh = scene_.mesh();
    for (uint32_t p = 0; p * 4 < n.count; ++p) {
      TriPack pack{};
      for (int lane = 0; lane < 4; ++lane) {
        uint32_t k = p * 4 + lane;
        pack.prim[lane] = kNoPrim;
        if (k >= n.count) continue;
        uint32_t tri = tree_.prims[n.offset + k].index;
        pack.prim[lane] = tri;
        for (int corner = 0; corner < 3; ++corner) {
          Vec3f v = mesh.vertex(tri, corner);
          for (int axis = 0; axis < 3; ++axis) pack.v[3 * corner + axis][lane] = v[axis];
        }
      }
      std::memcpy(out_.blocks.data() + at + p * kPackBlocks, &pack, sizeof(pack));
    }
  }

  // Wide levels near the root whose subtrees are measured and written as parallel tasks (8^3 tasks).
  static constexpr int kParallelLevels = 3;

  const Bvh2& tree_;
  const Geometry& scene_;
  WideBvh& out_;
  std::vector<Size> sizes_;  // per binary node that becomes a wide node
  std::atomic<size_t> nodes_{0}, packs_{0};
};

}  // namespace

WideBvh collapse_to_wide(const Bvh2& tree, const Geometry& scene) {
  WideBvh out;
  if (tree.nodes.empty()) return out;
  Collapser(tree, scene, out).run();
  return out;
}

}  // namespace pt::bvh
