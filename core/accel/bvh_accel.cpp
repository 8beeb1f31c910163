// Traversal of the 8-wide BVH built in bvh_build.cpp. Per node, one AVX slab test (Kay & Kajiya,
// "Ray Tracing Complex Scenes", SIGGRAPH 1986) of all eight children against the current closest
// hit; hit children are visited nearest entry distance first, the others pushed with their entry
// distance so that a pop can discard them once a closer hit is known. Triangles are tested four at
// a time (SSE Möller-Trumbore) or one at a time (watertight). occluded() is the same loop without
// the ordering, with a separate any-hit leaf test that stops at the first hit.
#include "core/accel/bvh_accel.h"

#if defined(__AVX__) || defined(__SSE2__)
#include <immintrin.h>
#endif

#include <chrono>
#include <cstring>

#include "core/accel/bvh_build.h"
#include "core/geometry/intersect.h"
#include "core/geometry/geometry.h"

namespace pt {
namespace {

using bvh::TriPack;
using bvh::WideNode;

// Per-ray constants of the slab test. A zero direction component would give 0 * inf = NaN for a
// ray starting exactly on a slab plane; replacing it by a tiny value keeps the arithmetic finite.
struct RayBoxPre {
  Vec3f o, inv;
  int near[3], far[3];  // row of WideNode::bounds holding the near / far plane of each axis
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
// writes their entry distances.
inline uint32_t intersect_children(const WideNode& node, const RayBoxPre& pre, float tmin, float tmax, float* tnear) {
#if defined(__AVX__)
  // (plane - o) * inv, not fma(plane, inv, -o * inv): the rounding of o * inv is relative to o,
  // not to the distance, and far from the origin it makes the test miss boxes the ray enters.
  __m256 ox = _mm256_set1_ps(pre.o.x), oy = _mm256_set1_ps(pre.o.y), oz = _mm256_set1_ps(pre.o.z);
  __m256 ix = _mm256_set1_ps(pre.inv.x), iy = _mm256_set1_ps(pre.inv.y), iz = _mm256_set1_ps(pre.inv.z);
  __m256 nx = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[pre.near[0]]), ox), ix);
  __m256 ny = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[pre.near[1]]), oy), iy);
  __m256 nz = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[pre.near[2]]), oz), iz);
  __m256 fx = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[pre.far[0]]), ox), ix);
  __m256 fy = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[pre.far[1]]), oy), iy);
  __m256 fz = _mm256_mul_ps(_mm256_sub_ps(_mm256_load_ps(node.bounds[pre.far[2]]), oz), iz);
  __m256 tn = _mm256_max_ps(_mm256_max_ps(nx, ny), _mm256_max_ps(nz, _mm256_set1_ps(tmin)));
  __m256 tf = _mm256_min_ps(_mm256_min_ps(fx, fy), _mm256_min_ps(fz, _mm256_set1_ps(tmax)));
  tf = _mm256_mul_ps(tf, _mm256_set1_ps(kFarScale));
  _mm256_store_ps(tnear, tn);
  return static_cast<uint32_t>(_mm256_movemask_ps(_mm256_cmp_ps(tn, tf, _CMP_LE_OQ)));
#else
  uint32_t mask = 0;
  for (int i = 0; i < bvh::kWidth; ++i) {
    float tn = tmin, tf = tmax;
    for (int a = 0; a < 3; ++a) {
      tn = std::max(tn, (node.bounds[pre.near[a]][i] - pre.o[a]) * pre.inv[a]);
      tf = std::min(tf, (node.bounds[pre.far[a]][i] - pre.o[a]) * pre.inv[a]);
    }
    tnear[i] = tn;
    if (tn <= tf * kFarScale) mask |= 1u << i;
  }
  return mask;
#endif
}

// Möller-Trumbore on four triangles at once, operation for operation the scalar
// intersect_triangle_mt, so both give the same t, u, v. Returns the mask of lanes hit in (tmin, tmax).
#if defined(__SSE2__)
struct PackHits {
  alignas(16) float t[4], u[4], v[4];
};

