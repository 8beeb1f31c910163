// Internals of the home-written BVH backend, exposed so the tests can check the invariants of what
// the builder produces. Two stages:
//  1. build_bvh2: a binary BVH over primitive boxes with a binned surface-area heuristic (Wald,
//     "On fast Construction of SAH-based Bounding Volume Hierarchies", IRT 2007), parallel with TBB,
//     stored as a flat array in depth-first order.
//  2. collapse_to_wide: the binary tree collapsed into 8-wide nodes (one AVX box test visits all eight
//     children), with the triangles copied into packs of four for SSE intersection, stored next to
//     the node that refers to them.
//     Which binary nodes become wide nodes is chosen by the SAH, by dynamic programming over the
//     binary tree (Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal on GPUs Through
//     Compressed Wide BVHs", HPG 2017); or greedily, as in Wald, Benthin and Boulos, "Getting Rid
//     of Packets", IRT 2008, and Dammertz et al., "Shallow Bounding Volume Hierarchies", EGSR 2008.
#pragma once
#include <bit>
#include <cstddef>
#include <cstdint>
#include <new>
#include <type_traits>
#include <vector>

#include "core/accel/bvh_memory.h"
#include "core/geometry/mesh.h"
#include "core/math/bbox.h"

namespace pt {
class Geometry;
}

