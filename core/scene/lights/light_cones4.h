// Four clusters' LightCones side by side (one lane each), and their importances at a shading point
// computed at once: the light tree's nodes have four children, and its descent evaluates them
// together, with SSE where the compiler has it. Every lane gives bit for bit what importance()
// (light_bounds.h) gives its LightCone: the same operations in the same order, the branches taken
// as selects (tests/test_unit_lighttree.cpp holds them to it).
#pragma once
#include <cstdint>

#include "core/scene/lights/light_bounds.h"

#if defined(__SSE2__)
#include <immintrin.h>
#endif

namespace pt {

struct alignas(16) LightCones4 {
  float cx[4] = {}, cy[4] = {}, cz[4] = {};  // bounding sphere centre
  float radius[4] = {}, radius2[4] = {};
  float ax[4] = {}, ay[4] = {}, az[4] = {};  // cone axis
  float phi[4] = {};                         // zero: an empty lane, never chosen
  float cos_o[4] = {}, sin_o[4] = {}, cos_e[4] = {};
  float behind[4] = {};

  void set(int lane, const LightCone& c) {
    cx[lane] = c.center.x, cy[lane] = c.center.y, cz[lane] = c.center.z;
    radius[lane] = c.radius, radius2[lane] = c.radius2;
    ax[lane] = c.axis.x, ay[lane] = c.axis.y, az[lane] = c.axis.z;
    phi[lane] = c.phi;
    cos_o[lane] = c.cos_o, sin_o[lane] = c.sin_o, cos_e[lane] = c.cos_e;
    behind[lane] = c.behind;
  }
  LightCone get(int lane) const {
    LightCone c;
    c.center = {cx[lane], cy[lane], cz[lane]};
    c.radius = radius[lane], c.radius2 = radius2[lane];
    c.axis = {ax[lane], ay[lane], az[lane]};
    c.phi = phi[lane];
    c.cos_o = cos_o[lane], c.sin_o = sin_o[lane], c.cos_e = cos_e[lane];
    c.behind = behind[lane];
    return c;
  }
};

#if defined(__SSE2__)

// importance() of the four lanes (see light_bounds.h for what it bounds).
inline void importance4(const LightCones4& b, const Vec3f& p, const Vec3f& n, float out[4]) {
  const __m128 zero = _mm_setzero_ps(), one = _mm_set1_ps(1.0f);
  auto select = [](__m128 mask, __m128 a, __m128 b) { return _mm_or_ps(_mm_and_ps(mask, a), _mm_andnot_ps(mask, b)); };
  __m128 phi = _mm_load_ps(b.phi), radius2 = _mm_load_ps(b.radius2);
  __m128 tx = _mm_sub_ps(_mm_set1_ps(p.x), _mm_load_ps(b.cx));
  __m128 ty = _mm_sub_ps(_mm_set1_ps(p.y), _mm_load_ps(b.cy));
  __m128 tz = _mm_sub_ps(_mm_set1_ps(p.z), _mm_load_ps(b.cz));
  __m128 dist2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(tx, tx), _mm_mul_ps(ty, ty)), _mm_mul_ps(tz, tz));
  __m128 outside = _mm_cmpgt_ps(dist2, radius2);
  __m128 along = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(b.ax), tx), _mm_mul_ps(_mm_load_ps(b.ay), ty)),
                            _mm_mul_ps(_mm_load_ps(b.az), tz));
  __m128 behind = _mm_cmplt_ps(along, _mm_xor_ps(_mm_load_ps(b.behind), _mm_set1_ps(-0.0f)));
  __m128 inside_value = _mm_min_ps(_mm_div_ps(phi, _mm_max_ps(radius2, _mm_set1_ps(1e-30f))), _mm_set1_ps(1e30f));
  __m128 inv_dist = _mm_div_ps(one, _mm_sqrt_ps(dist2));
  __m128 wx = _mm_mul_ps(tx, inv_dist), wy = _mm_mul_ps(ty, inv_dist), wz = _mm_mul_ps(tz, inv_dist);
  __m128 sin_b = _mm_mul_ps(_mm_load_ps(b.radius), inv_dist);
  __m128 cos_b = _mm_sqrt_ps(_mm_max_ps(_mm_sub_ps(one, _mm_mul_ps(sin_b, sin_b)), zero));
  __m128 cos_o = _mm_load_ps(b.cos_o), sin_o = _mm_load_ps(b.sin_o);
  __m128 cos_w = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_load_ps(b.ax), wx), _mm_mul_ps(_mm_load_ps(b.ay), wy)),
                            _mm_mul_ps(_mm_load_ps(b.az), wz));
  __m128 sin_w = _mm_sqrt_ps(_mm_max_ps(_mm_sub_ps(one, _mm_mul_ps(cos_w, cos_w)), zero));
  __m128 cos_x = _mm_add_ps(_mm_mul_ps(cos_w, cos_o), _mm_mul_ps(sin_w, sin_o));
  __m128 sin_x = _mm_sub_ps(_mm_mul_ps(sin_w, cos_o), _mm_mul_ps(cos_w, sin_o));
  __m128 narrowed = _mm_and_ps(_mm_and_ps(_mm_cmpgt_ps(cos_o, _mm_set1_ps(-1.0f)), _mm_cmplt_ps(cos_w, cos_o)),
                               _mm_cmplt_ps(cos_x, cos_b));
  __m128 cos_p = select(narrowed, _mm_add_ps(_mm_mul_ps(cos_x, cos_b), _mm_mul_ps(sin_x, sin_b)), one);
  __m128 cut = _mm_cmplt_ps(cos_p, _mm_load_ps(b.cos_e));
  __m128 result = _mm_mul_ps(_mm_mul_ps(phi, cos_p), _mm_mul_ps(inv_dist, inv_dist));
  if (n.x != 0 || n.y != 0 || n.z != 0) {
    __m128 dot_n = _mm_add_ps(_mm_add_ps(_mm_mul_ps(_mm_set1_ps(n.x), wx), _mm_mul_ps(_mm_set1_ps(n.y), wy)),
                              _mm_mul_ps(_mm_set1_ps(n.z), wz));
    __m128 cos_i = _mm_xor_ps(dot_n, _mm_set1_ps(-0.0f));
    __m128 tilted = _mm_cmplt_ps(cos_i, cos_b);
    __m128 sin_i = _mm_sqrt_ps(_mm_max_ps(_mm_sub_ps(one, _mm_mul_ps(cos_i, cos_i)), zero));
    __m128 cos_ip = _mm_add_ps(_mm_mul_ps(cos_i, cos_b), _mm_mul_ps(sin_i, sin_b));
    cut = _mm_or_ps(cut, _mm_and_ps(tilted, _mm_cmple_ps(cos_ip, zero)));
    result = select(tilted, _mm_mul_ps(result, cos_ip), result);
  }
  result = _mm_andnot_ps(cut, _mm_min_ps(result, _mm_set1_ps(1e30f)));
  result = select(outside, result, inside_value);
  _mm_store_ps(out, _mm_andnot_ps(behind, _mm_and_ps(_mm_cmpgt_ps(phi, zero), result)));
}

#else

inline void importance4(const LightCones4& b, const Vec3f& p, const Vec3f& n, float out[4]) {
  for (int lane = 0; lane < 4; ++lane) out[lane] = importance(b.get(lane), p, n);
}

#endif

}  // namespace pt