inline uint32_t intersect_pack_mt(const TriPack& p, const Ray& ray, float tmax, PackHits& out) {
  __m128 dx = _mm_set1_ps(ray.d.x), dy = _mm_set1_ps(ray.d.y), dz = _mm_set1_ps(ray.d.z);
  __m128 v0x = _mm_load_ps(p.v[0]), v0y = _mm_load_ps(p.v[1]), v0z = _mm_load_ps(p.v[2]);
  __m128 e1x = _mm_sub_ps(_mm_load_ps(p.v[3]), v0x), e1y = _mm_sub_ps(_mm_load_ps(p.v[4]), v0y),
         e1z = _mm_sub_ps(_mm_load_ps(p.v[5]), v0z);
  __m128 e2x = _mm_sub_ps(_mm_load_ps(p.v[6]), v0x), e2y = _mm_sub_ps(_mm_load_ps(p.v[7]), v0y),
         e2z = _mm_sub_ps(_mm_load_ps(p.v[8]), v0z);
  // pvec = cross(d, e2)
  __m128 px = _mm_sub_ps(_mm_mul_ps(dy, e2z), _mm_mul_ps(dz, e2y));
  __m128 py = _mm_sub_ps(_mm_mul_ps(dz, e2x), _mm_mul_ps(dx, e2z));
  __m128 pz = _mm_sub_ps(_mm_mul_ps(dx, e2y), _mm_mul_ps(dy, e2x));
  __m128 det = _mm_add_ps(_mm_add_ps(_mm_mul_ps(e1x, px), _mm_mul_ps(e1y, py)), _mm_mul_ps(e1z, pz));
  __m128 abs_det = _mm_andnot_ps(_mm_set1_ps(-0.0f), det);
  __m128 ok = _mm_and_ps(_mm_cmpgt_ps(abs_det, _mm_setzero_ps()), _mm_cmplt_ps(abs_det, _mm_set1_ps(kInf)));
  __m128 inv_det = _mm_div_ps(_mm_set1_ps(1.0f), det);
  __m128 tx = _mm_sub_ps(_mm_set1_ps(ray.o.x), v0x), ty = _mm_sub_ps(_mm_set1_ps(ray.o.y), v0y),
         tz = _mm_sub_ps(_mm_set1_ps(ray.o.z), v0z);
  __m128 u = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, px), _mm_mul_ps(ty, py)), _mm_mul_ps(tz, pz)), inv_det);
  ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpge_ps(u, _mm_setzero_ps()), _mm_cmple_ps(u, _mm_set1_ps(1.0f))));
  // qvec = cross(tvec, e1)
  __m128 qx = _mm_sub_ps(_mm_mul_ps(ty, e1z), _mm_mul_ps(tz, e1y));
  __m128 qy = _mm_sub_ps(_mm_mul_ps(tz, e1x), _mm_mul_ps(tx, e1z));
  __m128 qz = _mm_sub_ps(_mm_mul_ps(tx, e1y), _mm_mul_ps(ty, e1x));
  __m128 v = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(dx, qx), _mm_mul_ps(dy, qy)), _mm_mul_ps(dz, qz)), inv_det);
  ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpge_ps(v, _mm_setzero_ps()), _mm_cmple_ps(_mm_add_ps(u, v), _mm_set1_ps(1.0f))));
  __m128 t = _mm_mul_ps(_mm_add_ps(_mm_add_ps(_mm_mul_ps(e2x, qx), _mm_mul_ps(e2y, qy)), _mm_mul_ps(e2z, qz)), inv_det);
  ok = _mm_and_ps(ok, _mm_and_ps(_mm_cmpgt_ps(t, _mm_set1_ps(ray.tmin)), _mm_cmplt_ps(t, _mm_set1_ps(tmax))));
  uint32_t mask = static_cast<uint32_t>(_mm_movemask_ps(ok));
  if (mask) {
    _mm_store_ps(out.t, t);
    _mm_store_ps(out.u, u);
    _mm_store_ps(out.v, v);
  }
  return mask;
}
#endif

