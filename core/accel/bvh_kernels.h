// The per-node and per-pack tests of the BVH traversal (bvh_accel.cpp), in a header so that the
// tests can hold the SIMD versions against the scalar ones.
#pragma once
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <cstring>

#include "core/accel/bvh_build.h"
#include "core/geometry/intersect.h"

namespace pt::bvh {


// Per-ray constants of the slab test. A zero direction component would give 0 * inf = NaN for a
// ray starting exactly on a slab plane; replacing it by a tiny value keeps the arithmetic finite.
struct RayBoxPre {
  Vec3f o, inv;
  int near[3], far[3];  // row of WideNode::q holding the near / far plane of each axis
  explicit RayBoxPre(const Ray& r) : o(r.o) {
    for (int a = 0; a < 3; ++a) {
      float d = r.d[a];
      if (std::abs(d) < 1e-30f) d = std::copysign(1e-30f, d);
      inv[a] = 1.0f / d;
      near[a] = 2 * a + (r.d[a] < 0.0f ? 1 : 0);
      far[a] = 2 * a + (r.d[a] < 0.0f ? 0 : 1);
    }
  }
};

// Float rounding in (plane - o) * inv can put an exit distance an ulp or two in front of the entry
// distance for a box of zero thickness (an axis-aligned wall); scaling the exit distance by
// 1 + 2 gamma(3) makes the test conservative (Ize, "Robust BVH Ray Traversal", JCGT 2013).
constexpr float kFarScale = 1.0f + 6.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f);

// Tests all children of `node`; returns a bit mask of those the ray enters within [tmin, tmax] and
// writes their entry distances. The planes are decoded first (see WideNode) and then tested as
// floats: (plane - o) * inv, not fma(plane, inv, -o * inv), because the rounding of o * inv is
// relative to o, not to the distance, and far from the origin it makes the test miss boxes the ray
// enters.
#if defined(__AVX2__)
struct NodeTest {
  __m256 ox, oy, oz, ix, iy, iz;
  int near[3], far[3];
  explicit NodeTest(const RayBoxPre& pre)
      : ox(_mm256_set1_ps(pre.o.x)), oy(_mm256_set1_ps(pre.o.y)), oz(_mm256_set1_ps(pre.o.z)),
        ix(_mm256_set1_ps(pre.inv.x)), iy(_mm256_set1_ps(pre.inv.y)), iz(_mm256_set1_ps(pre.inv.z)) {
    for (int a = 0; a < 3; ++a) {
      near[a] = pre.near[a];
      far[a] = pre.far[a];
    }
  }

  uint32_t operator()(const WideNode& node, float tmin, float tmax, float* tnear) const {
    int32_t packed;  // the three exponents and the valid mask
    std::memcpy(&packed, node.exponent, sizeof(packed));
    __m128i e = _mm_cvtepi8_epi32(_mm_cvtsi32_si128(packed));
    __m256 scales = _mm256_castps128_ps256(_mm_castsi128_ps(_mm_slli_epi32(_mm_add_epi32(e, _mm_set1_epi32(127)), 23)));
    __m256 sx = _mm256_permutevar8x32_ps(scales, _mm256_set1_epi32(0));
    __m256 sy = _mm256_permutevar8x32_ps(scales, _mm256_set1_epi32(1));
    __m256 sz = _mm256_permutevar8x32_ps(scales, _mm256_set1_epi32(2));
    __m256 gx = _mm256_broadcast_ss(&node.origin[0]), gy = _mm256_broadcast_ss(&node.origin[1]),
           gz = _mm256_broadcast_ss(&node.origin[2]);
    auto plane = [&](int row, __m256 scale, __m256 origin) {
      __m256 q = _mm256_cvtepi32_ps(_mm256_cvtepu8_epi32(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(node.q[row]))));
      // q * scale is exact, so with or without FMA this is the one rounding the builder checked.
#if defined(__FMA__)
      return _mm256_fmadd_ps(q, scale, origin);
#else
      return _mm256_add_ps(_mm256_mul_ps(q, scale), origin);
#endif
    };
    __m256 nx = _mm256_mul_ps(_mm256_sub_ps(plane(near[0], sx, gx), ox), ix);
    __m256 ny = _mm256_mul_ps(_mm256_sub_ps(plane(near[1], sy, gy), oy), iy);
    __m256 nz = _mm256_mul_ps(_mm256_sub_ps(plane(near[2], sz, gz), oz), iz);
    __m256 fx = _mm256_mul_ps(_mm256_sub_ps(plane(far[0], sx, gx), ox), ix);
    __m256 fy = _mm256_mul_ps(_mm256_sub_ps(plane(far[1], sy, gy), oy), iy);
    __m256 fz = _mm256_mul_ps(_mm256_sub_ps(plane(far[2], sz, gz), oz), iz);
    __m256 tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, _mm256_set1_ps(tmin)));
    __m256 tf = _mm256_min_ps(_mm256_min_ps(fx, fy), _mm256_min_ps(fz, _mm256_set1_ps(tmax)));
    tf = _mm256_mul_ps(tf, _mm256_set1_ps(kFarScale));
    _mm256_store_ps(tnear, tn);
    return static_cast<uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ))) & node.valid;
  }
};
#endif

