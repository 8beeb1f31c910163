// The binned SAH's pieces (Wald, "On fast Construction of SAH-based Bounding Volume Hierarchies",
// IRT 2007): the bins of object splits and the sweep over the planes of any bins (the spatial
// splits' bins are in bvh_spatial_bins.h).
// Only the builder (bvh_build.cpp) uses them.
#pragma once
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cstdint>

#include "core/accel/bvh_build.h"
#include "core/math/bbox.h"

namespace pt::bvh::sah {

constexpr int kBins = 32;

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

}  // namespace pt::bvh::sah
