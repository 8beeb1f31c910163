// Binned-SAH construction of the binary BVH and its collapse into 8-wide nodes (see bvh_build.h).
#include "core/accel/bvh_build.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif
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
#include <memory>
#include <mutex>
#include <optional>
#include <type_traits>

#include "core/accel/bvh_clip.h"
#include "core/geometry/geometry.h"
#include "core/util/error.h"

namespace pt::bvh {
namespace {

constexpr int kBins = 32;
constexpr int kSpatialBins = 16;
// Ranges at least this large bin in parallel; subtrees at least this large build as separate tasks.
constexpr size_t kParallelBinning = 1 << 16;
constexpr size_t kParallelSubtree = 1 << 12;
// Below this depth SAH decides; deeper, ranges are halved by count, so the tree depth (and with it
// the traversal stack) stays bounded even on adversarial input.
constexpr int kSahDepthLimit = 40;

// SAH cost counts triangles in packs of four, the unit the leaf test works in (as Embree's
// builders do with their block size), and two packs at a time as one test of `pair` packs' cost
// where the leaf test takes them so (BuildOptions::pack_pair_cost).
struct LeafCost {
  float pair = 2.0f;
  float operator()(uint32_t n) const {
    uint32_t packs = (n + 3) / 4;
    return static_cast<float>(packs / 2) * pair + static_cast<float>(packs % 2);
  }
};

// The SAH sweep over N bins along one axis (Wald 2007, section 3): from the right, then from the
// left, the cost of each of the N - 1 planes. A reference is counted on the left of every plane
// after its `enter` bin and on the right of every plane before its `exit` bin (the same bin for
// object splits, where nothing straddles). Planes that leave either side empty, or all n
// references on one side, are skipped.
struct PlaneChoice {
  float cost = kInf;
  int plane = 0;  // the plane before bin `plane`
  uint32_t left = 0, right = 0;
};

template <size_t N, class BoxOf, class EnterOf, class ExitOf>
PlaneChoice sweep(uint32_t n, const LeafCost& blocks, BoxOf box, EnterOf enter, ExitOf exit) {
  std::array<float, N> right_cost{};
  std::array<uint32_t, N> right_count{};
  BBox acc;
  uint32_t count = 0;
  for (int i = static_cast<int>(N) - 1; i > 0; --i) {
    acc.expand(box(i));
    count += exit(i);
    right_count[i] = count;
    right_cost[i] = count ? acc.surface_area() * blocks(count) : kInf;
  }
  PlaneChoice best;
  acc = BBox();
  count = 0;
  for (int i = 0; i < static_cast<int>(N) - 1; ++i) {
    acc.expand(box(i));
    count += enter(i);
    uint32_t right = right_count[i + 1];
    if (count == 0 || right == 0 || count >= n || right >= n) continue;
    float cost = acc.surface_area() * blocks(count) + right_cost[i + 1];
    if (cost < best.cost) best = PlaneChoice{cost, i + 1, count, right};
  }
  return best;
}

// A bin's box and centroid box as four-float rows (the fourth lane is unused), so that binning can
// update them with one SSE min or max each. The operations are those of BBox::expand, in its operand
// order, so the bins hold the same bits either way.
struct Bin {
  alignas(16) float lo[4] = {kInf, kInf, kInf, kInf};
  alignas(16) float hi[4] = {-kInf, -kInf, -kInf, -kInf};
  alignas(16) float clo[4] = {kInf, kInf, kInf, kInf};
  alignas(16) float chi[4] = {-kInf, -kInf, -kInf, -kInf};
  uint32_t count = 0;

