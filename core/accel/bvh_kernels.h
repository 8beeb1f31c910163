// The per-node and per-pack tests of the BVH traversal (bvh_accel.cpp), in a header so that the
// tests can hold the SIMD versions against the scalar ones.
#pragma once
#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <array>
#include <bit>
#include <cstring>
#include <type_traits>

#include "core/accel/accel.h"
#include "core/accel/bvh_build.h"
#include "core/geometry/intersect.h"

// The kernels are compiled once per instruction set (bvh_accel_sse42.cpp, bvh_accel_avx2.cpp,
// bvh_accel_avx512.cpp, each under #pragma GCC target): such a file defines PT_BVH_ISA to name the
// namespace its copy lives in, so the copies never share a symbol (the linker would otherwise keep
// one of them for all), and PT_BVH_AVX2 to switch the eight-lane code on (GCC's pragma does not
// define __AVX2__ for C++). Other includers get the build's own flags, in `native`.
#if !defined(PT_BVH_ISA)
#define PT_BVH_ISA native
#endif
// PT_BVH_EXP: 1 only in the experimental copy (bvh_accel_experiment.cpp, -DPT_BVH_EXPERIMENT=ON),
// where a change under `#if PT_BVH_EXP` is timed against the kernels without it in one process.
#if !defined(PT_BVH_EXP)
#define PT_BVH_EXP 0
#endif
#if !defined(PT_BVH_AVX512)
#define PT_BVH_AVX512 0  // AVX-512 DQ and VL: vrangeps for max(|a|, |b|)
#endif
#if !defined(PT_BVH_AVX2)
#if defined(__AVX2__) && defined(__FMA__)
#define PT_BVH_AVX2 1
#else
#define PT_BVH_AVX2 0
#endif
#endif

namespace pt::bvh {
inline namespace PT_BVH_ISA {


// Per-ray constants of the slab test. A zero direction component would give 0 * inf = NaN for a
// ray starting exactly on a slab plane; replacing it by a tiny value keeps the arithmetic finite.
// The near plane of an axis is the one the component's sign bit picks, the sign its reciprocal
// has: for -0 (inverse -1e30) the upper one. (Taken by `d < 0`, which is false for -0, the near
// plane was the lower one while the inverse was negative, and such a ray missed every box.)
//
// Float rounding in (plane - o) * inv can put an exit distance an ulp or two in front of the entry
// distance for a box of zero thickness (an axis-aligned wall). Ize ("Robust BVH Ray Traversal",
// JCGT 2013) scales each exit distance by 1 + 2 gamma(3); here the exit planes' reciprocals are
// scaled instead, once per ray, by kFarInvScale = 1 + 2^-20, which takes one multiplication off
// every node's chain of dependent operations (in one process, 54 rows on 9 meshes: 0.98 of the
// time). It is as conservative: with u = 2^-24, a computed entry distance is at most (1 + u)^3
// times the exact one (the reciprocal, the difference, the product), a computed exit distance at
// least (1 + 2^-20)(1 - u)^4 > 1 + 11u times it, so every box the ray enters in exact arithmetic
// is entered. tmax is scaled by kFarScale = 1 + 2 gamma(3) as before.
constexpr float kFarScale = 1.0f + 6.0f * 0x1p-24f / (1.0f - 3.0f * 0x1p-24f);
constexpr float kFarInvScale = 1.0f + 0x1p-20f;

struct RayBoxPre {
  Vec3f o, inv, inv_far;  // inv_far = inv * kFarInvScale, for the exit planes
  int near[3], far[3];  // row of WideNode::q holding the near / far plane of each axis
  explicit RayBoxPre(const Ray& r) : o(r.o) {
    for (int a = 0; a < 3; ++a) {
      float d = r.d[a];
      int negative = std::signbit(d) ? 1 : 0;
      if (std::abs(d) < 1e-30f) d = std::copysign(1e-30f, d);
      inv[a] = 1.0f / d;
      inv_far[a] = inv[a] * kFarInvScale;
      near[a] = 2 * a + negative;
      far[a] = 2 * a + 1 - negative;
    }
  }
};

// Tests all children of `node`; returns a bit mask of those the ray enters within [tmin, tmax] and
// writes their entry distances. The planes are decoded first (see WideNode) and then tested as
// floats: (plane - o) * inv, not fma(plane, inv, -o * inv), because the rounding of o * inv is
// relative to o, not to the distance, and far from the origin it makes the test miss boxes the ray
// enters.
#if PT_BVH_AVX2
struct NodeTest {
  __m256 ox, oy, oz, ix, iy, iz, fx, fy, fz;  // f: the exit planes' reciprocals (kFarInvScale)
  int near[3], far[3];
  // RayBoxPre's values with one four-lane division instead of three scalar ones, and the rows from
  // a movemask of the sign bits: the same bits (division is correctly rounded in every lane). A
  // ray's first node tests wait on the divisions' latency, which on small meshes, where a shadow
  // ray visits two or three nodes, is a good part of its time.
  explicit NodeTest(const Ray& r)
      : ox(_mm256_set1_ps(r.o.x)), oy(_mm256_set1_ps(r.o.y)), oz(_mm256_set1_ps(r.o.z)) {
    const __m128 minus = _mm_set1_ps(-0.0f), tiny = _mm_set1_ps(1e-30f);
    __m128 d = _mm_setr_ps(r.d.x, r.d.y, r.d.z, 1.0f);
    __m128 sign = _mm_and_ps(d, minus);
    d = _mm_blendv_ps(d, _mm_or_ps(sign, tiny), _mm_cmplt_ps(_mm_andnot_ps(minus, d), tiny));
    alignas(16) float inv[4];
    _mm_store_ps(inv, _mm_div_ps(_mm_set1_ps(1.0f), d));
    ix = _mm256_set1_ps(inv[0]);
    iy = _mm256_set1_ps(inv[1]);
    iz = _mm256_set1_ps(inv[2]);
    fx = _mm256_mul_ps(ix, _mm256_set1_ps(kFarInvScale));
    fy = _mm256_mul_ps(iy, _mm256_set1_ps(kFarInvScale));
    fz = _mm256_mul_ps(iz, _mm256_set1_ps(kFarInvScale));
    int negative = _mm_movemask_ps(sign);
    for (int a = 0; a < 3; ++a) {
      near[a] = 2 * a + ((negative >> a) & 1);
      far[a] = 2 * a + 1 - ((negative >> a) & 1);
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
#if PT_BVH_AVX2
      return _mm256_fmadd_ps(q, scale, origin);
#else
      return _mm256_add_ps(_mm256_mul_ps(q, scale), origin);
#endif
    };
    __m256 nx = _mm256_mul_ps(_mm256_sub_ps(plane(near[0], sx, gx), ox), ix);
    __m256 ny = _mm256_mul_ps(_mm256_sub_ps(plane(near[1], sy, gy), oy), iy);
    __m256 nz = _mm256_mul_ps(_mm256_sub_ps(plane(near[2], sz, gz), oz), iz);
    __m256 ex = _mm256_mul_ps(_mm256_sub_ps(plane(far[0], sx, gx), ox), fx);
    __m256 ey = _mm256_mul_ps(_mm256_sub_ps(plane(far[1], sy, gy), oy), fy);
    __m256 ez = _mm256_mul_ps(_mm256_sub_ps(plane(far[2], sz, gz), oz), fz);
    __m256 tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, _mm256_set1_ps(tmin)));
    __m256 tf = _mm256_min_ps(_mm256_min_ps(ex, ey), _mm256_min_ps(ez, _mm256_set1_ps(tmax * kFarScale)));
    _mm256_store_ps(tnear, tn);
    return entered(tn, tf, node.valid);
  }

