// The binary BVH collapsed into 8-wide nodes with their triangle packs (see bvh_build.h).
#include <tbb/task_group.h>

#include <array>
#include <atomic>
#include <cstring>
#include <limits>

#include "core/accel/bvh_build.h"
#include "core/geometry/geometry.h"
#include "core/util/error.h"

namespace pt::bvh {
namespace {

// The collapse runs in two passes over the binary tree: the first chooses each wide node's children
// and sums the blocks (and sphere slots) of every subtree, so that the second can write all
// subtrees in parallel, each at its final place in one array allocated once.
class Collapser {
 public:
  Collapser(const Bvh2& tree, const Geometry& scene, PackLayout layout, const BuildOptions& options, WideBvh& out)
      : tree_(tree), scene_(scene), layout_(layout), options_(options), out_(out), sizes_(tree.nodes.size()) {}

  void run() {
    if (options_.collapse_node_cost > 0 && !tree_.nodes.empty()) plan();
    Size total = measure(0, 0);
    if (total.blocks > kFirstMask) throw Error("bvh: scene too large for the node encoding");
    out_.blocks.resize(total.blocks);
    out_.spheres.resize(total.spheres);
    out_.depth = total.depth;
    out_.root = total.float_node ? kFloatNodeBit : 0u;
    emit(0, 0, 0, 0);
    out_.nodes = nodes_.load();
    out_.float_nodes = float_nodes_.load();
    out_.packs = packs_.load();
  }

 private:
  struct Size {
    uint32_t blocks = 0, spheres = 0;
    int depth = 0;
    bool float_node = false;  // this subtree's wide node keeps float boxes
    size_t prims = 0;
  };
  struct Children {
    uint32_t index[kWidth];
    int n = 0;
  };

  // The SAH cost of a leaf: its packs, two at a time where the kernels test pairs.
  float leaf_cost(const Node2& n) const {
    uint32_t packs = (n.count + 3) / 4;
    float pair = options_.pack_pair_cost;
    float cost = pair < 2.0f ? float(packs / 2) * pair + float(packs % 2) : float(packs);
    return n.box.surface_area() * cost;
  }

  // Which binary nodes become wide nodes, by dynamic programming over the binary tree (Ylitie,
  // Karras and Laine, HPG 2017, section 4): dist(n, j) is the least SAH cost of covering n's
  // subtree with at most j children of one wide node, each a leaf or a wide node of its own;
  // a wide node at n costs area(n) * collapse_node_cost plus the best split of its eight slots
  // between n's two children. Binary leaves stay leaves.
  void plan() {
    const size_t count = tree_.nodes.size();
    dist_.resize(count);
    split_.resize(count);
    for (size_t i = count; i-- > 0;) {
      const Node2& n = tree_.nodes[i];
      auto& d = dist_[i];
      auto& k = split_[i];
      if (n.leaf()) {
        float c = leaf_cost(n);
        for (int j = 0; j <= kWidth; ++j) d[j] = c, k[j] = 0;
        continue;
      }
      const auto& l = dist_[i + 1];
      const auto& r = dist_[n.offset];
      // As a wide node of its own: the best split of eight slots (k[0] keeps it).
      float best = std::numeric_limits<float>::infinity();
      for (int a = 1; a < kWidth; ++a) {
        float c = l[a] + r[kWidth - a];
        if (c < best) best = c, k[0] = static_cast<uint8_t>(a);
      }
      float own = n.box.surface_area() * options_.collapse_node_cost + best;
      d[0] = d[1] = own;
      k[1] = 0;
      for (int j = 2; j <= kWidth; ++j) {
        d[j] = own;
        k[j] = 0;
        for (int a = 1; a < j; ++a) {
          float c = l[a] + r[j - a];
          if (c < d[j]) d[j] = c, k[j] = static_cast<uint8_t>(a);
        }
      }
    }
  }

  // The children plan() chose for up to j slots of binary node n.
  void collect(uint32_t n, int j, Children& c) const {
    int a = split_[n][j];
    if (a == 0) {
      c.index[c.n++] = n;
      return;
    }
    collect(n + 1, a, c);
    collect(tree_.nodes[n].offset, j - a, c);
  }