  static BBox rows(const float* a, const float* b) {
    BBox r;
    r.lo = {a[0], a[1], a[2]};
    r.hi = {b[0], b[1], b[2]};
    return r;
  }
  BBox box() const { return rows(lo, hi); }
  BBox centroids() const { return rows(clo, chi); }
  void set(const BBox& box, const BBox& centroids) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = box.lo[a];
      hi[a] = box.hi[a];
      clo[a] = centroids.lo[a];
      chi[a] = centroids.hi[a];
    }
  }
  void add(const PrimRef& r) {
    BBox b = box(), c = centroids();
    b.expand(r.lo);
    b.expand(r.hi);
    c.expand(r.centroid());
    set(b, c);
    ++count;
  }
#if defined(__SSE2__)
  // lo, hi: the reference's box; c: its centroid.
  void add(__m128 rlo, __m128 rhi, __m128 c) {
    __m128 l = _mm_load_ps(lo), h = _mm_load_ps(hi);
    _mm_store_ps(lo, _mm_min_ps(rhi, _mm_min_ps(rlo, l)));
    _mm_store_ps(hi, _mm_max_ps(rhi, _mm_max_ps(rlo, h)));
    _mm_store_ps(clo, _mm_min_ps(c, _mm_load_ps(clo)));
    _mm_store_ps(chi, _mm_max_ps(c, _mm_load_ps(chi)));
    ++count;
  }
#endif
  void merge(const Bin& o) {
    BBox b = box(), c = centroids();
    b.expand(o.box());
    c.expand(o.centroids());
    set(b, c);
    count += o.count;
  }
};

struct Binning {
  std::array<std::array<Bin, kBins>, 3> bins;
  void merge(const Binning& o) {
    for (int axis = 0; axis < 3; ++axis)
      for (int i = 0; i < kBins; ++i) bins[axis][i].merge(o.bins[axis][i]);
  }
};

struct BinMapping {
  Vec3f origin, scale;
  int bin(const Vec3f& c, int axis) const {
    int b = static_cast<int>((c[axis] - origin[axis]) * scale[axis]);
    return std::clamp(b, 0, kBins - 1);
  }
};

// Spatial bins: the node's box cut into kSpatialBins equal slabs per axis. Each bin holds the box of
// the parts of the references that lie in its slab; a reference is counted where it enters (its
// first bin) and where it exits (its last).
struct SpatialBin {
  BBox box;
  uint32_t enter = 0, exit = 0;
};
struct SpatialBinning {
  std::array<std::array<SpatialBin, kSpatialBins>, 3> bins;
  void merge(const SpatialBinning& o) {
    for (int axis = 0; axis < 3; ++axis) {
      for (int i = 0; i < kSpatialBins; ++i) {
        bins[axis][i].box.expand(o.bins[axis][i].box);
        bins[axis][i].enter += o.bins[axis][i].enter;
        bins[axis][i].exit += o.bins[axis][i].exit;
      }
    }
  }
};
struct SpatialMapping {
  Vec3f origin, scale;
  double step[3];
  int bin(float x, int axis) const {
    int b = static_cast<int>((x - origin[axis]) * scale[axis]);
    return std::clamp(b, 0, kSpatialBins - 1);
  }
  double plane(int axis, int i) const { return static_cast<double>(origin[axis]) + step[axis] * i; }
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

// The references of one subtree: `size` of them at `data`, with room for `cap` (spatial splits add
// references; a subtree that runs out of room moves to a block of its own).
struct Span {
  PrimRef* data = nullptr;
  uint32_t size = 0, cap = 0;
  PrimRef* begin() const { return data; }
  PrimRef* end() const { return data + size; }
};

struct TmpNode {  // trivially destructible: Builder frees the room for them without destroying them
  BBox box;
  uint32_t left = 0;                // inner: index of the left child (the right one is left + 1)
  const PrimRef* refs = nullptr;    // leaf: its references
  uint32_t count = 0;
};

static_assert(std::is_trivially_destructible_v<TmpNode>);

BBox ref_box(const PrimRef& r) {
  BBox b;
  b.lo = r.lo;
  b.hi = r.hi;
  return b;
}

class Builder {
 public:
  Builder(PrimRefs& refs, const BuildOptions& options, const Mesh* mesh)
      : refs_(refs), options_(options), mesh_(mesh), leaf_cost_{options.pack_pair_cost} {
    size_t n = refs.size();
    double extra = mesh ? std::max(0.0, static_cast<double>(options.spatial_split_budget)) * static_cast<double>(n) : 0.0;
    budget_.store(static_cast<int64_t>(std::min(extra, static_cast<double>((int64_t(1) << 31) - 1 - n))));
    // Each added reference adds at most one leaf; a full binary tree over m leaves has 2m - 1 nodes.
    // Room for the largest tree, left untouched: a tree uses about two nodes per leaf, a small part
    // of the room, and zeroing the rest (over 100 MB for a million triangles) costs more in page
    // faults than the binning of the top levels. Each node is constructed when it is written.
    size_t room = std::max<size_t>(1, 2 * (n + static_cast<size_t>(budget_.load())));
    nodes_.reset(static_cast<TmpNode*>(allocate_huge(room * sizeof(TmpNode))));
  }