  // The same test on exact float planes (an empty child's box is empty: every ray misses it).
  uint32_t operator()(const WideNodeF& node, float tmin, float tmax, float* tnear) const {
    __m256 nx = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.plane[near[0]]), ox), ix);
    __m256 ny = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.plane[near[1]]), oy), iy);
    __m256 nz = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.plane[near[2]]), oz), iz);
    __m256 ex = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.plane[far[0]]), ox), fx);
    __m256 ey = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.plane[far[1]]), oy), fy);
    __m256 ez = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.plane[far[2]]), oz), fz);
    __m256 tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, _mm256_set1_ps(tmin)));
    __m256 tf = _mm256_min_ps(_mm256_min_ps(ex, ey), _mm256_min_ps(ez, _mm256_set1_ps(tmax * kFarScale)));
    _mm256_store_ps(tnear, tn);
    return entered(tn, tf);
  }

 private:
  // tn <= tf lane by lane, as bits, in the lanes of `valid`. With AVX-512 the comparison writes a
  // mask register, one step shorter than a vector compare and a movemask (in one process: 0.995 of
  // the time).
  static uint32_t entered(__m256 tn, __m256 tf, uint8_t valid = 0xff) {
#if PT_BVH_AVX512
    return static_cast<uint32_t>(_mm256_mask_cmp_ps_mask(valid, tn, tf, _CMP_LE_OQ));
#else
    return static_cast<uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ))) & valid;
#endif
  }
};
#endif

// The same arithmetic one child at a time (origin + q * scale is exact to one rounding here too, see
// WideNode): traversal's node test without AVX2, and the tests' reference for the AVX2 one.
struct NodeTestScalar {
  RayBoxPre pre;
  explicit NodeTestScalar(const RayBoxPre& p) : pre(p) {}
  explicit NodeTestScalar(const Ray& r) : pre(r) {}

  uint32_t operator()(const WideNode& node, float tmin, float tmax, float* tnear) const {
    float scale[3];
    for (int a = 0; a < 3; ++a) scale[a] = node.scale(a);
    uint32_t mask = 0;
    for (int i = 0; i < kWidth; ++i) {
      if (!(node.valid & (1u << i))) continue;
      float tn = tmin, tf = tmax * kFarScale;
      for (int a = 0; a < 3; ++a) {
        float near = node.origin[a] + static_cast<float>(node.q[pre.near[a]][i]) * scale[a];
        float far = node.origin[a] + static_cast<float>(node.q[pre.far[a]][i]) * scale[a];
        tn = std::max(tn, (near - pre.o[a]) * pre.inv[a]);
        tf = std::min(tf, (far - pre.o[a]) * pre.inv_far[a]);
      }
      tnear[i] = tn;
      if (tn <= tf) mask |= 1u << i;
    }
    return mask;
  }

  uint32_t operator()(const WideNodeF& node, float tmin, float tmax, float* tnear) const {
    uint32_t mask = 0;
    for (int i = 0; i < kWidth; ++i) {
      float tn = tmin, tf = tmax * kFarScale;
      for (int a = 0; a < 3; ++a) {
        tn = std::max(tn, (node.plane[pre.near[a]][i] - pre.o[a]) * pre.inv[a]);
        tf = std::min(tf, (node.plane[pre.far[a]][i] - pre.o[a]) * pre.inv_far[a]);
      }
      tnear[i] = tn;
      if (tn <= tf) mask |= 1u << i;
    }
    return mask;
  }
};
#if !PT_BVH_AVX2
using NodeTest = NodeTestScalar;
#endif