// The same arithmetic one child at a time (origin + q * scale is exact to one rounding here too, see
// WideNode): traversal's node test without AVX2, and the tests' reference for the AVX2 one.
struct NodeTestScalar {
  RayBoxPre pre;
  explicit NodeTestScalar(const RayBoxPre& p) : pre(p) {}

  uint32_t operator()(const WideNode& node, float tmin, float tmax, float* tnear) const {
    float scale[3];
    for (int a = 0; a < 3; ++a) scale[a] = node.scale(a);
    uint32_t mask = 0;
    for (int i = 0; i < kWidth; ++i) {
      if (!(node.valid & (1u << i))) continue;
      float tn = tmin, tf = tmax;
      for (int a = 0; a < 3; ++a) {
        float near = node.origin[a] + static_cast<float>(node.q[pre.near[a]][i]) * scale[a];
        float far = node.origin[a] + static_cast<float>(node.q[pre.far[a]][i]) * scale[a];
        tn = std::max(tn, (near - pre.o[a]) * pre.inv[a]);
        tf = std::min(tf, (far - pre.o[a]) * pre.inv[a]);
      }
      tnear[i] = tn;
      if (tn <= tf * kFarScale) mask |= 1u << i;
    }
    return mask;
  }
};
#if !defined(__AVX2__)
using NodeTest = NodeTestScalar;
#endif

// Möller-Trumbore on four triangles at once (a pack in PackLayout::kEdges), operation for operation
// the scalar intersect_triangle_mt_edges, so both give the same t, u, v. Returns the mask of lanes hit in (tmin, tmax).
// The barycentric tests run on the undivided values with the sign of the determinant folded in, so
// the division (and t) is only computed when some lane's triangle contains the ray's line, which
// for most packs none does.
struct PackHits {
  alignas(16) float t[4], u[4], v[4];
};