  // The children of the wide node over binary node `index`: as plan() chose them, or greedily,
  // always opening the child with the largest surface area, until eight children are gathered or
  // only leaves remain (Wald, Benthin and Boulos 2008).
  Children gather(uint32_t index) const {
    Children c;
    const Node2& root = tree_.nodes[index];
    if (root.leaf()) {
      c.index[c.n++] = index;  // a root that is itself a leaf still gets a wide node above it
      return c;
    }
    if (!split_.empty()) {
      int a = split_[index][0];
      collect(index + 1, a, c);
      collect(root.offset, kWidth - a, c);
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

  // Whether the wide node over these children keeps float boxes (BuildOptions::float_node_growth
  // and float_node_prims): quantised, each child's box grows outward to the node's grid, which is
  // fine where the children are comparable in size to the node, and useless for a child much
  // smaller than one step of it.
  bool wants_float_node(const Children& c, size_t prims) const {
    if (prims >= options_.float_node_prims || tree_.prims.size() <= options_.float_tree_prims) return true;
    BBox boxes[kWidth];
    uint32_t refs[kWidth] = {};
    for (int i = 0; i < c.n; ++i) boxes[i] = tree_.nodes[c.index[i]].box;
    WideNode q;
    try {
      q = make_wide_node(boxes, refs, c.n);
    } catch (const Error&) {
      return true;  // beyond the quantised encoding (not conservatively representable)
    }
    // Child by child: SAH would weigh a child's growth by its area relative to the node's, which
    // is negligible for a small model under a huge ground; but the camera looks at the model, and
    // there every ray near it would enter its grown box.
    for (int i = 0; i < c.n; ++i) {
      if (q.child_box(i).surface_area() > (1.0f + options_.float_node_growth) * boxes[i].surface_area()) return true;
    }
    return false;
  }

  Size measure(uint32_t index, int depth) {
    Children c = gather(index);
    Size s;
    Size sub[kWidth];
    for_inner(c, depth < kParallelLevels, tree_, [&](int i) { sub[i] = measure(c.index[i], depth + 1); });
    for (int i = 0; i < c.n; ++i) {
      const Node2& n = tree_.nodes[c.index[i]];
      s.prims += n.leaf() ? n.count : sub[i].prims;
    }
    s.float_node = wants_float_node(c, s.prims);
    s.blocks = s.float_node ? kFloatNodeBlocks : kNodeBlocks;
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
    const bool float_node = sizes_[index].float_node;
    if (float_node) float_nodes_.fetch_add(1, std::memory_order_relaxed);
    BBox boxes[kWidth];
    uint32_t refs[kWidth];
    uint32_t next = at + (float_node ? kFloatNodeBlocks : kNodeBlocks);
    for (int i = 0; i < c.n; ++i) {
      const Node2& n = tree_.nodes[c.index[i]];
      boxes[i] = n.box;
      if (!n.leaf()) continue;
      if (sphere_leaf(n)) {
        refs[i] = leaf_ref(true, n.count, sphere_at);
        for (uint32_t k = 0; k < n.count; ++k) out_.spheres[sphere_at + k] = tree_.prims[n.offset + k].index;
        sphere_at += n.count;
      } else {
        uint32_t packs = (n.count + 3) / 4;
        refs[i] = leaf_ref(false, packs, next);
        write_packs(n, next);
        next += packs * kPackBlocks;
        packs_.fetch_add(packs, std::memory_order_relaxed);
      }
    }
    uint32_t child_at[kWidth], child_sphere_at[kWidth];
    for (int i = 0; i < c.n; ++i) {
      if (tree_.nodes[c.index[i]].leaf()) continue;
      const Size& sub = sizes_[c.index[i]];
      child_at[i] = next;
      refs[i] = next | (sub.float_node ? kFloatNodeBit : 0u);
      child_sphere_at[i] = sphere_at;
      next += sub.blocks;
      sphere_at += sub.spheres;
    }
    if (float_node) {
      WideNodeF node = make_float_node(boxes, refs, c.n);
      std::memcpy(out_.blocks.data() + at, &node, sizeof(node));
    } else {
      WideNode node = make_wide_node(boxes, refs, c.n);
      std::memcpy(out_.blocks.data() + at, &node, sizeof(node));
    }
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
        if (k >= n.count) {
          // NaN corners: every test rejects the lane, and the watertight one at its early exit.
          for (int row = 0; row < 9; ++row) pack.v[row][lane] = std::numeric_limits<float>::quiet_NaN();
          continue;
        }
        uint32_t tri = tree_.prims[n.offset + k].index;
        pack.prim[lane] = tri;
        Vec3f rows[3] = {mesh.vertex(tri, 0), mesh.vertex(tri, 1), mesh.vertex(tri, 2)};
        if (layout_ == PackLayout::kEdges) {
          rows[1] = rows[1] - rows[0];
          rows[2] = rows[2] - rows[0];
        }
        for (int row = 0; row < 3; ++row) {
          for (int axis = 0; axis < 3; ++axis) pack.v[3 * row + axis][lane] = rows[row][axis];
        }
      }
      std::memcpy(out_.blocks.data() + at + p * kPackBlocks, &pack, sizeof(pack));
    }
    if (out_.pairs) pair_packs(at, (n.count + 3) / 4);
  }

  // The packs at block `at` rewritten as pairs (TriPair; the last of an odd count stays a TriPack).
  void pair_packs(uint32_t at, uint32_t packs) {
    for (uint32_t k = 0; k + 1 < packs; k += 2) {
      TriPack two[2];
      std::memcpy(two, out_.blocks.data() + at + k * kPackBlocks, sizeof(two));
      TriPair pair = pair_of(two[0], two[1]);
      std::memcpy(out_.blocks.data() + at + k * kPackBlocks, &pair, sizeof(pair));
    }
  }

  // Wide levels near the root whose subtrees are measured and written as parallel tasks (8^3 tasks).
  static constexpr int kParallelLevels = 3;