// Triangle packs are in PackLayout::kEdges for Möller-Trumbore.
template <int kLanes>
struct LaneHits {
  alignas(32) float t[kLanes], u[kLanes], v[kLanes];
};
using PackHits = LaneHits<4>;

#if defined(__SSE2__)
// The accept conditions' operations of a lane type L (its M, m_*, bits), for both triangle kernels.
// With AVX-512 a comparison writes a mask register and takes the mask so far (k & (a op b) in one
// instruction, L::cmp_mask); elsewhere masks are vectors, and-ed and moved out as before.
// (The vector type is deduced, not given: a vector type as a template argument loses its attributes.)
template <class L>
struct MaskOps {
#if PT_BVH_AVX512
  using M = __mmask8;
  template <class V> static M m_gt(V a, V b) { return L::template cmp_mask<_CMP_GT_OS>(0xff, a, b); }
  template <class V> static M m_ge(V a, V b) { return L::template cmp_mask<_CMP_GE_OS>(0xff, a, b); }
  template <class V> static M m_le(V a, V b) { return L::template cmp_mask<_CMP_LE_OS>(0xff, a, b); }
  template <class V> static M m_gt(M k, V a, V b) { return L::template cmp_mask<_CMP_GT_OS>(k, a, b); }
  template <class V> static M m_ge(M k, V a, V b) { return L::template cmp_mask<_CMP_GE_OS>(k, a, b); }
  template <class V> static M m_le(M k, V a, V b) { return L::template cmp_mask<_CMP_LE_OS>(k, a, b); }
  template <class V> static M m_lt(M k, V a, V b) { return L::template cmp_mask<_CMP_LT_OS>(k, a, b); }
  template <class V> static M m_neq(M k, V a, V b) { return L::template cmp_mask<_CMP_NEQ_UQ>(k, a, b); }
  static M m_or(M a, M b) { return static_cast<M>(a | b); }
  static uint32_t bits(M k) { return k; }
#else
  template <class V> static V m_gt(V a, V b) { return L::gt(a, b); }
  template <class V> static V m_ge(V a, V b) { return L::ge(a, b); }
  template <class V> static V m_le(V a, V b) { return L::le(a, b); }
  template <class V> static V m_gt(V k, V a, V b) { return L::bit_and(k, L::gt(a, b)); }
  template <class V> static V m_ge(V k, V a, V b) { return L::bit_and(k, L::ge(a, b)); }
  template <class V> static V m_le(V k, V a, V b) { return L::bit_and(k, L::le(a, b)); }
  template <class V> static V m_lt(V k, V a, V b) { return L::bit_and(k, L::lt(a, b)); }
  template <class V> static V m_neq(V k, V a, V b) { return L::bit_and(k, L::neq(a, b)); }
  template <class V> static V m_or(V a, V b) { return L::bit_or(a, b); }
  template <class V> static uint32_t bits(V k) { return L::mask(k); }
#endif
};

// The vector operations the Möller-Trumbore kernel needs, four lanes (SSE) or eight (AVX: a pair of packs
// at once). The kernel is written once over them, so both widths do the same operations in the same
// order on each lane and give the same bits.
struct Lanes4 : MaskOps<Lanes4> {
  using V = __m128;
  static constexpr int kCount = 4;
  static V set1(float x) { return _mm_set1_ps(x); }
  static V zero() { return _mm_setzero_ps(); }
  static V add(V a, V b) { return _mm_add_ps(a, b); }
  static V sub(V a, V b) { return _mm_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm_mul_ps(a, b); }
  static V div(V a, V b) { return _mm_div_ps(a, b); }
  static V bit_and(V a, V b) { return _mm_and_ps(a, b); }
  static V bit_xor(V a, V b) { return _mm_xor_ps(a, b); }
  static V bit_or(V a, V b) { return _mm_or_ps(a, b); }
  static V min(V a, V b) { return _mm_min_ps(a, b); }
  static V max(V a, V b) { return _mm_max_ps(a, b); }
  static V neq(V a, V b) { return _mm_cmpneq_ps(a, b); }
  static V and_not(V a, V b) { return _mm_andnot_ps(a, b); }  // ~a & b
  // max(|a|, |b|), exact, so every way of forming it gives the same bits.
  static V max_abs(V a, V b) {
#if PT_BVH_AVX512
    return _mm_range_ps(a, b, 0x0b);  // the larger magnitude, sign cleared
#else
    V minus = _mm_set1_ps(-0.0f);
    return _mm_max_ps(_mm_andnot_ps(minus, a), _mm_andnot_ps(minus, b));
#endif
  }
  // A product the compiler may not fuse into an FMA (see rounded_product in intersect.h).
  static V mul_rounded(V a, V b) {
    V p = _mm_mul_ps(a, b);
    asm("" : "+x"(p));
    return p;
  }
  static V gt(V a, V b) { return _mm_cmpgt_ps(a, b); }
  static V ge(V a, V b) { return _mm_cmpge_ps(a, b); }
  static V lt(V a, V b) { return _mm_cmplt_ps(a, b); }
  static V le(V a, V b) { return _mm_cmple_ps(a, b); }
  static uint32_t mask(V a) { return static_cast<uint32_t>(_mm_movemask_ps(a)); }
#if !PT_BVH_AVX512
  using M = V;
#else
  template <int kPredicate>
  static __mmask8 cmp_mask(__mmask8 k, V a, V b) { return _mm_mask_cmp_ps_mask(k, a, b, kPredicate); }
#endif
  static void store(float* p, V a) { _mm_store_ps(p, a); }
  using Pack = TriPack;
  static V load(const TriPack& p, int row) { return _mm_load_ps(p.v[row]); }
  static V narrow(V a) { return a; }
#if PT_BVH_AVX2
  static V narrow(__m256 a) { return _mm256_castps256_ps128(a); }
#endif
};
#endif
#if PT_BVH_AVX2
struct Lanes8 : MaskOps<Lanes8> {
  using V = __m256;
  static constexpr int kCount = 8;
  static V set1(float x) { return _mm256_set1_ps(x); }
  static V zero() { return _mm256_setzero_ps(); }
  static V add(V a, V b) { return _mm256_add_ps(a, b); }
  static V sub(V a, V b) { return _mm256_sub_ps(a, b); }
  static V mul(V a, V b) { return _mm256_mul_ps(a, b); }
  static V div(V a, V b) { return _mm256_div_ps(a, b); }
  static V bit_and(V a, V b) { return _mm256_and_ps(a, b); }
  static V bit_xor(V a, V b) { return _mm256_xor_ps(a, b); }
  static V bit_or(V a, V b) { return _mm256_or_ps(a, b); }
  static V min(V a, V b) { return _mm256_min_ps(a, b); }
  static V max(V a, V b) { return _mm256_max_ps(a, b); }
  static V neq(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_NEQ_UQ); }
  static V and_not(V a, V b) { return _mm256_andnot_ps(a, b); }  // ~a & b
  static V max_abs(V a, V b) {
#if PT_BVH_AVX512
    return _mm256_range_ps(a, b, 0x0b);
#else
    V minus = _mm256_set1_ps(-0.0f);
    return _mm256_max_ps(_mm256_andnot_ps(minus, a), _mm256_andnot_ps(minus, b));
#endif
  }
  static V mul_rounded(V a, V b) {
    V p = _mm256_mul_ps(a, b);
    asm("" : "+x"(p));
    return p;
  }
  // The predicates of SSE's cmpgt/cmpge/cmplt/cmple (ordered, signalling).
  static V gt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GT_OS); }
  static V ge(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_GE_OS); }
  static V lt(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LT_OS); }
  static V le(V a, V b) { return _mm256_cmp_ps(a, b, _CMP_LE_OS); }
  static uint32_t mask(V a) { return static_cast<uint32_t>(_mm256_movemask_ps(a)); }
