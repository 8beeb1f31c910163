// Binned-SAH construction of the binary BVH (see bvh_build.h); its collapse into 8-wide nodes is in
// bvh_collapse.cpp.
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
#include "core/accel/bvh_sah_bins.h"
#include "core/geometry/geometry.h"
#include "core/util/error.h"

namespace pt::bvh {
namespace {

using namespace sah;

// Ranges at least this large bin in parallel; subtrees at least this large build as separate tasks.
constexpr size_t kParallelBinning = 1 << 16;
constexpr size_t kParallelSubtree = 1 << 12;
// Below this depth SAH decides; deeper, ranges are halved by count, so the tree depth (and with it
// the traversal stack) stays bounded even on adversarial input.
constexpr int kSahDepthLimit = 40;

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

}  // namespace pt::bvh