inline void pack_vertices(const TriPack& p, int lane, Vec3f& a, Vec3f& b, Vec3f& c) {
  a = {p.v[0][lane], p.v[1][lane], p.v[2][lane]};
  b = {p.v[3][lane], p.v[4][lane], p.v[5][lane]};
  c = {p.v[6][lane], p.v[7][lane], p.v[8][lane]};
}

struct StackEntry {
  uint32_t ref;
  float t;
};
// Depth of the binary tree is at most 40 SAH levels plus 32 halvings (bvh_build.cpp), and each wide
// level pushes at most seven children.
constexpr int kStackSize = 7 * 72 + 8;

template <TriangleTest kTest>
class BvhAccel final : public Accel {
 public:
  explicit BvhAccel(const Geometry& scene) : scene_(scene) {
    auto start = std::chrono::steady_clock::now();
    bvh::Bvh2 tree = bvh::build_bvh2(bvh::make_prim_refs(scene));
    bvh_ = bvh::collapse_to_wide(tree, scene);
    stats_.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    stats_.nodes = bvh_.nodes;
    stats_.primitives = tree.prims.size();
    stats_.bytes = bvh_.bytes();
  }

  std::optional<Hit> intersect(const Ray& ray) const override {
    Hit hit;
    if (!traverse<false>(ray, hit)) return std::nullopt;
    return hit;
  }

  bool occluded(const Ray& ray) const override {
    Hit hit;
    return traverse<true>(ray, hit);
  }

  // Closest hit (children visited nearest first), or with kAnyHit the first hit found.
  template <bool kAnyHit>
  bool traverse(const Ray& ray, Hit& hit) const {
    if (bvh_.blocks.empty()) return false;
    RayBoxPre pre(ray);
    [[maybe_unused]] WatertightRay wt(ray.d);
    hit.t = ray.tmax;
    bool found = false;
    StackEntry stack[kStackSize];
    int sp = 0;
    uint32_t cur = 0;
    alignas(32) float dist[bvh::kWidth];
    for (;;) {
      if (!bvh::is_leaf(cur)) {
        const WideNode& node = bvh_.node(cur);
        uint32_t mask = intersect_children(node, pre, ray.tmin, hit.t, dist);
        if (mask != 0) {
          int a = __builtin_ctz(mask);
          mask &= mask - 1;
          if constexpr (kAnyHit) {
            // Any hit ends the search, and most shadow rays find none: order would not pay for itself.
            cur = node.child[a];
            while (mask) {
              stack[sp++] = {node.child[__builtin_ctz(mask)], 0.0f};
              mask &= mask - 1;
            }
            continue;
          }
          if (mask == 0) {
            cur = node.child[a];
            continue;
          }
          int b = __builtin_ctz(mask);
          mask &= mask - 1;
          if (mask == 0) {
            if (dist[a] > dist[b]) std::swap(a, b);
            stack[sp++] = {node.child[b], dist[b]};
            cur = node.child[a];
            continue;
          }
          // Three or more: push all, sorted so that the nearest ends on top, and continue with it.
          int base = sp;
          stack[sp++] = {node.child[a], dist[a]};
          stack[sp++] = {node.child[b], dist[b]};
          while (mask) {
            int c = __builtin_ctz(mask);
            mask &= mask - 1;
            stack[sp++] = {node.child[c], dist[c]};
          }
          for (int i = base + 1; i < sp; ++i) {  // insertion sort, farthest first
            StackEntry e = stack[i];
            int j = i - 1;
            while (j >= base && stack[j].t < e.t) {
              stack[j + 1] = stack[j];
              --j;
            }
            stack[j + 1] = e;
          }
          cur = stack[--sp].ref;
          continue;
        }
      } else if (cur != bvh::kEmptyChild) {
        if constexpr (kAnyHit) {
          if (occluded_leaf(cur, ray, wt)) return true;
        } else {
          found |= intersect_leaf(cur, ray, wt, hit);
        }
      }
      // Pop the next subtree that may still hold a closer hit.
      for (;;) {
        if (sp == 0) return found;
        const StackEntry& e = stack[--sp];
        if (e.t <= hit.t) {
          cur = e.ref;
          break;
        }
      }
    }
  }

