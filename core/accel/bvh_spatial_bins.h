// The bins of spatial splits (Stich, Friedrich and Dietrich, "Spatial Splits in Bounding Volume
// Hierarchies", HPG 2009, section 4): a node's box cut into kSpatialBins equal slabs per axis. Each
// bin holds the box of the references' parts in its slab, and counts the references that enter
// (have their first part) and exit (their last) there. Only the builder (bvh_build.cpp) uses them.
//
// The bins only estimate each plane's SAH cost; the split that is applied clips the straddling
// triangles exactly (bvh_clip.h). So a triangle's part in a slab is bounded here in float, without
// clipping a polygon per slab: by the triangle's corners in the slab and its edges' crossings of the
// slab's two planes (the corners of the part), cut down to the reference's box. Clipping polygons
// per slab made a build with spatial splits 15 times longer than one without (the bunny).
#pragma once
#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include <algorithm>
#include <array>
#include <cstdint>

#include "core/accel/bvh_build.h"
#include "core/accel/bvh_sah_bins.h"
#include "core/geometry/mesh.h"
#include "core/math/bbox.h"

namespace pt::bvh::sah {

constexpr int kSpatialBins = 16;

struct SpatialBin {
  alignas(16) float lo[4] = {kInf, kInf, kInf, kInf};
  alignas(16) float hi[4] = {-kInf, -kInf, -kInf, -kInf};
  uint32_t enter = 0, exit = 0;

  BBox box() const { return Bin::rows(lo, hi); }
  void expand(const BBox& b) {
    for (int a = 0; a < 3; ++a) {
      lo[a] = std::min(lo[a], b.lo[a]);
      hi[a] = std::max(hi[a], b.hi[a]);
    }
  }
#if defined(__SSE2__)
  void expand(__m128 rlo, __m128 rhi) {
    _mm_store_ps(lo, _mm_min_ps(rlo, _mm_load_ps(lo)));
    _mm_store_ps(hi, _mm_max_ps(rhi, _mm_load_ps(hi)));
  }
#endif
  void merge(const SpatialBin& o) {
    expand(o.box());
    enter += o.enter;
    exit += o.exit;
  }
};

struct SpatialBinning {
  std::array<std::array<SpatialBin, kSpatialBins>, 3> bins;
  void merge(const SpatialBinning& o) {
    for (int axis = 0; axis < 3; ++axis)
      for (int i = 0; i < kSpatialBins; ++i) bins[axis][i].merge(o.bins[axis][i]);
  }
};

// The slabs of a box: bin(x) is the slab a coordinate falls in, plane(k) the plane before slab k (in
// double, for the exact clipping), planef the same rounded to float (for the binning's estimate).
struct SpatialMapping {
  Vec3f origin, scale;
  double step[3];
  float planef[3][kSpatialBins + 1];

