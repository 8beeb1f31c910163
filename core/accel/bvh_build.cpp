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
#include <optional>
#include <type_traits>
#include <vector>

#include "core/accel/bvh_clip.h"
#include "core/accel/bvh_sah_bins.h"
#include "core/accel/bvh_spatial_bins.h"
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

// The references of one subtree: `size` of them at `data`, with room for `cap`. The room beyond
// `size` is the subtree's budget for the references its spatial splits add; every split shares it
// between the two children in proportion to their sizes (as Embree's builders share their
// "extended range"), so the tree does not depend on the order in which the tasks run.
struct Span {
  PrimRef* data = nullptr;
  uint32_t size = 0, cap = 0;
  PrimRef* begin() const { return data; }
  PrimRef* end() const { return data + size; }
};

// Where a node is: its depth, and how many of the spatial splits tried on the way to it in a row
// lost to the object split.
struct Level {
  int depth = 0, misses = 0;
  Level next() const { return Level{depth + 1, misses}; }
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
    max_leaf_ = static_cast<uint32_t>(options.max_leaf > 0 ? options.max_leaf : default_max_leaf(n));
    bool spatial = mesh && n >= options.spatial_split_min_prims && n <= options.spatial_split_max_prims;
    double extra = spatial ? std::max(0.0, static_cast<double>(options.spatial_split_budget)) * static_cast<double>(n) : 0.0;
    extra = std::min(extra, static_cast<double>((int64_t(1) << 31) - 1 - n));
    room_ = n + static_cast<size_t>(extra);
    refs_.resize(room_);  // the added room is left uninitialised (HugeVector)
    // Each added reference adds at most one leaf; a full binary tree over m leaves has 2m - 1 nodes.
    // Room for the largest tree, left untouched: a tree uses about two nodes per leaf, a small part
    // of the room, and zeroing the rest (over 100 MB for a million triangles) costs more in page
    // faults than the binning of the top levels. Each node is constructed when it is written.
    nodes_.reset(static_cast<TmpNode*>(allocate_huge(std::max<size_t>(1, 2 * room_) * sizeof(TmpNode))));
    n_ = n;
  }

  void run() {
    Span root{refs_.data(), static_cast<uint32_t>(n_), static_cast<uint32_t>(room_)};
    Bounds bounds = bounds_of(root);
    root_area_ = bounds.box.surface_area();
    split_area_ = room_ > n_ ? typical_area(root) : root_area_;
    next_.store(1);
    build(0, root, bounds, Level{});
  }

  // Rewrites the nodes, allocated in whatever order the tasks ran, in depth-first order, and the
  // references of the leaves packed one after the other.
  void flatten(HugeVector<Node2>& nodes, PrimRefs& prims) const {
    nodes.reserve(next_.load());
    prims.reserve(n_ + added_.load());
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

  SpatialBinning spatial_bin(const Span& s, const SpatialMapping& map) const {
    return reduce<SpatialBinning>(s, [&](const PrimRef* first, const PrimRef* last, SpatialBinning& out) {
      sah::spatial_bin(first, last, map, *mesh_, out);
    });
  }

  struct SpatialSplit {
    float cost = kInf;
    int axis = -1, plane = 0;
    uint32_t left = 0, right = 0;  // references on each side, counting split ones on both
  };

  // The best spatial split of the span, by SAH over the spatial bins (Stich et al. 2009, section 4).
  SpatialSplit find_spatial_split(const Span& s, const SpatialMapping& map) const {
    // A large node bins every stride-th of its references (spatial_split_sample of them), with the
    // counts scaled back: an estimate, like the bins themselves, and the top levels of a million
    // triangles then cost what a node of a few thousand does.
    uint32_t sample = options_.spatial_split_sample;
    uint32_t stride = sample > 0 && s.size > 2 * sample ? s.size / sample : 1;
    SpatialBinning binning;
    uint32_t total = s.size;
    if (stride > 1) {
      sah::spatial_bin(s.begin(), s.end(), map, *mesh_, binning, stride);
      for (auto& axis : binning.bins) {
        for (auto& b : axis) {
          b.enter *= stride;
          b.exit *= stride;
        }
      }
      total = (s.size + stride - 1) / stride * stride;
    } else {
      binning = spatial_bin(s, map);
    }
    SpatialSplit best;
    for (int axis = 0; axis < 3; ++axis) {
      if (!(map.scale[axis] > 0.0f)) continue;
      const auto& bins = binning.bins[axis];
      PlaneChoice c = sweep<kSpatialBins>(
          total, leaf_cost_, [&](int i) { return bins[i].box(); }, [&](int i) { return bins[i].enter; },
          [&](int i) { return bins[i].exit; });
      if (c.cost < best.cost) best = SpatialSplit{c.cost, axis, c.plane, c.left, c.right};
    }
    return best;
  }

  // Sorts the references of `s` to either side of the spatial split, those that straddle the plane
  // split exactly into their two parts (where one part is empty the reference goes whole to the
  // other side), the left child first, each child followed by its share of the spare room. Nothing
  // (and `s` untouched) when a side would be empty or the parts would not fit.
  std::optional<std::pair<Span, Span>> apply_spatial_split(const Span& s, const SpatialSplit& split,
                                                           const SpatialMapping& map) {
    int axis = split.axis;
    double at = map.plane(axis, split.plane);
    std::vector<PrimRef> lefts, rights;
    lefts.reserve(split.left);
    rights.reserve(split.right);
    for (const PrimRef& ref : s) {
      int b0 = map.bin(ref.lo[axis], axis), b1 = map.bin(ref.hi[axis], axis);
      if (b1 < split.plane) {
        lefts.push_back(ref);
      } else if (b0 >= split.plane) {
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
    if (nl == 0 || nr == 0 || nl + nr > s.cap) return std::nullopt;
    if (nl + nr > s.size) added_.fetch_add(nl + nr - s.size);
    uint32_t spare = s.cap - nl - nr;
    uint32_t left_cap = nl + static_cast<uint32_t>(uint64_t(spare) * nl / (nl + nr));
    std::copy(lefts.begin(), lefts.end(), s.data);
    std::copy(rights.begin(), rights.end(), s.data + left_cap);
    return std::pair{Span{s.data, nl, left_cap}, Span{s.data + left_cap, nr, s.cap - left_cap}};
  }

  // SAH takes rays to come from outside a box, but a ray that starts on a surface starts inside
  // every box around it, unless the box is flat and the ray leaves its plane. A leaf holding part
  // of a floor (triangles in one axis-aligned plane, on a face of the leaf's box) with some of the
  // model standing on it has a box that rises off the floor, and every ray leaving the floor there
  // enters it and tests its packs: under the default studio, the dragon's leaf with three ground
  // triangles and one of its own was tested by nearly every shadow ray from the ground. Returns how
  // many references lie in such a plane, moved to the front of `s`, where they are some but not
  // all and their flat box has the larger area (the floor, not a face of the model that happens to
  // be axis-aligned); else 0.
  static uint32_t plane_part(const Span& s, const BBox& box) {
    for (int axis = 0; axis < 3; ++axis) {
      if (!(box.hi[axis] > box.lo[axis])) continue;
      for (float c : {box.lo[axis], box.hi[axis]}) {
        auto in_plane = [&](const PrimRef& p) { return p.lo[axis] == c && p.hi[axis] == c; };
        BBox flat, rest;
        uint32_t k = 0;
        for (const PrimRef& p : s) {
          if (in_plane(p)) {
            flat.expand(BBox{p.lo, p.hi});
            ++k;
          } else {
            rest.expand(BBox{p.lo, p.hi});
          }
        }
        if (k == 0 || k == s.size || !(flat.surface_area() > rest.surface_area())) continue;
        return static_cast<uint32_t>(std::partition(s.begin(), s.end(), in_plane) - s.begin());
      }
    }
    return 0;
  }

  // The area spatial splits' alpha is relative to (Stich et al. take the root's): that of the box
  // around every reference but the largest spatial_split_outliers of them by box area, where it is
  // under half the root's. Under the default studio the ground reaches 10^4 model radii, and alpha
  // times the root's area was larger than any node of the model, so a scan on the ground got none
  // of the spatial splits it got alone (scan-100k's rays from the model: 1.05-1.11 of Embree's
  // time, 0.86 without the ground).
  float typical_area(const Span& s) const {
    size_t n = s.size;
    size_t drop = static_cast<size_t>(static_cast<double>(n) * std::clamp(options_.spatial_split_outliers, 0.0f, 1.0f));
    if (drop == 0 || drop >= n) return root_area_;
    auto area = [&](size_t i) { return BBox{s.data[i].lo, s.data[i].hi}.surface_area(); };
    std::vector<float> areas(n);
    tbb::parallel_for(tbb::blocked_range<size_t>(0, n, 65536), [&](const tbb::blocked_range<size_t>& r) {
      for (size_t i = r.begin(); i < r.end(); ++i) areas[i] = area(i);
    });
    std::nth_element(areas.begin(), areas.begin() + static_cast<ptrdiff_t>(n - drop), areas.end());
    float limit = areas[n - drop];
    BBox box;
    for (size_t i = 0; i < n; ++i)
      if (area(i) <= limit) box.expand(BBox{s.data[i].lo, s.data[i].hi});
    // Only where the outliers set the scale: in a scene without such (a model alone) the box of all
    // but the largest 1% is nearly the root's, and its slightly smaller area let more splits be
    // tried that lost in time (dense-82k's diffuse rows 1.005 of Embree's time against 0.972).
    if (box.empty() || box.surface_area() > 0.5f * root_area_) return root_area_;
    return box.surface_area();
  }

  void make_leaf(uint32_t index, const Span& s, const BBox& box) {
    TmpNode& n = *new (&nodes_[index]) TmpNode;
    n.box = box;
    n.refs = s.data;
    n.count = s.size;
  }

  // The two children of a split of `s` after `mid` references, each with its share of the spare
  // room in proportion to its size (the right child's references move up to make the left's room).
  static std::pair<Span, Span> divide(const Span& s, uint32_t mid) {
    uint32_t spare = s.cap - s.size;
    uint32_t left_cap = mid + static_cast<uint32_t>(uint64_t(spare) * mid / s.size);
    if (left_cap > mid) std::memmove(s.data + left_cap, s.data + mid, size_t(s.size - mid) * sizeof(PrimRef));
    return {Span{s.data, mid, left_cap}, Span{s.data + left_cap, s.size - mid, s.cap - left_cap}};
  }

  void split_at(uint32_t index, const Span& s, uint32_t mid, const BBox& box, Level level) {
    auto [left, right] = divide(s, mid);
    split_into(index, left, right, box, level);
  }

  void split_into(uint32_t index, const Span& left, const Span& right, const BBox& box, Level level) {
    split_into(index, left, right, box, level, bounds_of(left), bounds_of(right));
  }

  // With the children's bounds known (an object split takes them from its bins).
  void split_into(uint32_t index, const Span& left, const Span& right, const BBox& box, Level level, const Bounds& lb,
                  const Bounds& rb) {
    uint32_t l = next_.fetch_add(2);
    TmpNode& n = *new (&nodes_[index]) TmpNode;
    n.box = box;
    n.left = l;
    n.count = 0;
    if (left.size + right.size >= kParallelSubtree) {
      tbb::parallel_invoke([&] { build(l, left, lb, level.next()); }, [&] { build(l + 1, right, rb, level.next()); });
    } else {
      build(l, left, lb, level.next());
      build(l + 1, right, rb, level.next());
    }
  }

  void build(uint32_t index, const Span& s, const Bounds& bounds, Level level) {
    uint32_t n = s.size;
    bool mixed = false;
    for (uint32_t i = 1; i < n && !mixed; ++i) mixed = s.data[i].kind != s.data[0].kind;
    bool triangles = !mixed && s.data[0].kind == PrimKind::kTriangle;
    if (n == 1 || (triangles && n <= 2)) {
      make_leaf(index, s, bounds.box);
      return;
    }
    if (mixed && n <= max_leaf_) {
      // A leaf holds one kind only, so a small mixed range splits by kind.
      PrimRef* mid = std::partition(s.begin(), s.end(), [](const PrimRef& p) { return p.kind == PrimKind::kTriangle; });
      split_at(index, s, static_cast<uint32_t>(mid - s.data), bounds.box, level);
      return;
    }
    Vec3f extent = bounds.centroids.extent();
    if (level.depth >= kSahDepthLimit || max_component(extent) <= 0.0f) {
      // No spatial order left to exploit (or the depth guard): a leaf if it fits, else halve by count.
      if (!mixed && n <= max_leaf_) {
        make_leaf(index, s, bounds.box);
      } else {
        split_at(index, s, n / 2, bounds.box, level);
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
    // small fraction of the root's surface (Stich et al. 2009, section 4.5: alpha), in nodes of at
    // least spatial_split_min_refs references, while the subtree's room for added references lasts;
    // one is taken where its SAH cost is lower and its added references fit that room. Where
    // spatial_split_misses tries in a row on the way down lost to the object split, the subtree
    // tries no more: on meshes of nearly equilateral triangles (the bunny, the dense meshes) one in
    // 60 tries won, and binning them tripled the build; on scans a third win.
    SpatialSplit spatial;
    std::optional<SpatialMapping> smap;
    if (triangles && mesh_ && best_axis >= 0 && s.cap > s.size && n >= options_.spatial_split_min_refs &&
        level.misses < options_.spatial_split_misses) {
      BBox left, right;
      const auto& bins = binning.bins[best_axis];
      for (int i = 0; i < kBins; ++i) (i < best_plane ? left : right).expand(bins[i].box());
      BBox overlap;
      overlap.lo = vmax(left.lo, right.lo);
      overlap.hi = vmin(left.hi, right.hi);
      // A node larger than the typical box holds some of the outliers (the ground): relative to the
      // root there, so that they are not cut up across the model's subtrees.
      float reference = bounds.box.surface_area() > split_area_ ? root_area_ : split_area_;
      if (overlap.surface_area() > options_.spatial_split_alpha * reference) {
        spatial = find_spatial_split(s, smap.emplace(bounds.box));
        if (int64_t(spatial.left) + spatial.right - n > int64_t(s.cap) - s.size) spatial = SpatialSplit{};
        level.misses = spatial.cost < best_cost ? 0 : level.misses + 1;
      }
    }
    bool use_spatial = spatial.cost < best_cost;
    float area = bounds.box.surface_area();
    float leaf_cost = leaf_cost_(n);
    float split_cost = options_.traversal_cost + (area > 0.0f ? std::min(best_cost, spatial.cost) / area : 0.0f);
    // SAH takes rays to come from outside a box, where the chance to enter it grows with its area;
    // but a box around a whole room contains every ray that starts in the room. Large boxes (the
    // room's walls, grouped) therefore hold few primitives, so that a ray tests only the walls it
    // can reach. Not a flat box: a ray enters it only where it crosses its plane, as SAH prices it,
    // and the studio's ground rings (a flat box of 8-16 triangles around the model) held two a leaf
    // cost a ground ray 3.3 leaves where one pack pair does.
    Vec3f size = bounds.box.extent();
    bool flat = options_.large_leaf_flat &&
                std::min({size.x, size.y, size.z}) <= 1e-6f * std::max({size.x, size.y, size.z});
    uint32_t max_leaf = area > options_.large_leaf_area * root_area_ && !flat ? std::min<uint32_t>(2, max_leaf_)
                                                                                : max_leaf_;
    if (n > max_leaf && n <= max_leaf_ && best_axis < 0 && !use_spatial) {
      split_at(index, s, n / 2, bounds.box, level);
      return;
    }
    if (!mixed && n <= max_leaf &&
        ((best_axis < 0 && !use_spatial) || leaf_cost <= split_cost)) {
      if (uint32_t k = options_.split_planes ? plane_part(s, bounds.box) : 0) {
        split_at(index, s, k, bounds.box, level);
        return;
      }
      make_leaf(index, s, bounds.box);
      return;
    }
    if (use_spatial) {
      if (auto children = apply_spatial_split(s, spatial, *smap)) {
        split_into(index, children->first, children->second, bounds.box, level);
        return;
      }
    }
    if (best_axis < 0) {
      split_at(index, s, n / 2, bounds.box, level);
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
    auto [left, right] = divide(s, static_cast<uint32_t>(mid - s.data));
    split_into(index, left, right, bounds.box, level, lb, rb);
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
  uint32_t max_leaf_;  // options_.max_leaf, or its default for this many references
  const Mesh* mesh_;
  LeafCost leaf_cost_;
  float root_area_ = 0.0f;
  float split_area_ = 0.0f;  // what spatial_split_alpha is a fraction of (typical_area)
  size_t n_ = 0, room_ = 0;         // references, and room for them and those spatial splits add
  std::atomic<size_t> added_{0};
  struct Release {
    void operator()(TmpNode* p) const { std::free(p); }
  };
  std::unique_ptr<TmpNode[], Release> nodes_;  // TmpNode is trivially destructible
  std::atomic<uint32_t> next_{0};
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