  void run() {
    Span root{refs_.data(), static_cast<uint32_t>(refs_.size()), static_cast<uint32_t>(refs_.size())};
    Bounds bounds = bounds_of(root);
    root_area_ = bounds.box.surface_area();
    next_.store(1);
    build(0, root, bounds, 0);
  }

  // Rewrites the nodes, allocated in whatever order the tasks ran, in depth-first order, and the
  // references of the leaves packed one after the other.
  void flatten(HugeVector<Node2>& nodes, PrimRefs& prims) const {
    nodes.reserve(next_.load());
    prims.reserve(refs_.size() + added_.load());
    flatten(0, nodes, prims);
  }

 private:
  // Folds `add(first, last, acc)` over the span: in parallel chunks, merged, for large spans.
  template <class Acc, class Add>
  static Acc reduce(const Span& s, Add add) {
    if (s.size < kParallelBinning) {
      Acc acc;
      add(s.begin(), s.end(), acc);
      return acc;
    }
    return tbb::parallel_reduce(
        tbb::blocked_range<const PrimRef*>(s.begin(), s.end(), 8192), Acc{},
        [&](const tbb::blocked_range<const PrimRef*>& r, Acc acc) {
          add(r.begin(), r.end(), acc);
          return acc;
        },
        [](Acc a, const Acc& b) {
          a.merge(b);
          return a;
        });
  }

  Bounds bounds_of(const Span& s) const {
    return reduce<Bounds>(s, [](const PrimRef* first, const PrimRef* last, Bounds& b) {
      for (const PrimRef* p = first; p != last; ++p) b.add(*p);
    });
  }