namespace pt::bvh {

enum class PrimKind : uint32_t { kTriangle = 0, kSphere = 1 };

// One primitive as the builder sees it: its box and what it is (index into the scene's mesh or
// sphere list).
struct PrimRef {
  Vec3f lo;
  uint32_t index = 0;
  Vec3f hi;
  PrimKind kind = PrimKind::kTriangle;
  Vec3f centroid() const { return (lo + hi) * 0.5f; }
};

// Binning loads lo and hi as four floats each (with index and kind as the fourth).
static_assert(sizeof(Vec3f) == 12 && sizeof(PrimRef) == 32 && offsetof(PrimRef, hi) == 16);

using PrimRefs = HugeVector<PrimRef>;

PrimRefs make_prim_refs(const Geometry& scene);

// Binary node, depth-first: the left child of inner node i is i + 1, the right child is `offset`.
// A leaf holds `count` > 0 primitives starting at `offset` in Bvh2::prims.
struct Node2 {
  BBox box;
  uint32_t offset = 0;
  uint32_t count = 0;
  bool leaf() const { return count > 0; }
};

// HugeVector leaves these uninitialised when resized; the builder writes each before reading it.
static_assert(std::is_trivially_copyable_v<PrimRef> && std::is_trivially_copyable_v<Node2>);

struct Bvh2 {
  HugeVector<Node2> nodes;  // nodes[0] is the root
  PrimRefs prims;           // in leaf order; a leaf never mixes triangles and spheres
};

// With AVX2 the leaf test takes two packs of four triangles at a time in one eight-lane test
// (bvh_kernels.h), which costs about 1.2 one-pack tests; elsewhere packs are tested one at a time.
// The defaults follow the kernels chosen at start-up (bvh_isa.h), and the largest leaf the tree's
// size: with pairs, up to 8 primitives in trees of at most kSmallTreePrims and 16 above. Timed in
// one process (`pt bench rays --bvh-variant max_leaf=16`), leaves of up to 8 took 0.920 of
// Embree's time against 0.926 with 16 on 9 meshes of 10k-124k triangles (geometric mean of 54
// rows, the worst row 1.09 against 1.12), but 0.880 against 0.872 on 328k-1.3M
// (docs/notes/bvh-history.md, eleventh round).
float default_pack_pair_cost();
constexpr size_t kSmallTreePrims = size_t(1) << 18;
int default_max_leaf(size_t primitives);

struct BuildOptions {
  // Largest leaf (primitives; at most 15 packs fit the leaf encoding); 0: default_max_leaf of the
  // number of primitives built over.
  int max_leaf = 0;
  float traversal_cost = 1.0f;  // SAH cost of visiting a node, relative to one pack of 4 triangles
  float pack_pair_cost = default_pack_pair_cost();  // SAH cost of two packs of a leaf, relative to one
  // Spatial splits (Stich et al. 2009; with a mesh): the references they may add, as a fraction
  // of the input's; where they are tried (bvh_build.cpp: the children of the best object split
  // overlap by more than alpha of the root's area, the node holds at least min_refs references, and
  // fewer than `misses` tries in a row above it lost); and how many references a node's spatial
  // bins sample at most (0: all). Trees of fewer or more primitives than the bounds have none.
  float spatial_split_budget = 1.0f;
  float spatial_split_alpha = 1e-5f;
  uint32_t spatial_split_min_refs = 64;
  int spatial_split_misses = 2;
  uint32_t spatial_split_sample = 4096;
  size_t spatial_split_min_prims = 0, spatial_split_max_prims = SIZE_MAX;
  // alpha is a fraction of the area of the box around all references but this fraction of the
  // largest (by box area; 0: the root's box, as Stich et al.): a huge ground does not set the scale.
  float spatial_split_outliers = 0.01f;
  // Leaves whose box has more than this fraction of the root's surface area hold at most two;
  // with large_leaf_flat, not where the box is flat (a floor's triangles in one plane).
  float large_leaf_area = 0.01f;
  bool large_leaf_flat = true;
  // A wide node keeps its children's boxes as floats (WideNodeF) where quantising one of them would
  // grow its surface area by more than this fraction, where its subtree holds at least
  // float_node_prims primitives (the top levels, which every ray visits), and everywhere in a tree
  // of at most float_tree_prims primitives: a small tree stays in the caches, where the quantised
  // node's decoding costs more than its smaller size saves (in-process A/B, all float against
  // quantised: 0.80-0.91 of the time on the bunny, a 10k scan and a 328k dense mesh; neutral to
  // 1.05 on a 1M scan).
  float float_node_growth = 1.0f;
  size_t float_node_prims = SIZE_MAX;
  size_t float_tree_prims = size_t(1) << 19;
  // Wide nodes: > 0, chosen by the SAH over the binary tree (bvh_collapse.cpp, plan()) with this
  // cost of one wide node's test relative to one pack's; 0, greedily (the largest child opened
  // first). Timed in one process against the greedy choice (54 rows on 9 meshes of 10k-124k
  // triangles, two rounds): 0.963 of the time with cost 1, 0.952 with 2, 0.954 with 3 (1 thread);
  // 0.944 on 328k-1.3M (docs/notes/bvh-history.md, twelfth round).
  float collapse_node_cost = 2.0f;
  // A leaf that would hold triangles in an axis-aligned plane on its box's face (a floor) with
  // others lifting the box off it splits in two (bvh_build.cpp, plane_part).
  bool split_planes = true;
};

// refs is consumed. With `mesh` (the triangles the references index), triangles may be split
// spatially (Stich et al. 2009), so one triangle can be referenced from several leaves, each time
// with the box of its part. An empty input gives an empty tree.
Bvh2 build_bvh2(PrimRefs refs, const BuildOptions& options = {}, const Mesh* mesh = nullptr);

// ---- the wide BVH that traversal uses ----
constexpr int kWidth = 8;

// Nodes and triangle packs live in one array of 32-byte blocks, each node directly followed by the
// packs of its leaf children and then by its inner children's subtrees (depth first). A ray that
// reaches a node near the bottom of the tree then finds the triangles it tests next a few cache
// lines further on, in the same page, instead of in a separate array.
struct alignas(32) Block {
  unsigned char bytes[32];
};
static_assert(sizeof(Block) == 32);

// A child reference: an inner node (bit 31 clear; bit 30 set for a WideNodeF; bits 0-25 the block
// where the node starts), a leaf (bit 31 set; bit 30 set for a sphere leaf; bits 26-29 the number of
// triangle packs or spheres; bits 0-25 the block of the first pack, or the first index into
// WideBvh::spheres), or empty.
constexpr uint32_t kLeafBit = 1u << 31;
constexpr uint32_t kSphereBit = 1u << 30;
constexpr uint32_t kFloatNodeBit = 1u << 30;
constexpr uint32_t kEmptyChild = 0xffffffffu;
constexpr int kCountShift = 26;
constexpr uint32_t kFirstMask = (1u << kCountShift) - 1;
inline bool is_leaf(uint32_t ref) { return (ref & kLeafBit) != 0; }
inline uint32_t leaf_count(uint32_t ref) { return (ref >> kCountShift) & 15u; }
inline uint32_t leaf_first(uint32_t ref) { return ref & kFirstMask; }
inline bool is_float_node(uint32_t inner_ref) { return (inner_ref & kFloatNodeBit) != 0; }
inline uint32_t node_block(uint32_t inner_ref) { return inner_ref & kFirstMask; }

// An 8-wide node whose child boxes are quantised to 8 bits per plane relative to the node's own box
// (Ylitie, Karras and Laine, "Efficient Incoherent Ray Traversal on GPUs Through Compressed Wide
// BVHs", HPG 2017): plane = origin + q * 2^exponent. q * 2^exponent is exact in float, so the decoded
// plane is the single rounding of origin + q * 2^exponent however it is evaluated (fma, or multiply
// then add); the builder picks every q so that this decoded plane lies outside the child's true box,
// and traversal then runs the same robust slab test on the decoded planes as on float boxes.
// 96 bytes, two cache lines, where float planes take 224.
struct alignas(32) WideNode {
  float origin[3];
  int8_t exponent[3];
  uint8_t valid = 0;       // bit i set: child i exists
  uint32_t child[kWidth];  // kEmptyChild where there is none
  uint8_t q[6][kWidth];    // q[2 * axis]: lower planes, q[2 * axis + 1]: upper planes