#if !PT_BVH_AVX512
  using M = V;
#else
  template <int kPredicate>
  static __mmask8 cmp_mask(__mmask8 k, V a, V b) { return _mm256_mask_cmp_ps_mask(k, a, b, kPredicate); }
#endif
  static void store(float* p, V a) { _mm256_store_ps(p, a); }
  // Row `row` of two packs, paired (TriPair): one aligned load, where two packs one after the other
  // took a load and an insert (in one process, 54 rows of 10k-124k triangles: 0.97 of the time on
  // diffuse rays, 0.98 on primary, shadow unchanged).
  using Pack = TriPair;
  static V load(const TriPair& p, int row) { return _mm256_load_ps(p.v[row]); }
  static V narrow(V a) { return a; }
};
#endif

#if defined(__SSE2__)
// Möller-Trumbore on the lanes of one pack (Lanes4) or a pair of packs (Lanes8, TriPair), operation for
// operation the scalar intersect_triangle_mt_edges. Returns the mask of lanes hit in (tmin, tmax).
// The barycentric tests run on the undivided values with the sign of the determinant folded in, so
// the division (and t) is only computed when some lane's triangle contains the ray's line, which
// for most packs none does.
template <class L>
inline uint32_t intersect_lanes_mt(const typename L::Pack& p, const Ray& ray, float tmax, LaneHits<L::kCount>& out) {
  using V = typename L::V;
  V dx = L::set1(ray.d.x), dy = L::set1(ray.d.y), dz = L::set1(ray.d.z);
  V v0x = L::load(p, 0), v0y = L::load(p, 1), v0z = L::load(p, 2);
  V e1x = L::load(p, 3), e1y = L::load(p, 4), e1z = L::load(p, 5);
  V e2x = L::load(p, 6), e2y = L::load(p, 7), e2z = L::load(p, 8);
  // pvec = cross(d, e2)
  V px = L::sub(L::mul(dy, e2z), L::mul(dz, e2y));
  V py = L::sub(L::mul(dz, e2x), L::mul(dx, e2z));
  V pz = L::sub(L::mul(dx, e2y), L::mul(dy, e2x));
  V det = L::add(L::add(L::mul(e1x, px), L::mul(e1y, py)), L::mul(e1z, pz));
  V sign = L::bit_and(det, L::set1(-0.0f));
  V abs_det = L::bit_xor(det, sign);
  V tx = L::sub(L::set1(ray.o.x), v0x), ty = L::sub(L::set1(ray.o.y), v0y), tz = L::sub(L::set1(ray.o.z), v0z);
  V u = L::add(L::add(L::mul(tx, px), L::mul(ty, py)), L::mul(tz, pz));
  // qvec = cross(tvec, e1)
  V qx = L::sub(L::mul(ty, e1z), L::mul(tz, e1y));
  V qy = L::sub(L::mul(tz, e1x), L::mul(tx, e1z));
  V qz = L::sub(L::mul(tx, e1y), L::mul(ty, e1x));
  V v = L::add(L::add(L::mul(dx, qx), L::mul(dy, qy)), L::mul(dz, qz));
  V us = L::bit_xor(u, sign), vs = L::bit_xor(v, sign);
  using M = typename L::M;
  M ok = L::m_lt(L::m_gt(abs_det, L::zero()), abs_det, L::set1(kInf));
  ok = L::m_le(L::m_ge(L::m_ge(ok, us, L::zero()), vs, L::zero()), L::add(us, vs), abs_det);
  if (L::bits(ok) == 0) return 0;
  V inv_det = L::div(L::set1(1.0f), det);
  V t = L::mul(L::add(L::add(L::mul(e2x, qx), L::mul(e2y, qy)), L::mul(e2z, qz)), inv_det);
  uint32_t mask = L::bits(L::m_lt(L::m_gt(ok, t, L::set1(ray.tmin)), t, L::set1(tmax)));
  if (mask) {
    L::store(out.t, t);
    L::store(out.u, L::mul(u, inv_det));
    L::store(out.v, L::mul(v, inv_det));
  }
  return mask;
}