  explicit SpatialMapping(const BBox& box) : origin(box.lo) {
    Vec3f extent = box.extent();
    for (int axis = 0; axis < 3; ++axis) {
      scale[axis] = extent[axis] > 0.0f ? kSpatialBins * (1.0f - 1e-6f) / extent[axis] : 0.0f;
      step[axis] = static_cast<double>(extent[axis]) / kSpatialBins;
      for (int k = 0; k <= kSpatialBins; ++k) planef[axis][k] = static_cast<float>(plane(axis, k));
    }
  }
  int bin(float x, int axis) const {
    int b = static_cast<int>((x - origin[axis]) * scale[axis]);
    return std::clamp(b, 0, kSpatialBins - 1);
  }
  double plane(int axis, int k) const { return static_cast<double>(origin[axis]) + step[axis] * k; }
};

#if defined(__SSE2__)
// A reference whose box straddles a plane on some axis (b0, b1: its first and last slab per axis;
// lo, hi: its box as rows). Along each straddled axis the triangle's corners are taken in order,
// a <= b <= c; its cross-section at a coordinate x is the segment between its edges ac and ab (x
// <= b) or bc, and its part in a slab is bounded by the cross-sections at the slab's two planes
// and the corner b where b lies inside: one cross-section per plane, carried from slab to slab.
inline void bin_straddling(const PrimRef& r, const int* b0, const int* b1, __m128 lo, __m128 hi,
                           const SpatialMapping& map, const Mesh& mesh, SpatialBinning& out) {
  const uint32_t* idx = &mesh.indices[3 * size_t(r.index)];
  const Vec3f* p[3] = {&mesh.positions[idx[0]], &mesh.positions[idx[1]], &mesh.positions[idx[2]]};
  for (int axis = 0; axis < 3; ++axis) {
    auto& bins = out.bins[axis];
    int first = b0[axis], last = b1[axis];
    bins[first].enter++;
    bins[last].exit++;
    if (first == last) {
      bins[first].expand(lo, hi);
      continue;
    }
    const Vec3f* s[3] = {p[0], p[1], p[2]};
    if ((*s[1])[axis] < (*s[0])[axis]) std::swap(s[0], s[1]);
    if ((*s[2])[axis] < (*s[1])[axis]) std::swap(s[1], s[2]);
    if ((*s[1])[axis] < (*s[0])[axis]) std::swap(s[0], s[1]);
    float ax = (*s[0])[axis], bx = (*s[1])[axis], cx = (*s[2])[axis];
    __m128 a = _mm_setr_ps(s[0]->x, s[0]->y, s[0]->z, 0.0f);
    __m128 b = _mm_setr_ps(s[1]->x, s[1]->y, s[1]->z, 0.0f);
    __m128 c = _mm_setr_ps(s[2]->x, s[2]->y, s[2]->z, 0.0f);
    __m128 ac = _mm_sub_ps(c, a), ab = _mm_sub_ps(b, a), bc = _mm_sub_ps(c, b);
    float iac = cx > ax ? 1.0f / (cx - ax) : 0.0f, iab = bx > ax ? 1.0f / (bx - ax) : 0.0f;
    float ibc = cx > bx ? 1.0f / (cx - bx) : 0.0f;
    auto section = [&](float x, __m128& slo, __m128& shi) {
      x = std::clamp(x, ax, cx);
      __m128 u = _mm_add_ps(a, _mm_mul_ps(ac, _mm_set1_ps(std::min((x - ax) * iac, 1.0f))));
      __m128 v = x <= bx ? _mm_add_ps(a, _mm_mul_ps(ab, _mm_set1_ps(std::min((x - ax) * iab, 1.0f))))
                         : _mm_add_ps(b, _mm_mul_ps(bc, _mm_set1_ps(std::min((x - bx) * ibc, 1.0f))));
      slo = _mm_min_ps(u, v);
      shi = _mm_max_ps(u, v);
    };
    __m128 llo, lhi;
    section(map.planef[axis][first], llo, lhi);
    for (int k = first; k <= last; ++k) {
      __m128 rlo, rhi;
      section(map.planef[axis][k + 1], rlo, rhi);
      __m128 plo = _mm_min_ps(llo, rlo), phi = _mm_max_ps(lhi, rhi);
      if (bx > map.planef[axis][k] && bx < map.planef[axis][k + 1]) {
        plo = _mm_min_ps(plo, b);
        phi = _mm_max_ps(phi, b);
      }
      __m128 l = _mm_max_ps(plo, lo), h = _mm_min_ps(phi, hi);
      if ((_mm_movemask_ps(_mm_cmpgt_ps(l, h)) & 7) == 0) bins[k].expand(l, h);
      llo = rlo;
      lhi = rhi;
    }
  }
}
#endif

// Bins the references [first, last) of a node into `out`, or with `stride` > 1 every stride-th of
// them.
inline void spatial_bin(const PrimRef* first, const PrimRef* last, const SpatialMapping& map, const Mesh& mesh,
                        SpatialBinning& out, size_t stride = 1) {
#if defined(__SSE2__)
  // Most references of a large node lie in one slab on every axis: those take the arithmetic of
  // SpatialMapping::bin four lanes at once, and one SSE min and max per axis.
  const __m128 keep = _mm_castsi128_ps(_mm_set_epi32(0, -1, -1, -1));
  const __m128 origin = _mm_setr_ps(map.origin.x, map.origin.y, map.origin.z, 0.0f);
  const __m128 scale = _mm_setr_ps(map.scale.x, map.scale.y, map.scale.z, 0.0f);
  size_t n = static_cast<size_t>(last - first);
  for (size_t i = 0; i < n; i += stride) {
    const PrimRef* r = first + i;
    __m128 lo = _mm_and_ps(_mm_loadu_ps(&r->lo.x), keep), hi = _mm_and_ps(_mm_loadu_ps(&r->hi.x), keep);
    alignas(16) int32_t c0[4], c1[4];
    _mm_store_si128(reinterpret_cast<__m128i*>(c0), _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(lo, origin), scale)));
    _mm_store_si128(reinterpret_cast<__m128i*>(c1), _mm_cvttps_epi32(_mm_mul_ps(_mm_sub_ps(hi, origin), scale)));
    int b0[3], b1[3];
    for (int axis = 0; axis < 3; ++axis) {
      b0[axis] = std::clamp(c0[axis], 0, kSpatialBins - 1);
      b1[axis] = std::clamp(c1[axis], 0, kSpatialBins - 1);
    }
    if (b0[0] != b1[0] || b0[1] != b1[1] || b0[2] != b1[2]) {
      bin_straddling(*r, b0, b1, lo, hi, map, mesh, out);
      continue;
    }
    for (int axis = 0; axis < 3; ++axis) {
      SpatialBin& bin = out.bins[axis][b0[axis]];
      bin.enter++;
      bin.exit++;
      bin.expand(lo, hi);
    }
  }