#if defined(__SSE2__)
inline uint32_t intersect_pack_mt(const TriPack& p, const Ray& ray, float tmax, PackHits& out) {
  __m128 dx = _mm_set1_ps(ray.d.x), dy = _mm_set1_ps(ray.d.y), dz = _mm_set1_ps(ray.d.z);
  __m128 v0x = _mm_load_ps(p.v[0]), v0y = _mm_load_ps(p.v[1]), v0z = _mm_load_ps(p.v[2]);
  __m128 e1x = _mm_load_ps(p.v[3]), e1y = _mm_load_ps(p.v[4]), e1z = _mm_load_ps(p.v[5]);
  __m128 e2x = _mm_load_ps(p.v[6]), e2y = _mm_load_ps(p.v[7]), e2z = _mm_load_ps(p.v[8]);
  // pvec = cross(d, e2)
  __m128 px = _mm_sub_ps(_mm_mul_ps(dy, e2z), _mm_mul_ps(dz, e2y));
  __m128 py = _mm_sub_ps(_mm_mul_ps(dz, e2x), _mm_mul_ps(dx, e2z));
  __m128 pz = _mm_sub_ps(_mm_mul_ps(dx, e2y), _mm_mul_ps(dy, e2x));
  __m128 det = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e1x, px), _mm_mul_ps(e1y, py)), _mm_mul_ps(e1z, pz));
  __m128 sign = _mm_and_ps(det, _mm_set1_ps(-0.0f));
  __m128 abs_det = _mm_xor_ps(det, sign);
  __m128 tx = _mm_sub_ps(_mm_set1_ps(ray.o.x), v0x), ty = _mm_sub_ps(_mm_set1_ps(ray.o.y), v0y),
         tz = _mm_sub_ps(_mm_set1_ps(ray.o.z), v0z);
  __m128 u = _mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, px), _mm_mul_ps(ty, py)), _mm_mul_ps(tz, pz));
  // qvec = cross(tvec, e1)
  __m128 qx = _mm_sub_ps(_mm_mul_ps(ty, e1z), _mm_mul_ps(tz, e1y));
  __m128 qy = _mm_sub_ps(_mm_mul_ps(tz, e1x), _mm_mul_ps(tx, e1z));
  __m128 qz = _mm_sub_ps(_mm_mul_ps(tx, e1y), _mm_mul_ps(ty, e1x));
  __m128 v = _mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, qx), _mm_mul_ps(dy, qy)), _mm_mul_ps(dz, qz));
  __m128 us = _mm_xor_ps(u, sign), vs = _mm_xor_ps(v, sign);
  __m128 ok = _mm_and_ps(_mm_cmpgt_ps(abs_det, _mm_setzero_ps()), _mm_cmplt_ps(abs_det, _mm_set1_ps(kInf)));
  ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpge_ps(us, _mm_setzero_ps()), _mm_cmpge_ps(vs, _mm_setzero_ps())));
  ok = _mm_and_ps(ok, _mm_cmple_ps(_mm_add_ps(us, vs), abs_det));
  if (_mm_movemask_ps(ok) == 0) return 0;
  __m128 inv_det = _mm_div_ps(_mm_set1_ps(1.0f), det);
  __m128 t = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(e2x, qx), _mm_mul_ps(e2y, qy)), _mm_mul_ps(e2z, qz)), inv_det);
  ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(t, _mm_set1_ps(ray.tmin)), _mm_cmplt_ps(t, _mm_set1_ps(tmax))));
  uint32_t mask = static_cast<uint32_t>(_mm_movemask_ps(ok));
  if (mask) {
    _mm_store_ps(out.t, t);
    _mm_store_ps(out.u, _mm_mul_ps(u, inv_det));
    _mm_store_ps(out.v, _mm_mul_ps(v, inv_det));
  }
  return mask;
}
#endif

// The three rows of a lane: corners or p0 and the edges, by the pack's layout.
inline void pack_rows(const TriPack& p, int lane, Vec3f& a, Vec3f& b, Vec3f& c) {
  a = {p.v[0][lane], p.v[1][lane], p.v[2][lane]};
  b = {p.v[3][lane], p.v[4][lane], p.v[5][lane]};
  c = {p.v[6][lane], p.v[7][lane], p.v[8][lane]};
}

// The layout each triangle test reads.
template <TriangleTest kTest>
constexpr PackLayout kPackLayout = kTest == TriangleTest::kWatertight ? PackLayout::kVertices : PackLayout::kEdges;

// Tests the four triangles of a pack one at a time, with either scalar test: the watertight one
// (kVertices), and Möller-Trumbore (kEdges) where there is no SSE.
template <TriangleTest kTest>
uint32_t intersect_pack_scalar(const TriPack& p, const Ray& ray, const WatertightRay& wt, float tmax, PackHits& out) {
  Ray r = ray;
  r.tmax = tmax;
  uint32_t mask = 0;
  for (int lane = 0; lane < 4; ++lane) {
    if (p.prim[lane] == kNoPrim) break;
    Vec3f a, b, c;
    pack_rows(p, lane, a, b, c);
    bool ok = kTest == TriangleTest::kWatertight
                  ? intersect_triangle_watertight(r, wt, a, b, c, out.t[lane], out.u[lane], out.v[lane])
                  : intersect_triangle_mt_edges(r, a, b, c, out.t[lane], out.u[lane], out.v[lane]);
    if (ok) mask |= 1u << lane;
  }
  return mask;
}

}  // namespace pt::bvh