// Bounds for the watertight test's range check without a division (intersect_lanes_wt): where the
// test computes t = tz * (1 / det) and accepts tmin < t < tmax, every accepted lane has
// range_lower(tmin) * |det| <= tz * sign(det) <= range_upper(tmax) * |det| in float. With u = 2^-24,
// t is within (1 +- u)^2 of tz / det (two roundings), and the factors 1 -+ 2^-20 on the bound cover
// those and the roundings of the bound and its product (a float beyond a real is beyond its
// rounding too, rounding being monotonic). Bounds below 2^-100 become 0 (a lane with t > tmin > 0
// has tz * sign(det) > 0): never a subnormal product, which costs a microcode assist on Intel CPUs
// (-2^-126 * |det| took 1.3-1.8x the time of the whole traversal).
inline float range_lower(float x) { return x > 0x1p-100f ? x * (1.0f - 0x1p-20f) : (x > 0.0f ? 0.0f : x * (1.0f + 0x1p-20f)); }
inline float range_upper(float x) { return x > 0.0f ? x * (1.0f + 0x1p-20f) + 0x1p-100f : x * (1.0f - 0x1p-20f); }

// The watertight test (intersect_triangle_watertight in intersect.h) on the lanes of one pack
// (Lanes4) or a pair (Lanes8, TriPair), in PackLayout::kVertices, operation for operation the
// scalar one, so every width gives the same bits. The per-ray part (the permuted axes, the shear and
// the origin) is set up once per traversal.
template <class L>
struct WatertightLanes {
  using V = typename L::V;
  int kx, ky, kz;
  V ox, oy, oz, sx, sy, sz, s2;
  float tmin;
  float tmin_check;  // range_lower(tmin)
  const Ray* ray;  // for the double-precision fallback
  WatertightLanes(const Ray& r, const WatertightRay& w)
      : kx(w.kx), ky(w.ky), kz(w.kz), sx(L::set1(w.sx)), sy(L::set1(w.sy)), sz(L::set1(w.sz)), s2(L::set1(w.s2)),
        tmin(r.tmin), tmin_check(range_lower(r.tmin)), ray(&r) {
    // Indexed as an array: Vec3f::operator[] branches on its index, which varies from ray to ray.
    const float o[3] = {r.o.x, r.o.y, r.o.z};
    ox = L::set1(o[w.kx]);
    oy = L::set1(o[w.ky]);
    oz = L::set1(o[w.kz]);
  }
#if PT_BVH_AVX2
  // Straight from the ray, in registers: the axes by one table load, the direction and origin
  // permuted by vpermilps, the shear by one division; the same values as WatertightRay's (its
  // division too is one four-lane division). On the dragon under the default studio, where most
  // shadow rays from the ground visit two or three nodes and one leaf, the set-up through
  // WatertightRay (the direction stored and read back by index, a table per axis) was a third of
  // the traversal's samples; this took 0.975 of the time over 54 rows in one process.
  explicit WatertightLanes(const Ray& r) : tmin(r.tmin), tmin_check(range_lower(r.tmin)), ray(&r) {
    static_assert(std::is_same_v<L, Lanes8>);
    static_assert(offsetof(Ray, d) == offsetof(Ray, o) + 12 && sizeof(Ray) >= offsetof(Ray, d) + 16);
    const __m128 minus = _mm_set1_ps(-0.0f);
    __m128 o = _mm_loadu_ps(&r.o.x);  // o.x o.y o.z d.x
    __m128 d = _mm_loadu_ps(&r.d.x);  // d.x d.y d.z tmin
    __m128 a = _mm_andnot_ps(minus, d);
    // bit 0: |x| > |y|, bit 1: |x| > |z|, bit 2: |y| > |z|
    int gt = _mm_movemask_ps(_mm_cmpgt_ps(_mm_permute_ps(a, _MM_SHUFFLE(3, 1, 0, 0)), _mm_permute_ps(a, _MM_SHUFFLE(3, 2, 2, 1)))) & 7;
    int negative = _mm_movemask_ps(_mm_cmplt_ps(d, _mm_setzero_ps())) & 7;  // not the sign bits: -0 is not < 0
    uint32_t axes = kAxes[gt * 8 + negative];
    kx = axes & 0xff;
    ky = (axes >> 8) & 0xff;
    kz = (axes >> 16) & 0xff;
    __m128i index = _mm_cvtepu8_epi32(_mm_cvtsi32_si128(static_cast<int>(axes)));
    __m128 dp = _mm_permutevar_ps(d, index), op = _mm_permutevar_ps(o, index);
    __m128 q = _mm_div_ps(_mm_blend_ps(dp, _mm_set1_ps(1.0f), 0b1100), _mm_permute_ps(dp, _MM_SHUFFLE(2, 2, 2, 2)));
    __m128 aq = _mm_andnot_ps(minus, q);
    __m128 m = _mm_max_ss(aq, _mm_permute_ps(aq, _MM_SHUFFLE(1, 1, 1, 1)));
    s2 = _mm256_broadcastss_ps(_mm_add_ss(m, m));
    sx = _mm256_broadcastss_ps(q);
    sy = _mm256_broadcastss_ps(_mm_permute_ps(q, _MM_SHUFFLE(1, 1, 1, 1)));
    sz = _mm256_broadcastss_ps(_mm_permute_ps(q, _MM_SHUFFLE(2, 2, 2, 2)));
    ox = _mm256_broadcastss_ps(op);
    oy = _mm256_broadcastss_ps(_mm_permute_ps(op, _MM_SHUFFLE(1, 1, 1, 1)));
    oz = _mm256_broadcastss_ps(_mm_permute_ps(op, _MM_SHUFFLE(2, 2, 2, 2)));
  }
  // kx | ky << 8 | kz << 16 | kz << 24 by (the comparisons above) * 8 + (the direction's
  // components below 0), as WatertightRay chooses them.
  static constexpr std::array<uint32_t, 64> kAxes = [] {
    std::array<uint32_t, 64> t{};
    for (int gt = 0; gt < 8; ++gt) {
      for (int negative = 0; negative < 8; ++negative) {
        int z = WatertightRay::kMaxAxis[((gt & 1) << 2) | (gt & 2) | ((gt >> 2) & 1)];
        int x = (z + 1) % 3, y = (x + 1) % 3;
        if ((negative >> z) & 1) std::swap(x, y);
        t[gt * 8 + negative] = uint32_t(x) | uint32_t(y) << 8 | uint32_t(z) << 16 | uint32_t(z) << 24;
      }
    }
    return t;
  }();
#endif
};