#else
  // The same bounds, one coordinate at a time.
  size_t n = static_cast<size_t>(last - first);
  for (size_t i = 0; i < n; i += stride) {
    const PrimRef* r = first + i;
    BBox box;
    box.lo = r->lo;
    box.hi = r->hi;
    const uint32_t* idx = &mesh.indices[3 * size_t(r->index)];
    const Vec3f* p[3] = {&mesh.positions[idx[0]], &mesh.positions[idx[1]], &mesh.positions[idx[2]]};
    for (int axis = 0; axis < 3; ++axis) {
      auto& bins = out.bins[axis];
      int first_bin = map.bin(r->lo[axis], axis), last_bin = map.bin(r->hi[axis], axis);
      bins[first_bin].enter++;
      bins[last_bin].exit++;
      if (first_bin == last_bin) {
        bins[first_bin].expand(box);
        continue;
      }
      std::array<BBox, kSpatialBins> part;
      for (int c = 0; c < 3; ++c) part[std::clamp(map.bin((*p[c])[axis], axis), first_bin, last_bin)].expand(*p[c]);
      for (int e = 0; e < 3; ++e) {
        const Vec3f& a = *p[e];
        const Vec3f& b = *p[e == 2 ? 0 : e + 1];
        if (a[axis] == b[axis]) continue;
        int k0 = std::max(first_bin + 1, map.bin(std::min(a[axis], b[axis]), axis) + 1);
        int k1 = std::min(last_bin, map.bin(std::max(a[axis], b[axis]), axis));
        Vec3f d = b - a;
        float inv = 1.0f / d[axis];
        for (int k = k0; k <= k1; ++k) {
          float at = map.planef[axis][k];
          Vec3f x = a + d * std::clamp((at - a[axis]) * inv, 0.0f, 1.0f);
          x[axis] = at;
          part[k - 1].expand(x);
          part[k].expand(x);
        }
      }
      for (int k = first_bin; k <= last_bin; ++k) {
        BBox cut;
        cut.lo = vmax(part[k].lo, box.lo);
        cut.hi = vmin(part[k].hi, box.hi);
        if (!cut.empty()) bins[k].expand(cut);
      }
    }
  }
#endif
}

}  // namespace pt::bvh::sah