  AccelStats stats() const override { return stats_; }
  std::string name() const override {
    return kTest == TriangleTest::kWatertight ? "bvh (watertight)" : "bvh";
  }

 private:
  bool intersect_leaf(uint32_t ref, const Ray& ray, const WatertightRay& wt, Hit& hit) const {
    uint32_t first = bvh::leaf_first(ref), count = bvh::leaf_count(ref);
    bool found = false;
    if (ref & bvh::kSphereBit) {
      Ray r = ray;
      for (uint32_t i = 0; i < count; ++i) {
        uint32_t s = bvh_.spheres[first + i];
        const Sphere& sphere = scene_.spheres()[s];
        r.tmax = hit.t;
        float t;
        if (intersect_sphere(r, sphere.center, sphere.radius, t)) {
          hit = Hit{t, kGeomSpheres, s, 0.0f, 0.0f};
          found = true;
        }
      }
      return found;
    }
    for (uint32_t k = 0; k < count; ++k) {
      const TriPack& p = bvh_.pack(ref, k);
      if constexpr (kTest == TriangleTest::kMollerTrumbore) {
#if defined(__SSE2__)
        PackHits h;
        uint32_t mask = intersect_pack_mt(p, ray, hit.t, h);
        while (mask) {
          int lane = __builtin_ctz(mask);
          mask &= mask - 1;
          if (h.t[lane] < hit.t) {
            hit = Hit{h.t[lane], kGeomTriangles, p.prim[lane], h.u[lane], h.v[lane]};
            found = true;
          }
        }
        continue;
#endif
      }
      Ray r = ray;
      for (int lane = 0; lane < 4; ++lane) {
        if (p.prim[lane] == bvh::kNoPrim) break;
        Vec3f a, b, c;
        pack_vertices(p, lane, a, b, c);
        r.tmax = hit.t;
        float t, u, v;
        bool ok = kTest == TriangleTest::kWatertight ? intersect_triangle_watertight(r, wt, a, b, c, t, u, v)
                                                     : intersect_triangle_mt(r, a, b, c, t, u, v);
        if (ok) {
          hit = Hit{t, kGeomTriangles, p.prim[lane], u, v};
          found = true;
        }
      }
    }
    return found;
  }

  bool occluded_leaf(uint32_t ref, const Ray& ray, const WatertightRay& wt) const {
    uint32_t first = bvh::leaf_first(ref), count = bvh::leaf_count(ref);
    if (ref & bvh::kSphereBit) {
      for (uint32_t i = 0; i < count; ++i) {
        const Sphere& sphere = scene_.spheres()[bvh_.spheres[first + i]];
        float t;
        if (intersect_sphere(ray, sphere.center, sphere.radius, t)) return true;
      }
      return false;
    }
    for (uint32_t k = 0; k < count; ++k) {
      const TriPack& p = bvh_.pack(ref, k);
      if constexpr (kTest == TriangleTest::kMollerTrumbore) {
#if defined(__SSE2__)
        PackHits h;
        if (intersect_pack_mt(p, ray, ray.tmax, h)) return true;
        continue;
#endif
      }
      for (int lane = 0; lane < 4; ++lane) {
        if (p.prim[lane] == bvh::kNoPrim) break;
        Vec3f a, b, c;
        pack_vertices(p, lane, a, b, c);
        float t, u, v;
        bool ok = kTest == TriangleTest::kWatertight ? intersect_triangle_watertight(ray, wt, a, b, c, t, u, v)
                                                     : intersect_triangle_mt(ray, a, b, c, t, u, v);
        if (ok) return true;
      }
    }
    return false;
  }

  const Geometry& scene_;
  bvh::WideBvh bvh_;
  AccelStats stats_;
};

}  // namespace

std::unique_ptr<Accel> make_bvh_accel(const Geometry& scene, TriangleTest test) {
  if (test == TriangleTest::kWatertight) return std::make_unique<BvhAccel<TriangleTest::kWatertight>>(scene);
  return std::make_unique<BvhAccel<TriangleTest::kMollerTrumbore>>(scene);
}

}  // namespace pt