// The fallback (intersect_triangle_watertight_refined) on one lane of a pack or a pair; out of
// line, as it runs for about one pack test in 10^4 on a mesh seen from near by, but on a field of
// instances seen from far (small triangles, far corners: the shear's rounding is large against
// the edge functions) in 0.17 traversals in one. So it takes the
// ray's axes and shear from the kernels' set-up (`wide`: the same values as WatertightRay's,
// test `pack test: the eight-lane set-up ...`) rather than dividing again, and is not marked cold,
// which kept GCC from inlining the fallback's corners and edges into it.
inline float first_lane(__m128 v) { return _mm_cvtss_f32(v); }
#if PT_BVH_AVX2
inline float first_lane(__m256 v) { return _mm256_cvtss_f32(v); }
#endif
// Lane i of a pack (0-3) or of a pair (0-7).
template <class P, class W>
inline bool refine_lane(const P& p, int i, const W& wide, float tmax, float& t, float& u, float& v) {
  Vec3f a{p.v[0][i], p.v[1][i], p.v[2][i]}, b{p.v[3][i], p.v[4][i], p.v[5][i]}, c{p.v[6][i], p.v[7][i], p.v[8][i]};
  WatertightRay w;
  w.kx = wide.kx;
  w.ky = wide.ky;
  w.kz = wide.kz;
  w.sx = first_lane(wide.sx);
  w.sy = first_lane(wide.sy);
  w.sz = first_lane(wide.sz);
  w.s2 = first_lane(wide.s2);
  return intersect_triangle_watertight_refined(*wide.ray, w, a, b, c, tmax, t, u, v);
}

// A pack's corners relative to the ray's origin and sheared (x, y in the ray's plane, z along it,
// unscaled), and its edge functions: the watertight test's first half, shared by the kernel and
// the fallback's filter below so that both compute the same bits.
template <class L>
struct ShearedPack {
  using V = typename L::V;
  V ax, ay, az, bx, by, bz, cx, cy, cz, e0, e1, e2;
  template <class W>
  ShearedPack(const typename L::Pack& p, const W& wide) {
    const int kx = wide.kx, ky = wide.ky, kz = wide.kz;
    const V ox = L::narrow(wide.ox), oy = L::narrow(wide.oy), oz = L::narrow(wide.oz);
    const V sx = L::narrow(wide.sx), sy = L::narrow(wide.sy);
    az = L::sub(L::load(p, kz), oz);
    bz = L::sub(L::load(p, 3 + kz), oz);
    cz = L::sub(L::load(p, 6 + kz), oz);
    ax = L::sub(L::sub(L::load(p, kx), ox), L::mul_rounded(sx, az));
    ay = L::sub(L::sub(L::load(p, ky), oy), L::mul_rounded(sy, az));
    bx = L::sub(L::sub(L::load(p, 3 + kx), ox), L::mul_rounded(sx, bz));
    by = L::sub(L::sub(L::load(p, 3 + ky), oy), L::mul_rounded(sy, bz));
    cx = L::sub(L::sub(L::load(p, 6 + kx), ox), L::mul_rounded(sx, cz));
    cy = L::sub(L::sub(L::load(p, 6 + ky), oy), L::mul_rounded(sy, cz));
    e0 = L::sub(L::mul_rounded(cx, by), L::mul_rounded(cy, bx));
    e1 = L::sub(L::mul_rounded(ax, cy), L::mul_rounded(ay, cx));
    e2 = L::sub(L::mul_rounded(bx, ay), L::mul_rounded(by, ax));
  }
};