  float scale(int axis) const { return std::bit_cast<float>(static_cast<uint32_t>(exponent[axis] + 127) << 23); }
  float plane(int row, int i) const { return origin[row / 2] + static_cast<float>(q[row][i]) * scale(row / 2); }
  // The box traversal tests for child i (it contains the child's true box).
  BBox child_box(int i) const {
    BBox b;
    b.lo = {plane(0, i), plane(2, i), plane(4, i)};
    b.hi = {plane(1, i), plane(3, i), plane(5, i)};
    return b;
  }
};
static_assert(sizeof(WideNode) == 96);

// The quantised node for up to kWidth children with the given boxes and references.
WideNode make_wide_node(const BBox* boxes, const uint32_t* refs, int n);

// An 8-wide node with its children's boxes as floats, exactly: where quantising would lose too much
// (a small model beside a ground 10^4 times its size: one step of the root's grid is wider than the
// model), and optionally at the top of the tree. The same planes in the same rows as WideNode's q, so
// the same slab test runs on them; an empty child has the empty box (+inf, -inf), which every ray
// misses. 224 bytes.
struct alignas(32) WideNodeF {
  uint32_t child[kWidth];  // kEmptyChild where there is none
  float plane[6][kWidth];  // plane[2 * axis]: lower planes, plane[2 * axis + 1]: upper planes
  BBox child_box(int i) const {
    BBox b;
    b.lo = {plane[0][i], plane[2][i], plane[4][i]};
    b.hi = {plane[1][i], plane[3][i], plane[5][i]};
    return b;
  }
};
static_assert(sizeof(WideNodeF) == 224);

WideNodeF make_float_node(const BBox* boxes, const uint32_t* refs, int n);

// Four triangles in structure-of-arrays form: v[3 * row + axis][lane]. With PackLayout::kVertices
// the three rows are the corners p0, p1, p2 (the watertight test needs them); with kEdges they are
// p0, e1 = p1 - p0 and e2 = p2 - p0, the values Möller-Trumbore starts from, so the test skips six
// subtractions and gets the same bits. Unused lanes have NaN corners (every test rejects them, the
// watertight one at its early exit; the tests' own packs may leave them zero, a degenerate triangle
// every test rejects too) and prim = kNoPrim.
constexpr uint32_t kNoPrim = 0xffffffffu;
enum class PackLayout { kVertices, kEdges };
struct alignas(32) TriPack {
  float v[9][4];
  uint32_t prim[4];
};

// Two packs interleaved, for the eight-lane kernels (AVX2 and up): row r of both in one 32-byte
// row, lanes 0-3 the first pack's and 4-7 the second's, so an eight-lane test loads each row once
// where two packs in a row took a load and an insert per row. The size of two packs: a leaf of n
// packs in the paired layout (WideBvh::pairs) holds n / 2 pairs and, for odd n, one TriPack last,
// so pack k starts where it does unpaired.
struct alignas(32) TriPair {
  float v[9][8];
  uint32_t prim[8];
};
static_assert(sizeof(TriPair) == 2 * sizeof(TriPack));
TriPair pair_of(const TriPack& first, const TriPack& second);

constexpr uint32_t kNodeBlocks = sizeof(WideNode) / sizeof(Block);
constexpr uint32_t kFloatNodeBlocks = sizeof(WideNodeF) / sizeof(Block);
constexpr uint32_t kPackBlocks = sizeof(TriPack) / sizeof(Block);
static_assert(sizeof(WideNode) % sizeof(Block) == 0 && sizeof(WideNodeF) % sizeof(Block) == 0 &&
              sizeof(TriPack) % sizeof(Block) == 0);
static_assert(std::is_trivially_copyable_v<Block>);

struct WideBvh {
  HugeVector<Block> blocks;                              // the root node starts at block 0 (no blocks: no geometry)
  std::vector<uint32_t> spheres;                        // sphere indices in leaf order
  uint32_t root = 0;                                    // the root's reference (block 0, maybe kFloatNodeBit)
  size_t nodes = 0, float_nodes = 0, packs = 0;
  int depth = 0;  // levels of wide nodes, for the traversal stack bound
  bool pairs = false;  // leaves' packs paired (TriPair), for the eight-lane kernels