  Binning bin(const Span& s, const BinMapping& map) const {
    return reduce<Binning>(s, [&](const PrimRef* first, const PrimRef* last, Binning& out) {
#if defined(__SSE2__)
      // The arithmetic of PrimRef::centroid and BinMapping::bin, four lanes at once; the fourth lane
      // (the reference's index and kind) is cleared first.
      const __m128 keep = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
      const __m128 origin = _mm_setr_ps(map.origin.x, map.origin.y, map.origin.z, 0.0f);
      const __m128 scale = _mm_setr_ps(map.scale.x, map.scale.y, map.scale.z, 0.0f);
      for (const PrimRef* p = first; p != last; ++p) {
        __m128 lo = _mm_and_ps(_mm_loadu_ps(&p->lo.x), keep), hi = _mm_and_ps(_mm_loadu_ps(&p->hi.x), keep);
        __m128 c = _mm_mul_ps(_mm_add_ps(lo, hi), _mm_set1_ps(0.5f));
        alignas(16) int32_t b[4];
        _mm_store_si128(reinterpret_cast<__m128i*>(b), _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(c, origin), scale)));
        for (int axis = 0; axis < 3; ++axis) out.bins[axis][std::clamp(b[axis], 0, kBins - 1)].add(lo, hi, c);
      }
#else
      for (const PrimRef* p = first; p != last; ++p) {
        Vec3f c = p->centroid();
        for (int axis = 0; axis < 3; ++axis) out.bins[axis][map.bin(c, axis)].add(*p);
      }
#endif
    });
  }

  ClipPolygon polygon(const PrimRef& r) const {
    const uint32_t* idx = &mesh_->indices[3 * size_t(r.index)];
    return triangle_polygon(mesh_->positions[idx[0]], mesh_->positions[idx[1]], mesh_->positions[idx[2]]);
  }
  BBox triangle_box(const PrimRef& r) const {
    const uint32_t* idx = &mesh_->indices[3 * size_t(r.index)];
    BBox b;
    for (int c = 0; c < 3; ++c) b.expand(mesh_->positions[idx[c]]);
    return b;
  }

  void spatial_bin_range(const PrimRef* first, const PrimRef* last, const SpatialMapping& map,
                         SpatialBinning& out) const {
    for (const PrimRef* p = first; p != last; ++p) {
      const PrimRef& r = *p;
      BBox box = ref_box(r);
      bool clipped = false;
      ClipPolygon poly;
      BBox tri;
      for (int axis = 0; axis < 3; ++axis) {
        if (!(map.scale[axis] > 0.0f)) continue;
        int b0 = map.bin(r.lo[axis], axis), b1 = map.bin(r.hi[axis], axis);
        auto& bins = out.bins[axis];
        bins[b0].enter++;
        bins[b1].exit++;
        if (b0 == b1) {
          bins[b0].box.expand(box);
          continue;
        }
        if (!clipped) {
          poly = clip_box(polygon(r), box);
          tri = triangle_box(r);
          clipped = true;
        }
        for (int b = b0; b <= b1; ++b) {
          ClipPolygon part = clip_slab(poly, axis, map.plane(axis, b), map.plane(axis, b + 1));
          bins[b].box.expand(polygon_bounds(part, box, tri));
        }
      }
    }
  }

  SpatialBinning spatial_bin(const Span& s, const SpatialMapping& map) const {
    return reduce<SpatialBinning>(s, [&](const PrimRef* first, const PrimRef* last, SpatialBinning& out) {
      spatial_bin_range(first, last, map, out);
    });
  }

  struct SpatialSplit {
    float cost = kInf;
    int axis = -1, plane = 0;
    uint32_t left = 0, right = 0;  // references on each side, counting split ones on both
  };

  // The best spatial split of the span, by SAH over the spatial bins (Stich et al. 2009, section 4).
  SpatialSplit find_spatial_split(const Span& s, const BBox& box, SpatialMapping& map) const {
    Vec3f extent = box.extent();
    map.origin = box.lo;
    for (int axis = 0; axis < 3; ++axis) {
      map.scale[axis] = extent[axis] > 0.0f ? kSpatialBins * (1.0f - 1e-6f) / extent[axis] : 0.0f;
      map.step[axis] = static_cast<double>(extent[axis]) / kSpatialBins;
    }
    SpatialBinning binning = spatial_bin(s, map);
    SpatialSplit best;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(map.scale[axis] > 0.0f)) continue;
      const auto& bins = binning.bins[axis];
      PlaneChoice c = sweep<kSpatialBins>(
          s.size, leaf_cost_, [&](int i) { return bins[i].box; }, [&](int i) { return bins[i].enter; },
          [&](int i) { return bins[i].exit; });
      if (c.cost < best.cost) best = SpatialSplit{c.cost, axis, c.plane, c.left, c.right};
    }
    return best;
  }

  // Room for `n` references of a subtree, with some to spare for the splits below it.
  Span allocate(uint32_t n) {
    uint32_t spare = static_cast<uint32_t>(std::min<int64_t>(std::max<int64_t>(0, budget_.load()), n / 4 + 16));
    auto block = std::make_unique<PrimRef[]>(size_t(n) + spare);
    Span s{block.get(), 0, n + spare};
    std::lock_guard<std::mutex> lock(blocks_mutex_);
    blocks_.push_back(std::move(block));
    return s;
  }

  // Sorts the references of `s` to either side of the spatial split, splitting those that straddle
  // the plane into two clipped references. Returns the two children, or nothing when the split
  // would exceed the budget of added references.
  std::optional<std::pair<Span, Span>> apply_spatial_split(const Span& s, const SpatialSplit& split,
                                                           const SpatialMapping& map) {
    int axis = split.axis;
    double at = map.plane(axis, split.plane);
    auto side = [&](const PrimRef& ref) {  // 0 left, 1 right, 2 both
      int b0 = map.bin(ref.lo[axis], axis), b1 = map.bin(ref.hi[axis], axis);
      return b1 < split.plane ? 0 : (b0 >= split.plane ? 1 : 2);
    };
    // Clip the straddling references first, into their left and right parts; one whose part on
    // one side is empty goes whole to the other side.
    std::vector<PrimRef> lefts, rights;
    for (const PrimRef& ref : s) {
      int k = side(ref);
      if (k == 0) {
        lefts.push_back(ref);
      } else if (k == 1) {
        rights.push_back(ref);
      } else {
        BBox box = ref_box(ref), tri = triangle_box(ref);
        ClipPolygon poly = clip_box(polygon(ref), box);
        BBox lb = polygon_bounds(clip_plane(poly, axis, at, -1.0), box, tri);
        BBox rb = polygon_bounds(clip_plane(poly, axis, at, 1.0), box, tri);
        if (!lb.empty()) lefts.push_back(PrimRef{lb.lo, ref.index, lb.hi, ref.kind});
        if (!rb.empty()) rights.push_back(PrimRef{rb.lo, ref.index, rb.hi, ref.kind});
        if (lb.empty() && rb.empty()) lefts.push_back(ref);  // numerically lost: keep it whole
      }
    }
    uint32_t nl = static_cast<uint32_t>(lefts.size()), nr = static_cast<uint32_t>(rights.size());
    if (nl == 0 || nr == 0) return std::nullopt;
    int64_t added = int64_t(nl) + nr - s.size;
    if (added > 0 && budget_.fetch_sub(added) < added) {
      budget_.fetch_add(added);
      return std::nullopt;
    }
    if (added > 0) added_.fetch_add(static_cast<size_t>(added));
    Span target = nl + nr <= s.cap ? Span{s.data, 0, s.cap} : allocate(nl + nr);
    // Left child first; the right one gets the rest of the room.
    std::copy(lefts.begin(), lefts.end(), target.data);
    std::copy(rights.begin(), rights.end(), target.data + nl);
    return std::pair{Span{target.data, nl, nl}, Span{target.data + nl, nr, target.cap - nl}};
  }

  void make_leaf(uint32_t index, const Span& s, const BBox& box) {
    TmpNode& n = *new (&nodes_[index]) TmpNode;
    n.box = box;
    n.refs = s.data;
    n.count = s.size;
  }

  // Two children from a split of `s` after `mid` references: the spare room goes with the right one.
  void split_at(uint32_t index, const Span& s, uint32_t mid, const BBox& box, int depth) {
    split_into(index, Span{s.data, mid, mid}, Span{s.data + mid, s.size - mid, s.cap - mid}, box, depth);
  }

  void split_into(uint32_t index, const Span& left, const Span& right, const BBox& box, int depth) {
    split_into(index, left, right, box, depth, bounds_of(left), bounds_of(right));
  }

  // With the children's bounds known (an object split takes them from its bins).
  void split_into(uint32_t index, const Span& left, const Span& right, const BBox& box, int depth,
                  const Bounds& lb, const Bounds& rb) {
    uint32_t l = next_.fetch_add(2);
    TmpNode& n = *new (&nodes_[index]) TmpNode;
    n.box = box;
    n.left = l;
    n.count = 0;
    if (left.size + right.size >= kParallelSubtree) {
      tbb::parallel_invoke([&] { build(l, left, lb, depth + 1); }, [&] { build(l + 1, right, rb, depth + 1); });
    } else {
      build(l, left, lb, depth + 1);
      build(l + 1, right, rb, depth + 1);
    }
  }

  void build(uint32_t index, const Span& s, const Bounds& bounds, int depth) {
    uint32_t n = s.size;
    bool mixed = false;
    for (uint32_t i = 1; i < n && !mixed; ++i) mixed = s.data[i].kind != s.data[0].kind;
    bool triangles = !mixed && s.data[0].kind == PrimKind::kTriangle;
    if (n == 1 || (triangles && n <= 2)) {
      make_leaf(index, s, bounds.box);
      return;
    }
    if (mixed && n <= static_cast<uint32_t>(options_.max_leaf)) {
      // A leaf holds one kind only, so a small mixed range splits by kind.
      PrimRef* mid = std::partition(s.begin(), s.end(), [](const PrimRef& p) { return p.kind == PrimKind::kTriangle; });
      split_at(index, s, static_cast<uint32_t>(mid - s.data), bounds.box, depth);
      return;
    }
    Vec3f extent = bounds.centroids.extent();
    if (depth >= kSahDepthLimit || max_component(extent) <= 0.0f) {
      // No spatial order left to exploit (or the depth guard): a leaf if it fits, else halve by count.
      if (!mixed && n <= static_cast<uint32_t>(options_.max_leaf)) {
        make_leaf(index, s, bounds.box);
      } else {
        split_at(index, s, n / 2, bounds.box, depth);
      }
      return;
    }

    BinMapping map;
    map.origin = bounds.centroids.lo;
    for (int axis = 0; axis < 3; ++axis) {
      map.scale[axis] = extent[axis] > 0.0f ? kBins * (1.0f - 1e-6f) / extent[axis] : 0.0f;
    }
    Binning binning = bin(s, map);

    float best_cost = kInf;
    int best_axis = -1, best_plane = 0;
    for (int axis = 0; axis < 3; ++axis) {
      if (extent[axis] <= 0.0f) continue;
      const auto& bins = binning.bins[axis];
      auto count = [&](int i) { return bins[i].count; };
      PlaneChoice c = sweep<kBins>(n, leaf_cost_, [&](int i) { return bins[i].box(); }, count, count);
      if (c.cost < best_cost) {
        best_cost = c.cost;
        best_axis = axis;
        best_plane = c.plane;
      }
    }

    // Spatial splits are tried where the two sides of the best object split overlap by more than a
    // small fraction of the root's surface (Stich et al. 2009, section 4.5: alpha), while the budget
    // of added references lasts.
    SpatialSplit spatial;
    SpatialMapping smap;
    if (triangles && mesh_ && best_axis >= 0 && budget_.load(std::memory_order_relaxed) > 0) {
      BBox left, right;
      const auto& bins = binning.bins[best_axis];
      for (int i = 0; i < kBins; ++i) (i < best_plane ? left : right).expand(bins[i].box());
      BBox overlap;
      overlap.lo = vmax(left.lo, right.lo);
      overlap.hi = vmin(left.hi, right.hi);
      if (overlap.surface_area() > options_.spatial_split_alpha * root_area_) {
        spatial = find_spatial_split(s, bounds.box, smap);
      }
    }
    bool use_spatial = spatial.cost < best_cost;
    float area = bounds.box.surface_area();
    float leaf_cost = leaf_cost_(n);
    float split_cost = options_.traversal_cost + (area > 0.0f ? std::min(best_cost, spatial.cost) / area : 0.0f);
    // SAH takes rays to come from outside a box, where the chance to enter it grows with its area;
    // but a box around a whole room contains every ray that starts in the room. Large boxes (the
    // room's walls, grouped) therefore hold few primitives, so that a ray tests only the walls it
    // can reach.
    uint32_t max_leaf = area > options_.large_leaf_area * root_area_ ? std::min<uint32_t>(2, options_.max_leaf)
                                                                       : static_cast<uint32_t>(options_.max_leaf);
    if (n > max_leaf && n <= static_cast<uint32_t>(options_.max_leaf) && best_axis < 0 && !use_spatial) {
      split_at(index, s, n / 2, bounds.box, depth);
      return;
    }
    if (!mixed && n <= max_leaf &&
        ((best_axis < 0 && !use_spatial) || leaf_cost <= split_cost)) {
      make_leaf(index, s, bounds.box);
      return;
    }
    if (use_spatial) {
      if (auto children = apply_spatial_split(s, spatial, smap)) {
        split_into(index, children->first, children->second, bounds.box, depth);
        return;
      }
    }
    if (best_axis < 0) {
      split_at(index, s, n / 2, bounds.box, depth);
      return;
    }
    PrimRef* mid = std::partition(s.begin(), s.end(), [&](const PrimRef& p) {
      return map.bin(p.centroid(), best_axis) < best_plane;
    });
    // The partition puts on the left exactly the references of the bins before the plane, so the
    // union of those bins is the left child's bounds (min and max are exact): no pass over the
    // references is needed to find them.
    Bounds lb, rb;
    const auto& bins = binning.bins[best_axis];
    for (int i = 0; i < kBins; ++i) {
      Bounds& side = i < best_plane ? lb : rb;
      side.box.expand(bins[i].box());
      side.centroids.expand(bins[i].centroids());
    }
    uint32_t nl = static_cast<uint32_t>(mid - s.data);
    split_into(index, Span{s.data, nl, nl}, Span{s.data + nl, s.size - nl, s.cap - nl}, bounds.box, depth, lb, rb);
  }

  void flatten(uint32_t index, HugeVector<Node2>& out, PrimRefs& prims) const {
    const TmpNode& n = nodes_[index];
    size_t me = out.size();
    if (n.count > 0) {
      out.push_back(Node2{n.box, static_cast<uint32_t>(prims.size()), n.count});
      prims.insert(prims.end(), n.refs, n.refs + n.count);
      return;
    }
    out.push_back(Node2{n.box, 0, 0});
    flatten(n.left, out, prims);
    out[me].offset = static_cast<uint32_t>(out.size());
    flatten(n.left + 1, out, prims);
  }

  PrimRefs& refs_;
  const BuildOptions& options_;
  const Mesh* mesh_;
  LeafCost leaf_cost_;
  float root_area_ = 0.0f;
  std::atomic<int64_t> budget_{0};  // references spatial splits may still add
  std::atomic<size_t> added_{0};
  struct Release {
    void operator()(TmpNode* p) const { std::free(p); }
  };
  std::unique_ptr<TmpNode[], Release> nodes_;  // TmpNode is trivially destructible
  std::atomic<uint32_t> next_{0};
  std::mutex blocks_mutex_;
  std::vector<std::unique_ptr<PrimRef[]>> blocks_;  // room allocated for subtrees that outgrew theirs
};

}  // namespace