// The lanes the fallback could turn into a hit, by each edge against its own bound
// (watertight_edge_bound, in float and widened by 1 + 2^-18 and 2^-126 to stay above the double
// one): every edge function of one sign within its bound. The triangle's threshold before it is
// one bound for all three edges, from the farthest corner; on the studio's ground (corners 10^4
// model radii out) and on far instances it let through 300-400 times the lanes this does (dense-20k
// under the ground: 42,880 lanes to 100 in 524k primary traversals), each a double-precision
// fallback for nothing. Only on the rare path (some lane near an edge by the threshold), out of
// line (refine_lanes), from the pack again: inlined into the kernel, its code made every pack
// test 2-3% slower.
template <class L, class W>
inline uint32_t edges_within_bounds(const typename L::Pack& p, const W& wide) {
  using V = typename L::V;
  const ShearedPack<L> k(p, wide);
  const V minus = L::set1(-0.0f), zero = L::zero();
  auto abs = [&](V v) { return L::and_not(minus, v); };
  // m_x = |x| + 2 |s_x| |z|, as watertight_corner forms it.
  const V sx = L::narrow(wide.sx), sy = L::narrow(wide.sy);
  const V two_sx = abs(L::add(sx, sx)), two_sy = abs(L::add(sy, sy));
  struct Corner {
    V x, y, mx, my;
  };
  auto corner = [&](V x, V y, V z) {
    Corner c{abs(x), abs(y), zero, zero};
    c.mx = L::add(c.x, L::mul_rounded(two_sx, abs(z)));
    c.my = L::add(c.y, L::mul_rounded(two_sy, abs(z)));
    return c;
  };
  const Corner a = corner(k.ax, k.ay, k.az), b = corner(k.bx, k.by, k.bz), c = corner(k.cx, k.cy, k.cz);
  const V e0 = k.e0, e1 = k.e1, e2 = k.e2;
  auto bound = [&](const Corner& p, const Corner& q) {
    V t = L::add(L::add(L::mul_rounded(p.x, q.my), L::mul_rounded(p.my, q.x)),
                 L::add(L::mul_rounded(p.mx, q.y), L::mul_rounded(p.y, q.mx)));
    V s = L::add(L::mul_rounded(p.mx, q.my), L::mul_rounded(p.my, q.mx));
    V e = L::add(L::mul_rounded(t, L::set1(kWatertightEdgeBoundT)), L::mul_rounded(s, L::set1(kWatertightEdgeBoundS)));
    return L::add(L::mul_rounded(e, L::set1(1.0f + 0x1p-18f)), L::set1(0x1p-126f));
  };
  const V b0 = bound(b, c), b1 = bound(c, a), b2 = bound(a, b);  // the edges of e0, e1, e2
  auto within = [&](V e, V bd) { return L::le(abs(e), bd); };
  V negative_ok = L::bit_and(L::bit_and(L::bit_or(L::ge(e0, zero), within(e0, b0)), L::bit_or(L::ge(e1, zero), within(e1, b1))),
                             L::bit_or(L::ge(e2, zero), within(e2, b2)));
  V positive_ok = L::bit_and(L::bit_and(L::bit_or(L::le(e0, zero), within(e0, b0)), L::bit_or(L::le(e1, zero), within(e1, b1))),
                             L::bit_or(L::le(e2, zero), within(e2, b2)));
  return L::mask(L::bit_or(negative_ok, positive_ok));
}

// The lanes of `refine` the fallback turns into hits (their t, u, v in `out`): the kernel's one
// call into the rare path, so that none of it is in the kernel's code.
template <class L, class W>
[[gnu::noinline]] uint32_t refine_lanes(const typename L::Pack& p, const W& wide, uint32_t refine, float tmax,
                                        LaneHits<L::kCount>& out) {
  refine &= edges_within_bounds<L>(p, wide);
  uint32_t mask = 0;
  while (refine) {
    int lane = std::countr_zero(refine);
    refine &= refine - 1;
    if (refine_lane(p, lane, wide, tmax, out.t[lane], out.u[lane], out.v[lane])) mask |= 1u << lane;
  }
  return mask;
}