  const Bvh2& tree_;
  const Geometry& scene_;
  PackLayout layout_;
  const BuildOptions& options_;
  WideBvh& out_;
  std::vector<Size> sizes_;  // per binary node that becomes a wide node
  // plan()'s tables per binary node: dist(n, j) for j = 1..8 (dist_[n][0]: n as a wide node) and
  // the slots its first child takes (0: n is one child itself; split_[n][0]: n's own wide node).
  std::vector<std::array<float, kWidth + 1>> dist_;
  std::vector<std::array<uint8_t, kWidth + 1>> split_;
  std::atomic<size_t> nodes_{0}, float_nodes_{0}, packs_{0};
};

}  // namespace

WideNode make_wide_node(const BBox* boxes, const uint32_t* refs, int n) {
  WideNode node;
  BBox all;
  for (int i = 0; i < n; ++i) all.expand(boxes[i]);
  for (int axis = 0; axis < 3; ++axis) {
    float origin = n > 0 ? all.lo[axis] : 0.0f;
    double extent = n > 0 ? static_cast<double>(all.hi[axis]) - origin : 0.0;
    // The smallest power of two with 255 steps covering the extent; beyond 2^119, 255 * 2^e would
    // overflow a float. From -126 down the scale would be subnormal, where q * 2^e is no longer exact.
    int e = -126;
    if (extent > 0.0) e = std::max(e, static_cast<int>(std::ceil(std::log2(extent / 255.0))));
    while (e > -126 && 255.0 * std::ldexp(1.0, e - 1) >= extent) --e;
    while (255.0 * std::ldexp(1.0, e) < extent) ++e;
    if (e > 119) throw Error("bvh: scene extent beyond the node encoding");
    node.origin[axis] = origin;
    node.exponent[axis] = static_cast<int8_t>(e);
  }
  for (int i = 0; i < kWidth; ++i) {
    node.child[i] = i < n ? refs[i] : kEmptyChild;
    for (int axis = 0; axis < 3; ++axis) {
      node.q[2 * axis][i] = 0;
      node.q[2 * axis + 1][i] = 0;
    }
    if (i >= n) continue;
    node.valid |= static_cast<uint8_t>(1u << i);
    for (int axis = 0; axis < 3; ++axis) {
      double step = std::ldexp(1.0, node.exponent[axis]);
      double lo = (static_cast<double>(boxes[i].lo[axis]) - node.origin[axis]) / step;
      double hi = (static_cast<double>(boxes[i].hi[axis]) - node.origin[axis]) / step;
      int qlo = static_cast<int>(std::clamp(std::floor(lo), 0.0, 255.0));
      int qhi = static_cast<int>(std::clamp(std::ceil(hi), 0.0, 255.0));
      // Round outward in the arithmetic traversal uses: q = 0 decodes to the origin (<= every lower
      // plane) and q = 255 to at least the node's upper plane, so both loops end.
      node.q[2 * axis][i] = static_cast<uint8_t>(qlo);
      while (qlo > 0 && node.plane(2 * axis, i) > boxes[i].lo[axis]) node.q[2 * axis][i] = static_cast<uint8_t>(--qlo);
      node.q[2 * axis + 1][i] = static_cast<uint8_t>(qhi);
      while (qhi < 255 && node.plane(2 * axis + 1, i) < boxes[i].hi[axis]) {
        node.q[2 * axis + 1][i] = static_cast<uint8_t>(++qhi);
      }
      if (node.plane(2 * axis, i) > boxes[i].lo[axis] || node.plane(2 * axis + 1, i) < boxes[i].hi[axis]) {
        throw Error("bvh: a child box cannot be quantised conservatively");
      }
    }
  }
  return node;
}

WideNodeF make_float_node(const BBox* boxes, const uint32_t* refs, int n) {
  WideNodeF node;
  for (int i = 0; i < kWidth; ++i) {
    node.child[i] = i < n ? refs[i] : kEmptyChild;
    for (int axis = 0; axis < 3; ++axis) {
      node.plane[2 * axis][i] = i < n ? boxes[i].lo[axis] : kInf;
      node.plane[2 * axis + 1][i] = i < n ? boxes[i].hi[axis] : -kInf;
    }
  }
  return node;
}

TriPair pair_of(const TriPack& first, const TriPack& second) {
  TriPair pair;
  const TriPack* two[2] = {&first, &second};
  for (int h = 0; h < 2; ++h) {
    for (int lane = 0; lane < 4; ++lane) {
      for (int row = 0; row < 9; ++row) pair.v[row][4 * h + lane] = two[h]->v[row][lane];
      pair.prim[4 * h + lane] = two[h]->prim[lane];
    }
  }
  return pair;
}

WideBvh collapse_to_wide(const Bvh2& tree, const Geometry& scene, PackLayout layout, const BuildOptions& options,
                         bool pairs) {
  WideBvh out;
  out.pairs = pairs;
  if (tree.nodes.empty()) return out;
  Collapser(tree, scene, layout, options, out).run();
  return out;
}

}  // namespace pt::bvh