  // An inner node's reference: a quantised node, or with kFloatNodeBit a float one.
  const WideNode& node(uint32_t ref) const {
    return *std::launder(reinterpret_cast<const WideNode*>(blocks.data() + node_block(ref)));
  }
  const WideNodeF& float_node(uint32_t ref) const {
    return *std::launder(reinterpret_cast<const WideNodeF*>(blocks.data() + node_block(ref)));
  }
  // Pack k of a triangle leaf (unpaired, or the last of an odd count paired).
  const TriPack& pack(uint32_t leaf_ref, uint32_t k) const {
    return *std::launder(reinterpret_cast<const TriPack*>(blocks.data() + leaf_first(leaf_ref) + k * kPackBlocks));
  }
  // Packs k and k + 1 (k even) of a leaf in the paired layout.
  const TriPair& pair(uint32_t leaf_ref, uint32_t k) const {
    return *std::launder(reinterpret_cast<const TriPair*>(blocks.data() + leaf_first(leaf_ref) + k * kPackBlocks));
  }
  // Triangle `lane` (0-3) of pack k, in either layout (for checking a tree: traversal reads packs
  // and pairs whole): row r of its three corners (or p0, e1, e2), and its primitive.
  float lane_value(uint32_t leaf_ref, uint32_t k, int row, int lane) const {
    return in_pair(leaf_ref, k) ? pair(leaf_ref, k & ~1u).v[row][4 * (k & 1) + lane] : pack(leaf_ref, k).v[row][lane];
  }
  uint32_t lane_prim(uint32_t leaf_ref, uint32_t k, int lane) const {
    return in_pair(leaf_ref, k) ? pair(leaf_ref, k & ~1u).prim[4 * (k & 1) + lane] : pack(leaf_ref, k).prim[lane];
  }
  // Pack k is half of a pair: paired, and not the last of an odd count.
  bool in_pair(uint32_t leaf_ref, uint32_t k) const { return pairs && (k % 2 == 1 || k + 1 < leaf_count(leaf_ref)); }
  size_t bytes() const { return blocks.size() * sizeof(Block) + spheres.size() * sizeof(uint32_t); }
};

// `pairs`: the leaves' packs in the paired layout (TriPair), for the eight-lane kernels.
WideBvh collapse_to_wide(const Bvh2& tree, const Geometry& scene, PackLayout layout = PackLayout::kVertices,
                         const BuildOptions& options = {}, bool pairs = false);

}  // namespace pt::bvh