// `W` is WatertightLanes<L>, or with AVX2 WatertightLanes<Lanes8> for four lanes as well, read as
// the low halves of its broadcasts (L::narrow): a ray sets up one width.
template <class L, class W>
inline uint32_t intersect_lanes_wt(const typename L::Pack& p, const W& wide, float tmax, LaneHits<L::kCount>& out) {
  using V = typename L::V;
  const ShearedPack<L> k(p, wide);
  const V ax = k.ax, ay = k.ay, az = k.az, bx = k.bx, by = k.by, bz = k.bz, cx = k.cx, cy = k.cy, cz = k.cz;
  const V e0 = k.e0, e1 = k.e1, e2 = k.e2;
  // key = min(-lo, hi) <= 0: no edge function below zero, or none above (the scalar test's
  // condition); key > 0: both signs, which the double-precision fallback (watertight_near_edge in
  // intersect.h) may still turn into a hit where key is within rounding of zero, below thr
  // (watertight_threshold). Empty lanes are NaN (key and thr NaN: no lane passes), and so is a
  // lane with a NaN edge function, or else det is NaN, which the finite test rejects.
  V zero = L::zero(), minus = L::set1(-0.0f);
  V lo = L::min(L::min(e0, e1), e2), hi = L::max(L::max(e0, e1), e2);
  V key = L::min(L::bit_xor(lo, minus), hi);
  V mxy = L::max(L::max(L::max_abs(ax, ay), L::max_abs(bx, by)), L::max_abs(cx, cy));
  V mz = L::max_abs(L::max_abs(az, bz), cz);
  V n = L::add(mxy, L::mul_rounded(L::narrow(wide.s2), mz));
  V thr = L::mul_rounded(L::mul_rounded(n, L::add(mxy, L::mul_rounded(n, L::set1(kWatertightThresholdN)))),
                         L::set1(kWatertightThresholdScale));  // watertight_threshold
  V det = L::add(L::add(e0, e1), e2);
  const V sz = L::narrow(wide.sz);
  V tz = L::add(L::add(L::mul_rounded(e0, L::mul_rounded(sz, az)), L::mul_rounded(e1, L::mul_rounded(sz, bz))),
                L::mul_rounded(e2, L::mul_rounded(sz, cz)));
  // The early exit, which most packs take: no lane inside its triangle (or near an edge) with t in
  // range, by the division-free bounds of range_lower and range_upper. Taken on the edge functions
  // alone, it let through every triangle the ray's line crosses behind the origin or beyond the
  // closest hit, the one under a ray leaving a surface among them: on dense-82k's diffuse rays
  // without the ground 1.18 of 2.51 pack tests a ray passed and 0.35 hit, an unpredictable branch.
  V adet = L::and_not(minus, det);
  V tzs = L::bit_xor(tz, L::bit_and(det, minus));
  // The conditions as masks (L::M): with AVX-512 each comparison goes into a mask register and
  // takes the mask so far, where a vector compare, an and and a movemask did (in one process, 54
  // rows of 10k-124k triangles: 0.986 of the time on diffuse rays, 0.99 over all).
  using M = typename L::M;
  M in_range = L::m_le(L::m_ge(tzs, L::mul_rounded(L::set1(wide.tmin_check), adet)), tzs,
                       L::mul_rounded(L::set1(range_upper(tmax)), adet));
  M signs = L::m_le(key, zero);
  uint32_t passing = L::bits(L::m_le(L::m_or(L::m_gt(key, zero), in_range), key, thr));
  if (passing == 0) return 0;
  uint32_t refine = passing & ~L::bits(signs);
  M ok = L::m_lt(L::m_neq(signs, det, zero), adet, L::set1(kInf));
  V inv_det = L::div(L::set1(1.0f), det);
  V t = L::mul_rounded(tz, inv_det);
  uint32_t mask = L::bits(L::m_lt(L::m_gt(ok, t, L::set1(wide.tmin)), t, L::set1(tmax)));
  if (mask) {
    L::store(out.t, t);
    L::store(out.u, L::mul_rounded(e1, inv_det));
    L::store(out.v, L::mul_rounded(e2, inv_det));
  }
  // After the float answers are stored: no vector is live across the call.
  if (refine) mask |= refine_lanes<L>(p, wide, refine, tmax, out);
  return mask;
}

inline uint32_t intersect_pack_mt(const TriPack& p, const Ray& ray, float tmax, PackHits& out) {
  return intersect_lanes_mt<Lanes4>(p, ray, tmax, out);
}
#endif

#if PT_BVH_AVX2
// A pair of packs in one eight-lane test: lanes 0-3 are its first pack's, 4-7 its second's.
inline uint32_t intersect_pack_pair_mt(const TriPair& p, const Ray& ray, float tmax, LaneHits<8>& out) {
  return intersect_lanes_mt<Lanes8>(p, ray, tmax, out);
}
#endif

#if PT_BVH_AVX2
inline uint32_t intersect_pack_pair_wt(const TriPair& p, const WatertightLanes<Lanes8>& w, float tmax, LaneHits<8>& out) {
  return intersect_lanes_wt<Lanes8>(p, w, tmax, out);
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

// One ray's triangle tests, set up once per traversal: one pack at a time (one), and with AVX2 two
// paired packs in one eight-lane test (pair, where kPairs).
template <TriangleTest kTest>
class PackTests {
 public:
#if PT_BVH_AVX2
  static constexpr bool kPairs = true;
#else
  static constexpr bool kPairs = false;
#endif
  explicit PackTests(const Ray& ray)
      : ray_(ray)
#if PT_BVH_AVX2
        , w8_(ray)
#else
        , wt_(ray.d)
#if defined(__SSE2__)
        , w4_(ray, wt_)
#endif
#endif
  {
  }
  PackTests(const PackTests&) = delete;
  PackTests& operator=(const PackTests&) = delete;

  uint32_t one(const TriPack& p, float tmax, PackHits& h) const {
#if defined(__SSE2__)
    if constexpr (kTest == TriangleTest::kWatertight) {
#if PT_BVH_AVX2
      return intersect_lanes_wt<Lanes4>(p, w8_, tmax, h);
#else
      return intersect_lanes_wt<Lanes4>(p, w4_, tmax, h);
#endif
    } else {
      return intersect_pack_mt(p, ray_, tmax, h);
    }
#else
    return intersect_pack_scalar<kTest>(p, ray_, wt_, tmax, h);
#endif
  }

#if PT_BVH_AVX2
  uint32_t pair(const TriPair& p, float tmax, LaneHits<8>& h) const {
    if constexpr (kTest == TriangleTest::kWatertight) {
      return intersect_pack_pair_wt(p, w8_, tmax, h);
    } else {
      return intersect_pack_pair_mt(p, ray_, tmax, h);
    }
  }
#endif

 private:
  const Ray& ray_;
#if PT_BVH_AVX2
  WatertightLanes<Lanes8> w8_;
#else
  WatertightRay wt_;
#if defined(__SSE2__)
  WatertightLanes<Lanes4> w4_;
#endif
#endif
};

}  // namespace PT_BVH_ISA
}  // namespace pt::bvh