PrimRefs make_prim_refs(const Geometry& scene) {
  const Mesh& mesh = scene.mesh();
  const auto& spheres = scene.spheres();
  size_t tris = mesh.triangle_count();
  PrimRefs refs(tris + spheres.size());  // left uninitialised (HugePageAllocator), filled below
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
  // A primitive with a non-finite coordinate can never be hit (the tests reject it: NaN compares
  // false, an infinite corner gives a non-finite determinant), and its box would blow up the
  // quantised child boxes of every node above it; it is left out, as Embree leaves it out.
  auto finite = [](const Vec3f& p) { return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z); };
  std::erase_if(refs, [&](const PrimRef& r) { return !finite(r.lo) || !finite(r.hi); });
  return refs;
}

Bvh2 build_bvh2(PrimRefs refs, const BuildOptions& options, const Mesh* mesh) {
  Bvh2 out;
  if (refs.empty()) return out;
  if (refs.size() >= (size_t(1) << 31)) throw Error("bvh: too many primitives");
  Builder builder(refs, options, mesh);
  builder.run();
  builder.flatten(out.nodes, out.prims);
  return out;
}

namespace {

// The collapse runs in two passes over the binary tree: the first chooses each wide node's children
// and sums the blocks (and sphere slots) of every subtree, so that the second can write all
// subtrees in parallel, each at its final place in one array allocated once.
class Collapser {
 public:
  Collapser(const Bvh2& tree, const Geometry& scene, PackLayout layout, WideBvh& out)
      : tree_(tree), scene_(scene), layout_(layout), out_(out), sizes_(tree.nodes.size()) {}

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
    BBox boxes[kWidth];
    uint32_t refs[kWidth];
    uint32_t next = at + kNodeBlocks;
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
      refs[i] = child_at[i] = next;
      child_sphere_at[i] = sphere_at;
      next += sub.blocks;
      sphere_at += sub.spheres;
    }
    WideNode node = make_wide_node(boxes, refs, c.n);
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
  }

  // Wide levels near the root whose subtrees are measured and written as parallel tasks (8^3 tasks).
  static constexpr int kParallelLevels = 3;

  const Bvh2& tree_;
  const Geometry& scene_;
  PackLayout layout_;
  WideBvh& out_;
  std::vector<Size> sizes_;  // per binary node that becomes a wide node
  std::atomic<size_t> nodes_{0}, packs_{0};
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

WideBvh collapse_to_wide(const Bvh2& tree, const Geometry& scene, PackLayout layout) {
  WideBvh out;
  if (tree.nodes.empty()) return out;
  Collapser(tree, scene, layout, out).run();
  return out;
}

}  // namespace pt::bvh
